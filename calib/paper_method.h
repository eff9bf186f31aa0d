#ifndef KINCAL_CALIB_PAPER_METHOD_H_
#define KINCAL_CALIB_PAPER_METHOD_H_

// The seed paper's accuracy model (Wang, Cao, Liu 2013, eq. 9):
//   min_x eps(x) = 1/n sum_i | f(x + dt_i) - 1/n sum_j f(x + dt_j) |
//   s.t. |x - t0| <= delta,
// per fixed point, solved by a derivative-free direct search.
//
// With several fixed points, eps is the mean over all fixed-point poses of
// the distance of the model tip to the centroid of its own group (each group
// is eq. 8; pooling them keeps every pose's weight 1/n as in eq. 8).
//
// Search (docs/PAPER_METHOD.md): the paper names "variable rotation"
// (cyclic coordinate search) and "simplex" (Nelder-Mead, Matlab's
// fminsearch). The default runs both: Nelder-Mead with the dimension-adaptive
// coefficients of Gao & Han (2012), restarted from its best vertex until a
// restart no longer improves eps (plain Nelder-Mead stalls in > 10
// dimensions), then a cyclic coordinate ("variable rotation") pattern search
// that polishes the result and certifies it: it stops only when no single
// parameter step of the final size improves eps. The variables are scaled by
// delta (u = (x - t0) / delta in [-1, 1]), so mm and rad compare; trial
// points are clamped to the box |x - t0| <= delta.

#include <vector>

#include "calib/fit.h"
#include "calib/model_state.h"

namespace kincal {

struct PaperOptions {
  // Parameters x (robot geometry, joint errors). Frame and point parameters
  // in the list are ignored: the measuring frame plays no part in eq. 9 and
  // the fixed points are the centroids (eliminated, not searched).
  std::vector<ParamInfo> free;
  const Chain* bounds_center = nullptr;  // t0; delta from the chain's bounds
  int max_evaluations = 200000;

  enum Search { kSimplex, kCoordinate, kSimplexThenCoordinate };
  Search search = kSimplexThenCoordinate;
  int max_restarts = 30;      // Nelder-Mead restarts
  double initial_step = 0.1;  // simplex edge / coordinate step, in delta units
  double min_step = 1e-7;  // coordinate search stops below this (delta units)
  double tolerance_mm = 1e-10;  // restarts stop when eps improves by less

  // Extension beyond the paper: known distances between fixed points (the
  // scale that single-point data lacks) as an exact L1 penalty
  //   eps + distance_weight * sum | |c_a - c_b| - distance_mm |
  // on the group centroids c. With a weight above d eps / d scale the
  // constraint holds exactly at the optimum.
  std::vector<PointDistance> distances;
  double distance_weight = 10.0;
};

// Per fixed-point measurement (in order): distance of the model tip to the
// centroid of its group (measured rows are skipped). Mean = the paper's eps.
std::vector<double> PaperDistances(const ModelState& state,
                                   const std::vector<Measurement>& ms);
// The paper's eps (eq. 8 pooled over groups), mm.
double PaperEpsilon(const ModelState& state,
                    const std::vector<Measurement>& ms);

// Minimises the paper's epsilon over the fixed-point measurements in `ms`
// (measured rows are ignored). Fills the summary like Fit (final_rms_mm is
// the RMS of the distances to the centroids; residual_mm the distances;
// sigmas are the Gauss-Newton linearisation at the solution of the
// equivalent least-squares problem with the points free, NaN when singular);
// `iterations` counts objective evaluations. Sets the fixed points to the
// final centroids. Throws InputError when `ms` has no fixed-point group with
// at least 2 poses.
FitSummary FitPaperObjective(const std::vector<Measurement>& ms,
                             const PaperOptions& options, ModelState* state);

}  // namespace kincal

#endif  // KINCAL_CALIB_PAPER_METHOD_H_
