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
};

struct Identifiability {
  std::vector<ParamInfo> identifiable;    // in priority order
  std::vector<ParamInfo> unidentifiable;  // held at nominal
  std::vector<std::string> weak;          // identifiable but poorly
  // For each unidentifiable parameter: "j2.d = +1.000 frame.z - 1.000 j1.d"
  // (linearised effect on the residuals; up to 4 largest terms).
  std::vector<std::string> relations;
  // Singular values of the column-normalised Jacobian of the identifiable
  // parameters, largest first; condition = first / last.
  std::vector<double> singular_values;
  double condition = 0.0;

  std::vector<std::string> IdentifiableNames() const;
  std::vector<std::string> UnidentifiableNames() const;
};

Identifiability AnalyzeIdentifiability(
    const std::vector<Measurement>& measurements, const ModelState& state,
    const std::vector<ParamInfo>& candidates,
    const IdentifiabilityOptions& options = {},
    const std::vector<PointDistance>& distances = {});

}  // namespace kincal

#endif  // KINCAL_CALIB_IDENTIFIABILITY_H_
