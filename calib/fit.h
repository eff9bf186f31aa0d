#ifndef KINCAL_CALIB_FIT_H_
#define KINCAL_CALIB_FIT_H_

// Least-squares fit of robot parameters, measuring frame and fixed points to
// measured tip positions (Ceres Levenberg-Marquardt, autodiff through the
// templated chain). Options, what is variable, and the Summary are kept apart
// (as Ceres' Solver::Options / Summary).

#include <Eigen/Core>
#include <map>
#include <string>
#include <vector>

#include "calib/chain.h"
#include "calib/model_state.h"
#include "data/observations.h"

namespace kincal {

// One usable observation row.
struct Measurement {
  enum Kind { kMeasured, kFixedPoint };
  int row = 0;  // index in Observations::rows
  Kind kind = kMeasured;
  PoseInput input;
  Eigen::Vector3d p_in_meas = Eigen::Vector3d::Zero();  // kMeasured
  int point = -1;  // kFixedPoint: index into ModelState::points_in_base
  // kMeasured: the measuring frame (ModelState::FrameBlock) of its series.
  int frame = 0;
};

// Rows with x,y,z become kMeasured; rows with only a fixed_point label become
// kFixedPoint (adding the label to state->point_labels); other rows are
// skipped but still count for the approach directions. Pose inputs (s, tau)
// use `nominal`'s geometry.
std::vector<Measurement> MakeMeasurements(const Chain& nominal,
                                          const Observations& obs,
                                          ModelState* state);

// One measuring frame per series (spec v3 column `series`) when `obs` has
// more than one: each measured row of `measurements` (made from `obs`) gets
// its series' frame index (Observations::SeriesNames order) and `state`
// that many frames, labelled in state->frame_series. Data of one series are
// left as they are (frame 0). Returns the number of frames.
int AssignSeriesFrames(const Observations& obs,
                       std::vector<Measurement>* measurements,
                       ModelState* state);

// The model's residual of one measurement (mm), 3 numbers:
//   kMeasured:   meas_from_base * tip_in_base(q) - p_in_meas (the frame of
//                the measurement's series)
//   kFixedPoint: tip_in_base(q) - point_in_base
Eigen::Vector3d Residual(const ModelState& state, const Measurement& m);

// A known distance between two fixed points, as an extra residual
// weight * (|point_a - point_b| - distance_mm).
struct PointDistance {
  int a = 0, b = 0;  // indices into ModelState::points_in_base
  double distance_mm = 0.0;
  double weight = 1.0;
};

struct FitOptions {
  std::vector<PointDistance> distances;
  // Parameters the fit may change; every other one is held at its value.
  std::vector<ParamInfo> free;
  // When set, free geometry parameters stay within +-bound (chain's
  // bound_length_mm / bound_angle_rad) of this chain's values (the seed's
  // |x - t0| <= delta).
  const Chain* bounds_center = nullptr;
  // With bounds_center: a soft pull of each free geometry parameter towards
  // it (ridge regularisation), residual prior_weight * (x - center) / bound,
  // in mm-equivalents beside the tip residuals. 0 = none.
  double prior_weight = 0.0;
  // Bounds (internal units: mm, rad) that replace RowBound for the named
  // parameters: calibrate widens the bound of a well-determined parameter
  // the data press against (CalibrateResult::widened_bounds).
  std::map<std::string, double> bound_override;
  // Robust loss on the 3D residual: "none", "huber" or "cauchy", scale in mm.
  std::string loss = "none";
  double loss_scale_mm = 1.0;
  int max_iterations = 200;
  double function_tolerance = 1e-12;
  double parameter_tolerance = 1e-12;
  bool compute_covariance = true;
  int num_threads = 1;
};

struct FitSummary {
  bool converged = false;
  std::string termination;  // Ceres' message
  int iterations = 0;
  double initial_rms_mm = 0.0;  // RMS of |residual| over measurements
  double final_rms_mm = 0.0;
  std::vector<double> residual_mm;  // |residual| per measurement
  // Noise estimate per axis: sqrt(sum r^2 / (3 m - p)), mm.
  double sigma0_mm = 0.0;
  // Free parameters, their values and 1-sigma (interface units: mm, deg);
  // sigma is NaN when the covariance could not be computed.
  std::vector<ParamInfo> params;
  std::vector<double> values;
  std::vector<double> sigmas;
  Eigen::MatrixXd covariance;  // internal units, order of `params`
  double seconds = 0.0;
};

FitSummary Fit(const std::vector<Measurement>& measurements,
               const FitOptions& options, ModelState* state);

// Half-width of a geometry parameter's box about FitOptions::bounds_center
// (internal units): the chain's bound_angle_rad for an angle,
// bound_length_mm for a length.
double RowBound(const Chain& center, const ParamInfo& p);
// RowBound unless `options` overrides the parameter's bound.
double RowBound(const Chain& center, const ParamInfo& p,
                const FitOptions& options);

// Jacobian of all stacked residuals (3 per measurement, then one per
// distance) with respect to `params` (internal units), evaluated at `state`,
// by the same autodiff functors the fit uses.
Eigen::MatrixXd ResidualJacobian(
    const std::vector<Measurement>& measurements, const ModelState& state,
    const std::vector<ParamInfo>& params,
    const std::vector<PointDistance>& distances = {});

// Registers the measuring frame only (robot held fixed): an Umeyama
// (rigid, no scale) initial value from the model's tips, refined by Fit;
// each frame (Measurement::frame) on its own rows, `state` given as many
// frames as the measurements use. Needs >= 3 measured rows per frame that
// are not collinear; throws InputError otherwise. Fixed points, if any, are set
// to their groups' centroids first.
void InitializeFrameAndPoints(const std::vector<Measurement>& measurements,
                              ModelState* state);

// Number of distinct joint-reading vectors among the measurements (repeated
// poses count once): what bounds how much the data can determine.
int DistinctPoses(const std::vector<Measurement>& measurements);

struct ErrorStats {
  int n = 0;
  double rms_mm = 0, mean_mm = 0, max_mm = 0, std_mm = 0;
};
ErrorStats ComputeErrorStats(const std::vector<double>& errors_mm);

}  // namespace kincal

#endif  // KINCAL_CALIB_FIT_H_
