#ifndef KINCAL_CAMCAL_COST_FUNCTIONS_H_
#define KINCAL_CAMCAL_COST_FUNCTIONS_H_

// Reprojection cost functors (Ceres autodiff) shared by the camera
// calibration (camcal/calibrate_cameras.cc) and the tool pose estimate
// (vision/tool_pose.cc). Each keeps its measurement as const members, is
// built through a static Create, and composes a pose before ProjectPoint
// (camcal/camera_model.h). A point behind the camera makes the functor
// return false (Ceres then rejects the step); none throws.

#include <ceres/ceres.h>
#include <ceres/rotation.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>

#include "camcal/camera_model.h"
#include "camcal/rig.h"

namespace kincal {

// The reprojection residual every functor below ends with:
//   residual = ProjectPoint(intrinsics, p_in_cam) - pixel
// false (no residual) for a point ProjectPoint rejects (behind the camera).
template <typename T>
bool PixelResidual(const T* intrinsics, const T* p_in_cam,
                   const Eigen::Vector2d& pixel, T* residuals) {
  T projected[2];
  if (!ProjectPoint(intrinsics, p_in_cam, projected)) return false;
  residuals[0] = projected[0] - T(pixel.x());
  residuals[1] = projected[1] - T(pixel.y());
  return true;
}

// Reprojection error of a target point seen by the reference camera (whose
// frame is the rig frame):
//   residual = ProjectPoint(intrinsics, rig_from_target * p_in_target) - pixel
// rig_from_target is a unit quaternion (Eigen order x, y, z, w) and a
// translation in target units.
class TargetReprojectionError {
 public:
  TargetReprojectionError(const Eigen::Vector3d& p_in_target,
                          const Eigen::Vector2d& pixel)
      : p_in_target_(p_in_target), pixel_(pixel) {}

  template <typename T>
  bool operator()(const T* intrinsics, const T* rig_from_target_q,
                  const T* rig_from_target_t, T* residuals) const {
    const Eigen::Map<const Eigen::Quaternion<T>> q(rig_from_target_q);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> t(rig_from_target_t);
    const Eigen::Matrix<T, 3, 1> p_in_cam = q * p_in_target_.cast<T>() + t;
    return PixelResidual(intrinsics, p_in_cam.data(), pixel_, residuals);
  }

  static ceres::CostFunction* Create(const Eigen::Vector3d& p_in_target,
                                     const Eigen::Vector2d& pixel) {
    return new ceres::AutoDiffCostFunction<TargetReprojectionError, 2,
                                           kNumIntrinsics, 4, 3>(
        new TargetReprojectionError(p_in_target, pixel));
  }

 private:
  const Eigen::Vector3d p_in_target_;
  const Eigen::Vector2d pixel_;
};

// Reprojection error of a target point seen by a non-reference camera:
//   residual = ProjectPoint(intrinsics,
//                 cam_from_rig * rig_from_target * p_in_target) - pixel
class RigTargetReprojectionError {
 public:
  RigTargetReprojectionError(const Eigen::Vector3d& p_in_target,
                             const Eigen::Vector2d& pixel)
      : p_in_target_(p_in_target), pixel_(pixel) {}

  template <typename T>
  bool operator()(const T* intrinsics, const T* cam_from_rig_q,
                  const T* cam_from_rig_t, const T* rig_from_target_q,
                  const T* rig_from_target_t, T* residuals) const {
    const Eigen::Map<const Eigen::Quaternion<T>> q_cr(cam_from_rig_q);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> t_cr(cam_from_rig_t);
    const Eigen::Map<const Eigen::Quaternion<T>> q_rt(rig_from_target_q);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> t_rt(rig_from_target_t);
    const Eigen::Matrix<T, 3, 1> p_in_rig =
        q_rt * p_in_target_.cast<T>() + t_rt;
    const Eigen::Matrix<T, 3, 1> p_in_cam = q_cr * p_in_rig + t_cr;
    return PixelResidual(intrinsics, p_in_cam.data(), pixel_, residuals);
  }

