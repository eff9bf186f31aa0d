#ifndef KINCAL_VISION_PIVOT_H_
#define KINCAL_VISION_PIVOT_H_

// Pivot calibration of the needle tip offset: the needle tip rests in a fixed
// divot while the tool is turned about it. For every tool pose i
//   R_i * tip_in_tool + t_i = pivot_in_rig,
// i.e. [R_i  -I] [tip_in_tool; pivot_in_rig] = -t_i, stacked over all poses
// and solved by linear least squares (SVD). The residual of pose i is
// |R_i * tip_in_tool + t_i - pivot_in_rig| (mm).

#include <Eigen/Core>
#include <vector>

#include "camcal/camera_model.h"

namespace kincal {

struct PivotResult {
  Eigen::Vector3d tip_in_tool = Eigen::Vector3d::Zero();
  Eigen::Vector3d pivot_in_rig = Eigen::Vector3d::Zero();
  double rms_mm = 0;  // RMS of the per-pose residuals
  double max_mm = 0;
  std::vector<double> residuals_mm;  // one per pose
  // Smallest / largest singular value of the stacked system: near 0 when the
  // rotations do not span two axes (the offset along the axis is unknown).
  double conditioning = 0;
  // 1-sigma of tip_in_tool and pivot_in_rig per axis (mm), from the linear
  // least squares, robust to pose errors that differ from pose to pose in
  // size and direction (the depth of a stereo pose errs most):
  // (A^T A)^-1 (sum_i A_i^T e_i e_i^T A_i) (A^T A)^-1 over the poses, e_i =
  // (I - A_i (A^T A)^-1 A_i^T)^-1 r_i the residual of pose i had it been
  // left out of the fit. Isotropic noise: as sigma^2 (A^T A)^-1.
  Eigen::Vector3d tip_sigma_mm = Eigen::Vector3d::Zero();
  Eigen::Vector3d pivot_sigma_mm = Eigen::Vector3d::Zero();
  // The full 3x3 covariance of tip_in_tool behind tip_sigma_mm (mm^2).
  Eigen::Matrix3d tip_covariance = Eigen::Matrix3d::Zero();
  // How far the tool was tilted: the extent (max - min, deg) of the poses'
  // rotations about the second principal axis of their spread (the smaller
  // of the two largest; a needle turned about one axis only has ~0).
  double tilt_range_deg = 0;
  // Per pose 3x3 weight of its residual (identity without pose
  // covariances); the covariances above are those of the weighted fit.
  std::vector<Eigen::Matrix3d> weights;
};

// Tilt range of a set of tool poses, as PivotResult::tilt_range_deg.
double PivotTiltRangeDeg(const std::vector<Rigid3>& rig_from_tool);

// rig_from_tool: tool poses (mm) while pivoting. Throws InputError for fewer
// than 3 poses, rotations that leave the offset undetermined
// (conditioning < min_conditioning, e.g. all about one axis), or a tilt
// range below min_tilt_range_deg (the message says how to record instead).
//
// pose_covariances (optional, one 6x6 per pose in the order (a, dt) of
// PivotTipJacobian; only their shape matters, any common scale): the fit is
// then weighted by how each pose errs, W_i = (B_i C_i B_i^T)^-1 with
// B_i = [-[R_i tip]x  I] the residual's change with pose i (iterated from
// the unweighted tip): a camera pose errs mostly by a turn about the tags
// with a matching shift, which moves the tip 100 mm away by far more than
// it moves the tags, so the weights lean on where the tags went rather
// than on how they turned. Stored in PivotResult::weights.
PivotResult PivotCalibration(
    const std::vector<Rigid3>& rig_from_tool, double min_conditioning = 1e-3,
    double min_tilt_range_deg = 0,
    const std::vector<Eigen::Matrix<double, 6, 6>>& pose_covariances = {});

// How the least-squares tip moves with the tool poses: d tip_in_tool /
// d (a_i, dt_i), 3 x 6n, for pose i corrected as (exp([a_i]x) R_i, t_i +
// dt_i) (rotation vector a_i on the left, rad; dt_i in mm). With the pivot's
// residuals small, dx = -(A^T A)^-1 A^T de, where de_i = -[R_i tip]x a_i +
// dt_i is the change of pose i's residual at the fitted (tip, pivot).
// weights: PivotResult::weights of a weighted fit (empty: unweighted), then
// dx = -(A^T W A)^-1 A^T W de.
Eigen::MatrixXd PivotTipJacobian(
    const std::vector<Rigid3>& rig_from_tool,
    const Eigen::Vector3d& tip_in_tool,
    const std::vector<Eigen::Matrix3d>& weights = {});

}  // namespace kincal

#endif  // KINCAL_VISION_PIVOT_H_
