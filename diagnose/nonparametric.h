#ifndef KINCAL_DIAGNOSE_NONPARAMETRIC_H_
#define KINCAL_DIAGNOSE_NONPARAMETRIC_H_

// The honest last resort of `diagnose model`: a smooth non-parametric
// correction of the residual over the pose inputs (joint readings, t,
// temp_c), k-nearest-neighbour regression on standardised inputs with k and
// the input subset chosen by k-fold cross-validation on the training poses.
// It names no cause: it says which inputs the unexplained part depends on
// (`depends_on`, strongest first) and how much of it a smooth function of
// them predicts on poses it was not fitted to (held-out RMS before / after).

#include <Eigen/Core>
#include <limits>
#include <string>
#include <vector>

namespace kincal {

struct SmoothInputs {
  std::vector<std::string> names;                // one per input column
  std::vector<std::vector<double>> train, held;  // [pose][input]
  // The measured point of every training pose (measuring frame, mm); empty
  // when the data have none (single-point data without metrology).
  std::vector<Eigen::Vector3d> point_train;
};

struct SmoothCorrection {
  // Inputs of the chosen subset, strongest first (single-input CV gain).
  std::vector<std::string> depends_on;
  int k = 0;  // neighbours
  // Share of the training residual power the correction predicts in
  // cross-validation (0 = nothing, negative = worse than none).
  double cv_explained = 0.0;
  double heldout_rms_before_mm = 0.0, heldout_rms_after_mm = 0.0;
  // Per single input: its cross-validated share of the residual power.
  std::vector<std::pair<std::string, double>> single;
  // Robot or instrument: the share a smooth function of the measured
  // point's position (x, y, z in the measuring frame, one scale) predicts in
  // the same cross-validation. An error of the measuring instrument depends
  // on where the point is in the instrument's frame, not on the joint
  // configuration that put it there; an error of the robot follows the
  // joints. NaN when the data have no measured points.
  double point_cv_explained = std::numeric_limits<double>::quiet_NaN();
};

// `train_res` / `held_res`: residual vectors (mm) of the final model.
// `folds`: k-fold cross-validation; `max_train`: training poses used for
// the search (a seeded subsample above it keeps the cost bounded).
SmoothCorrection FitSmoothCorrection(
    const SmoothInputs& inputs, const std::vector<Eigen::Vector3d>& train_res,
    const std::vector<Eigen::Vector3d>& held_res, int folds = 5,
    int max_train = 1200);

}  // namespace kincal

#endif  // KINCAL_DIAGNOSE_NONPARAMETRIC_H_
