#ifndef KINCAL_DIAGNOSE_CROSS_VALIDATION_H_
#define KINCAL_DIAGNOSE_CROSS_VALIDATION_H_

// K-fold cross-validation of the model selection of `diagnose model`
// (docs/DIAGNOSE.md "k-fold cross-validation").
//
// The training poses are split into K folds (seeded; poses with identical
// joint readings always share a fold, so a repeated pose never predicts
// itself). A model's cross-validated RMS is the pooled RMS of |residual| over
// all training poses, each predicted by the model fitted on the K - 1 folds
// it is not in:
//   cv_rms = sqrt( sum_k sum_{i in fold k} |r_i(x_{-k})|^2 / n ).
// x_{-k} is the fit without fold k, started from the fit on all training
// poses x* (a warm start). Two ways to get it:
//   - linearised (default): one Gauss-Newton step of the fold's fit from x*,
//     x_{-k} = x* + d, (J_{-k}^T J_{-k}) d = -J_{-k}^T r_{-k}, Jacobi-scaled,
//     projected onto the +-delta box; the held-out fold is predicted as
//     r_k + J_k d. One exact Jacobian (calib/exact_jacobian.h) of the
//     fitted model serves all K folds: J^T J and J^T r are summed per fold
//     once, each fold's normal equations are the total minus its own.
//   - refit: Levenberg-Marquardt (calib/free_fit.h) on the K - 1 folds
//     from x*, to convergence; K fits per model (the reference that the
//     bench compares the linearised figure with).

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "calib/fit.h"
#include "calib/free_fit.h"
#include "calib/model_state.h"

namespace kincal {

struct FoldPlan {
  int folds = 0;             // 0 = no cross-validation
  std::vector<int> fold_of;  // per measurement, in [0, folds)
};

// Seeded assignment of `ms` to `folds` folds of (nearly) equal size, each
// series' frame (Measurement::frame) spread evenly over them; groups of
// identical joint readings (within a series) stay together. Requires 2 <= folds
// <= DistinctPoses(ms) (callers check and say so).
FoldPlan MakeFolds(const std::vector<Measurement>& ms, int folds,
                   uint64_t seed);

// Cross-validated RMS (3D, mm) of the model `fitted` (already fitted on all
// of `ms` with `options.free` free, `options.bounds_center` the box). With
// `r` / `J` given (the residuals and Jacobian of `ms` at `fitted` in
// options.free) the linearised path does not recompute them. refit = true:
// full Levenberg-Marquardt fits per fold instead of the linearised step.
// `per_pose` (optional) receives each measurement's out-of-fold squared
// error |r_i(x_{-k})|^2 (mm^2), for paired comparisons of two models.
double CrossValidatedRms(const std::vector<Measurement>& ms,
                         const FoldPlan& plan, const ModelState& fitted,
                         const FreeFitOptions& options, bool refit = false,
                         std::vector<double>* per_pose = nullptr,
                         const Eigen::VectorXd* r = nullptr,
                         const Eigen::MatrixXd* J = nullptr);

// Paired comparison of two models' out-of-fold squared errors on the same
// poses: z = mean(a_i - b_i) / (sd(a_i - b_i) / sqrt(n)), > 0 when b
// predicts better; 0 when the two are identical, +-inf when every pose
// differs by the same amount.
double PairedZ(const std::vector<double>& a, const std::vector<double>& b);

}  // namespace kincal

#endif  // KINCAL_DIAGNOSE_CROSS_VALIDATION_H_