  static ceres::CostFunction* Create(const Eigen::Vector3d& p_in_target,
                                     const Eigen::Vector2d& pixel) {
    return new ceres::AutoDiffCostFunction<RigTargetReprojectionError, 2,
                                           kNumIntrinsics, 4, 3, 4, 3>(
        new RigTargetReprojectionError(p_in_target, pixel));
  }

 private:
  const Eigen::Vector3d p_in_target_;
  const Eigen::Vector2d pixel_;
};

// Quadratic regulariser of the rational distortion coefficients k4 k5 k6
// (intrinsics[kK4..]), pulling them toward 0 as mrcal regularises its
// distortions:
//   residual_i = scale * intrinsics[kK4 + i],  i = 0, 1, 2
// so the cost adds 1/2 scale^2 (k4^2 + k5^2 + k6^2). `scale` is sized by the
// caller relative to the number of pixel residuals (calibrate_cameras.cc).
class RationalDistortionRegularizationError {
 public:
  static constexpr int kNumRational = 3;
  static constexpr int kK4 = kNumIntrinsics - kNumRational;

  explicit RationalDistortionRegularizationError(double scale)
      : scale_(scale) {}

  template <typename T>
  bool operator()(const T* intrinsics, T* residuals) const {
    for (int i = 0; i < kNumRational; ++i) {
      residuals[i] = T(scale_) * intrinsics[kK4 + i];
    }
    return true;
  }

  static ceres::CostFunction* Create(double scale) {
    return new ceres::AutoDiffCostFunction<
        RationalDistortionRegularizationError, kNumRational, kNumIntrinsics>(
        new RationalDistortionRegularizationError(scale));
  }

 private:
  const double scale_;
};

// mrcal's lens regulariser: every distortion coefficient pulled toward 0
// and the principal point toward the image centre (centre_x, centre_y):
//   residual_i     = distortion_scale * intrinsics[kK1 + i],  i = 0 .. 7
//   residual_8, _9 = centre_scale * (cx - centre_x), centre_scale * (cy -
//   centre_y)
// Coefficients beyond the model are fixed at 0 and add nothing. The scales
// are sized by the caller relative to the number of pixel residuals
// (calibrate_cameras.cc, LensRegularizationScales).
class LensRegularizationError {
 public:
  static constexpr int kNumDistortion = kNumIntrinsics - kK1;
  static constexpr int kNumResiduals = kNumDistortion + 2;

  LensRegularizationError(double distortion_scale, double centre_scale,
                          double centre_x, double centre_y)
      : distortion_scale_(distortion_scale),
        centre_scale_(centre_scale),
        centre_x_(centre_x),
        centre_y_(centre_y) {}

  template <typename T>
  bool operator()(const T* intrinsics, T* residuals) const {
    for (int i = 0; i < kNumDistortion; ++i) {
      residuals[i] = T(distortion_scale_) * intrinsics[kK1 + i];
    }
    residuals[kNumDistortion] =
        T(centre_scale_) * (intrinsics[kCx] - T(centre_x_));
    residuals[kNumDistortion + 1] =
        T(centre_scale_) * (intrinsics[kCy] - T(centre_y_));
    return true;
  }

  static ceres::CostFunction* Create(double distortion_scale,
                                     double centre_scale, double centre_x,
                                     double centre_y) {
    return new ceres::AutoDiffCostFunction<LensRegularizationError,
                                           kNumResiduals, kNumIntrinsics>(
        new LensRegularizationError(distortion_scale, centre_scale, centre_x,
                                    centre_y));
  }

 private:
  const double distortion_scale_;
  const double centre_scale_;
  const double centre_x_;
  const double centre_y_;
};

// A ray at infinity of one model, rotated, projected by another model:
//   residual = ProjectPoint(intrinsics_b, R(rotation_aa) * ray_a) - pixel
class RotatedRayError {
 public:
  RotatedRayError(const Eigen::Vector3d& ray_a, const Eigen::Vector2d& pixel,
                  const std::array<double, kNumIntrinsics>& intrinsics_b)
      : ray_a_(ray_a), pixel_(pixel), intrinsics_b_(intrinsics_b) {}

