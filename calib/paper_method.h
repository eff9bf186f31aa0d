#ifndef KINCAL_CALIB_PAPER_METHOD_H_
#define KINCAL_CALIB_PAPER_METHOD_H_

// The seed paper's accuracy model (Wang, Cao, Liu 2013, eq. 9):
//   min_x eps(x) = 1/n sum_i | f(x + dt_i) - 1/n sum_j f(x + dt_j) |
//   s.t. |x - t0| <= delta,
// per fixed point, solved by a derivative-free direct search.

#include <vector>

#include "calib/fit.h"
#include "calib/model_state.h"

namespace kincal {

struct PaperOptions {
  std::vector<ParamInfo> free;          // parameters x (robot geometry)
  const Chain* bounds_center = nullptr;  // t0; delta from the chain's bounds
  int max_evaluations = 200000;
};

// Minimises the paper's epsilon over the fixed-point measurements in `ms`
// (measured rows are ignored). Fills the summary like Fit (final_rms_mm is
// the RMS of the distances to the centroids); sets the fixed points to the
// final centroids.
FitSummary FitPaperObjective(const std::vector<Measurement>& ms,
                             const PaperOptions& options, ModelState* state);

}  // namespace kincal

#endif  // KINCAL_CALIB_PAPER_METHOD_H_
