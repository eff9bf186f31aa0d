#ifndef KINCAL_CALIB_IDENTIFIABILITY_H_
#define KINCAL_CALIB_IDENTIFIABILITY_H_

// Which parameters the data determine. Method: the Jacobian of all residuals
// with respect to the candidate parameters, each column scaled to unit norm
// (so mm and rad compare), is scanned in priority order with Gram-Schmidt: a
// parameter is identifiable when the part of its column outside the span of
// the columns already accepted is larger than `tolerance` (the sine of the
// angle between the column and that span). Otherwise it is a combination of
// accepted parameters: it is held at its nominal value and listed, with the
// combination that makes it redundant. Priority order puts the measuring
// frame and fixed points first, then rows in chain order, so redundant robot
// parameters are the ones dropped.

#include <Eigen/Core>
#include <string>
#include <vector>

#include "calib/fit.h"
#include "calib/model_state.h"

namespace kincal {

struct IdentifiabilityOptions {
  // sin(angle) below which a column counts as inside the span of the earlier
  // ones. 1e-6 separates exact (structural) redundancy, which leaves ~1e-12,
  // from merely weak determination; weak parameters are flagged separately.
  double tolerance = 1e-6;
  // Columns with sin(angle) below this are "weak": estimated, but with a
  // large sigma; listed in `weak`.
  double weak_tolerance = 1e-2;
  // Statistical criterion, used when noise_sigma_mm > 0 (at a solution): a
  // row parameter is determined only if its predicted 1-sigma given the
  // parameters accepted before it, noise_sigma_mm / |part of its column
  // outside their span|, is below max_sigma_fraction of its admissible
  // deviation (the robot's bounds: length or angle). This catches
  // redundancies that are exact only where the model fits (e.g. a rigid
  // rotation of the whole arm with single-point data), which the sine test
  // misses away from the solution.
  double noise_sigma_mm = 0.0;
  double max_sigma_fraction = 0.1;
};

struct Identifiability {
  std::vector<ParamInfo> identifiable;    // in priority order
  std::vector<ParamInfo> unidentifiable;  // held at nominal
  std::vector<std::string> weak;          // identifiable but poorly
  // Predicted 1-sigma (interface units) of each identifiable parameter given
  // the ones before it; NaN without a noise level.
  std::vector<double> conditional_sigma;
  // For each unidentifiable parameter: "j2.d = +1.000 frame.z - 1.000 j1.d"
  // (linearised effect on the residuals; up to 4 largest terms).
  std::vector<std::string> relations;
  // Singular values of the column-normalised Jacobian of the identifiable
  // parameters, largest first; condition = first / last.
  std::vector<double> singular_values;
  double condition = 0.0;

  std::vector<std::string> IdentifiableNames() const;
  // Identifiable parameters of the robot itself (not frame.*, point.*).
  int RobotParameterCount() const;
  std::vector<std::string> UnidentifiableNames() const;
};

Identifiability AnalyzeIdentifiability(
    const std::vector<Measurement>& measurements, const ModelState& state,
    const std::vector<ParamInfo>& candidates,
    const IdentifiabilityOptions& options = {},
    const std::vector<PointDistance>& distances = {});

// The same scan on a Jacobian the caller computed, column c belonging to
// candidates[c] in priority order, for residuals that are not tip points
// (the image bundle's pixels: options.noise_sigma_mm is then the pixel
// noise, in the residuals' unit). `chain` gives the row parameters' bounds.
// A column that stands for no robot parameter (a frame's pose) is passed
// as a ParamInfo of kind kFrame: it takes part in the span, without the
// bound test.
Identifiability AnalyzeJacobianColumns(
    const Eigen::MatrixXd& jacobian, const std::vector<ParamInfo>& candidates,
    const Chain& chain, const IdentifiabilityOptions& options = {});

}  // namespace kincal

#endif  // KINCAL_CALIB_IDENTIFIABILITY_H_
