#ifndef KINCAL_CAMCAL_BOARD_WARP_H_
#define KINCAL_CAMCAL_BOARD_WARP_H_

// mrcal's board deflection ("calobject_warp"): a planar target that is not
// quite flat, modelled as a paraboloid over the board with two parameters
// (target units):
//   z = warp_x * (1 - u^2) + warp_y * (1 - v^2)
// with u, v = the point's x, y scaled to [-1, 1] over the board's extent
// (mrcal's 4 xr (1 - xr) with xr in [0, 1]). The edges stay in the plane;
// the centre moves by warp_x + warp_y along the target's z.

#include <ceres/ceres.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <vector>

#include "camcal/cost_functions.h"

namespace kincal {

// The extent of the target points over which u, v run from -1 to 1.
struct BoardExtent {
  double x_min = 0, x_max = 1, y_min = 0, y_max = 1;

  // The bounding box of `points` (x and y); a degenerate side keeps width 1.
  static BoardExtent Of(const std::vector<Eigen::Vector3d>& points);
};

// p_in_target moved by the warp (parameters warp[0] = warp_x, warp[1] =
// warp_y).
template <typename T>
Eigen::Matrix<T, 3, 1> WarpedPoint(const Eigen::Vector3d& p_in_target,
                                   const BoardExtent& extent, const T* warp) {
  const double u =
      2.0 * (p_in_target.x() - extent.x_min) / (extent.x_max - extent.x_min) -
      1.0;
  const double v =
      2.0 * (p_in_target.y() - extent.y_min) / (extent.y_max - extent.y_min) -
      1.0;
  Eigen::Matrix<T, 3, 1> p = p_in_target.cast<T>();
  p.z() += warp[0] * T(1.0 - u * u) + warp[1] * T(1.0 - v * v);
  return p;
}

// Reprojection error of a warped target point seen by the reference camera:
//   residual = ProjectPoint(intrinsics,
//                 rig_from_target * WarpedPoint(p_in_target, warp)) - pixel
class WarpedTargetReprojectionError {
 public:
  WarpedTargetReprojectionError(const Eigen::Vector3d& p_in_target,
                                const Eigen::Vector2d& pixel,
                                const BoardExtent& extent)
      : p_in_target_(p_in_target), pixel_(pixel), extent_(extent) {}

  template <typename T>
  bool operator()(const T* intrinsics, const T* rig_from_target_q,
                  const T* rig_from_target_t, const T* warp,
                  T* residuals) const {
    const Eigen::Map<const Eigen::Quaternion<T>> q(rig_from_target_q);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> t(rig_from_target_t);
    const Eigen::Matrix<T, 3, 1> p_in_cam =
        q * WarpedPoint(p_in_target_, extent_, warp) + t;
    return PixelResidual(intrinsics, p_in_cam.data(), pixel_, residuals);
  }

  static ceres::CostFunction* Create(const Eigen::Vector3d& p_in_target,
                                     const Eigen::Vector2d& pixel,
                                     const BoardExtent& extent) {
    return new ceres::AutoDiffCostFunction<WarpedTargetReprojectionError, 2,
                                           kNumIntrinsics, 4, 3, 2>(
        new WarpedTargetReprojectionError(p_in_target, pixel, extent));
  }

 private:
  const Eigen::Vector3d p_in_target_;
  const Eigen::Vector2d pixel_;
  const BoardExtent extent_;
};

// The same seen by a non-reference camera:
//   residual = ProjectPoint(intrinsics, cam_from_rig * rig_from_target *
//                 WarpedPoint(p_in_target, warp)) - pixel
class WarpedRigTargetReprojectionError {
 public:
  WarpedRigTargetReprojectionError(const Eigen::Vector3d& p_in_target,
                                   const Eigen::Vector2d& pixel,
                                   const BoardExtent& extent)
      : p_in_target_(p_in_target), pixel_(pixel), extent_(extent) {}

  template <typename T>
  bool operator()(const T* intrinsics, const T* cam_from_rig_q,
                  const T* cam_from_rig_t, const T* rig_from_target_q,
                  const T* rig_from_target_t, const T* warp,
                  T* residuals) const {
    const Eigen::Map<const Eigen::Quaternion<T>> q_cr(cam_from_rig_q);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> t_cr(cam_from_rig_t);
    const Eigen::Map<const Eigen::Quaternion<T>> q_rt(rig_from_target_q);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> t_rt(rig_from_target_t);
    const Eigen::Matrix<T, 3, 1> p_in_rig =
        q_rt * WarpedPoint(p_in_target_, extent_, warp) + t_rt;
    const Eigen::Matrix<T, 3, 1> p_in_cam = q_cr * p_in_rig + t_cr;
    return PixelResidual(intrinsics, p_in_cam.data(), pixel_, residuals);
  }

  static ceres::CostFunction* Create(const Eigen::Vector3d& p_in_target,
                                     const Eigen::Vector2d& pixel,
                                     const BoardExtent& extent) {
    return new ceres::AutoDiffCostFunction<WarpedRigTargetReprojectionError, 2,
                                           kNumIntrinsics, 4, 3, 4, 3, 2>(
        new WarpedRigTargetReprojectionError(p_in_target, pixel, extent));
  }

 private:
  const Eigen::Vector3d p_in_target_;
  const Eigen::Vector2d pixel_;
  const BoardExtent extent_;
};

}  // namespace kincal

#endif  // KINCAL_CAMCAL_BOARD_WARP_H_