  template <typename T>
  bool operator()(const T* rotation_aa, T* residuals) const {
    const T ray[3] = {T(ray_a_.x()), T(ray_a_.y()), T(ray_a_.z())};
    T p_in_b[3];
    ceres::AngleAxisRotatePoint(rotation_aa, ray, p_in_b);
    T intrinsics[kNumIntrinsics];
    for (int i = 0; i < kNumIntrinsics; ++i)
      intrinsics[i] = T(intrinsics_b_[i]);
    return PixelResidual(intrinsics, p_in_b, pixel_, residuals);
  }

  static ceres::CostFunction* Create(
      const Eigen::Vector3d& ray_a, const Eigen::Vector2d& pixel,
      const std::array<double, kNumIntrinsics>& intrinsics_b) {
    return new ceres::AutoDiffCostFunction<RotatedRayError, 2, 3>(
        new RotatedRayError(ray_a, pixel, intrinsics_b));
  }

 private:
  const Eigen::Vector3d ray_a_;
  const Eigen::Vector2d pixel_;
  const std::array<double, kNumIntrinsics> intrinsics_b_;
};

// Reprojection of one tag corner of the tool into one camera:
//   r = pi(K, cam_from_rig * (rig_from_tool * p_in_tool)) - px_measured
// with rig_from_tool = (q, t), q a unit quaternion in Ceres' order
// (w, x, y, z; ceres::QuaternionManifold), t in mm. Returns false (no
// exception) when the point is behind the camera.
class ToolCornerReprojectionCost {
 public:
  ToolCornerReprojectionCost(const Eigen::Vector2d& px_measured,
                             const Eigen::Vector3d& p_in_tool,
                             const Camera& camera)
      : px_measured_(px_measured),
        p_in_tool_(p_in_tool),
        intrinsics_(camera.intrinsics.ToArray()),
        cam_from_rig_(camera.cam_from_rig) {}

  template <typename T>
  bool operator()(const T* rig_from_tool_q, const T* rig_from_tool_t,
                  T* residuals) const {
    const T p_in_tool[3] = {T(p_in_tool_.x()), T(p_in_tool_.y()),
                            T(p_in_tool_.z())};
    T p_in_rig[3];
    ceres::UnitQuaternionRotatePoint(rig_from_tool_q, p_in_tool, p_in_rig);
    for (int i = 0; i < 3; ++i) p_in_rig[i] += rig_from_tool_t[i];
    T p_in_cam[3];
    for (int i = 0; i < 3; ++i) {
      p_in_cam[i] = T(cam_from_rig_.t(i));
      for (int j = 0; j < 3; ++j) {
        p_in_cam[i] += T(cam_from_rig_.R(i, j)) * p_in_rig[j];
      }
    }
    T intrinsics[kNumIntrinsics];
    for (int i = 0; i < kNumIntrinsics; ++i) intrinsics[i] = T(intrinsics_[i]);
    return PixelResidual(intrinsics, p_in_cam, px_measured_, residuals);
  }

  static ceres::CostFunction* Create(const Eigen::Vector2d& px_measured,
                                     const Eigen::Vector3d& p_in_tool,
                                     const Camera& camera) {
    return new ceres::AutoDiffCostFunction<ToolCornerReprojectionCost, 2, 4, 3>(
        new ToolCornerReprojectionCost(px_measured, p_in_tool, camera));
  }

 private:
  const Eigen::Vector2d px_measured_;
  const Eigen::Vector3d p_in_tool_;
  const std::array<double, kNumIntrinsics> intrinsics_;
  const Rigid3 cam_from_rig_;
};

}  // namespace kincal

#endif  // KINCAL_CAMCAL_COST_FUNCTIONS_H_
