#ifndef KINCAL_CALIB_CALIBRATE_H_
#define KINCAL_CALIB_CALIBRATE_H_

// The calibration workflow behind `kincal calibrate`: split poses into
// training and held-out (seeded, within every series), register the
// measuring frame (one per series, spec v3 column `series`), decide which
// parameters the training data determine, fit them (bounded by the robot
// file's +-delta), and report training and held-out error.

#include <cstdint>
#include <functional>
#include <set>
#include <string>
#include <vector>

#include "calib/fit.h"
#include "calib/identifiability.h"
#include "calib/model_state.h"
#include "calib/outliers.h"
#include "data/observations.h"
#include "data/robot.h"

namespace kincal {

// A known distance between two fixed points (mm): the scale reference that
// single-point data lacks (e.g. two sockets 50 mm apart).
struct FixedDistance {
  std::string a, b;
  double distance_mm = 0.0;
};

struct CalibrateOptions {
  enum Method { kLeastSquares, kPaper };
  Method method = kLeastSquares;
  // Fraction of poses held out of the fit to measure prediction error
  // (per fixed-point group for single-point data). 0 = none.
  double holdout_fraction = 0.2;
  uint64_t seed = 1;
  std::string loss = "none";  // none | huber | cauchy
  double loss_scale_mm = 1.0;
  IdentifiabilityOptions identifiability;
  std::vector<FixedDistance> distances;
  // Weight of each known distance's residual weight * (|a - b| - d) beside
  // the tip residuals (mm). 10 holds the distance to ~1 um for tip noise of
  // ~0.1-1 mm, i.e. a near-hard constraint; on the MUKCa Pandas 1000 gives
  // the same held-out figures and 1 lets the tips pull it 0.4 mm off
  // (docs/REAL_DATA.md).
  double distance_weight = 10.0;
  // The least-squares fits' residual and Jacobian passes (and Ceres's) on
  // up to this many threads.
  int num_threads = 1;
  // Extra parameters to free besides the row geometry (e.g. "j2.beta").
  std::vector<std::string> extra_params;
  // Fit the geometry (false: only the frame / fixed points, as `evaluate`).
  bool fit_geometry = true;
  // Passes of fit -> identifiability at the solution -> fit, until the free
  // set is stable (1 = decide once, at the start values).
  int max_identifiability_passes = 6;
  // Ridge pull of the geometry towards the nominal model (FitOptions::
  // prior_weight); 0 = none. Negative (the default): 1 for single-point
  // data (no measured tip point), 0 with measured points. Two fixed points
  // x 30 poses of a Panda 2-5 mm / 0.6-1.5 deg from nominal: without the
  // pull the calibrated model predicted the workspace 7-36x worse (23-73 mm
  // RMS against 0.9-7.6 mm with it) at nearly the same training RMS; with
  // 240 measured points the pull only biases far deviations (docs/
  // CALIBRATION.md).
  double prior_weight = -1.0;
  // The first look (at the start values) also holds parameters whose
  // predicted 1-sigma, for a noise level of this fraction of the misfit
  // after registering the frame, exceeds IdentifiabilityOptions::
  // max_sigma_fraction of their admissible range. 0 = sine test only.
  double first_look_noise_fraction = 0.1;
  // Training rows whose error exceeds this many robust sigmas (per axis,
  // from the median error) are gross errors: left out of the fit, which is
  // repeated from the nominal model until the set is stable, and listed
  // (calib/outliers.h). Held-out rows beyond it are listed and left out of
  // the held-out figures. 0 = keep every row.
  double outlier_sigmas = kDefaultOutlierSigmas;
};

// One pass of fit -> identifiability: parameters that entered (freed) or
// left (held) the free set compared with the pass before, and the fit.
struct IdentifiabilityPass {
  int num_free = 0;
  std::vector<std::string> freed, held;
  double train_rms_mm = 0.0;
  bool undone = false;  // its fit ended worse: the pass before was kept
};

// A bound calibrate widened because the data pressed a well-determined
// parameter against it (interface units: mm, deg).
struct WidenedBound {
  std::string name;
  double from = 0.0, to = 0.0;
};

struct CalibrateResult {
  Robot calibrated;  // nominal description with fitted values
  ModelState state;
  Identifiability identifiability;  // of the final pass
  // Passes run (the first decides at the start values); freed / held: the
  // final set against the first one.
  std::vector<IdentifiabilityPass> passes;
  std::vector<std::string> freed, held;
  FitSummary fit;
  std::vector<int> train_rows, heldout_rows;  // indices in observations
  ErrorStats train, heldout;                  // |residual| statistics, mm
  // Single-point data: the seed's epsilon (mean distance to the group
  // centroid), its max and std, on the training poses (Table 2's footer).
  bool has_epsilon = false;
  ErrorStats epsilon;
  std::vector<double> distance_errors_mm;  // per FixedDistance
  // Bounds widened during the fit, in order, and the parameters that still
  // end on their bound (the robot may deviate more than the bounds allow).
  std::vector<WidenedBound> widened_bounds;
  std::vector<std::string> at_bound;
  double seconds = 0.0;
  std::string method;
  double prior_weight = 0.0;  // the ridge weight used
  // Gross errors (CalibrateOptions::outlier_sigmas): the rows beyond the
  // threshold, the robust per-axis sigma of the fitted rows (mm), the
  // rounds of fit -> flag -> refit run, and whether more rows than a fit
  // can spare were beyond it (training or held-out; those are kept).
  std::vector<RowOutlier> outliers;
  double outlier_axis_sigma_mm = 0.0;
  int outlier_rounds = 1;
  bool outliers_too_many = false;
};

CalibrateResult Calibrate(const Robot& nominal, const Observations& obs,
                          const CalibrateOptions& options);

// The least-squares solver of the geometry's fits: calib/fit.h's Fit
// (Ceres, autodiff through the chain; `calibrate`) or Levenberg-Marquardt on
// the exact Jacobian (calib/free_fit.h FreeFitWithCovariance; the base model
// of `diagnose`). Same problem and bounds.
enum class GeometrySolver { kCeres, kExactJacobian };

// What FitGeometry fits: the training rows of `obs` from the nominal model.
struct GeometryProblem {
  const Observations* obs = nullptr;  // the rows' source
  const Chain* nominal = nullptr;     // start and centre of the bounds
  bool bounds_stated = false;         // Robot::bounds_stated
  // The parameters the fit may free: frame / points, geometry, extras.
  std::vector<ParamInfo> candidates;
  // The misfit after registering the frame / points, per axis (mm).
  double registered_sigma0_mm = 0.0;
  std::vector<PointDistance> distances;
  // Training rows, and held-out rows (may be null): their joint-error
  // inputs are recomputed from the fitted geometry.
  std::vector<Measurement>* train = nullptr;
  std::vector<Measurement>* held = nullptr;
  // Called with the first look's free set (callers throw their InputError
  // there); may be empty.
  std::function<void(const Identifiability&)> check;
  GeometrySolver solver = GeometrySolver::kCeres;
};

struct GeometryFit {
  Identifiability identifiability;  // of the final pass
  std::vector<IdentifiabilityPass> passes;
  std::set<std::string> first_set;  // the free set of the first look
  FitSummary fit;
  double prior_weight = 0.0;  // the ridge weight used
  // The options of the last fit (free set, bounds widened): bounds_center
  // is null, the caller's nominal chain goes there.
  FitOptions fit_options;
  std::vector<WidenedBound> widened_bounds;
  std::vector<std::string> at_bound;
};

// The geometry from the nominal model, as `calibrate` fits it, for callers
// with measurements of their own (diagnose's base model):
//   1. the first look at the start values: the sine test and, with a noise
//      level of options.first_look_noise_fraction x
//      problem.registered_sigma0_mm, the parameters too weak to free;
//   2. problem.check on that set;
//   3. fit, identifiability at the solution, refit, until the free set is
//      stable (at most options.max_identifiability_passes);
//   4. bounds the robot does not state widened where a free parameter ends
//      on them (CalibrateResult::widened_bounds).
// `state` holds the registered frame / points on entry, the fitted model on
// return. Least squares only: options.method is not used.
GeometryFit FitGeometry(const GeometryProblem& problem,
                        const CalibrateOptions& options, ModelState* state);

// The seed's epsilon for fixed-point measurements: for each group, distances
// of the model tips to the group's centroid.
std::vector<double> CentroidDistances(const ModelState& state,
                                      const std::vector<Measurement>& ms);

}  // namespace kincal

#endif  // KINCAL_CALIB_CALIBRATE_H_
