#ifndef KINCAL_CAMCAL_CAMERA_MODEL_H_
#define KINCAL_CAMCAL_CAMERA_MODEL_H_

// Pinhole camera with OpenCV radial-tangential distortion (the model of
// cv::projectPoints with 4, 5 or 8 coefficients).
//
// Pixel convention (OpenCV): (0, 0) is the CENTRE of the top-left pixel; x
// right, y down. libapriltag reports corners with (0, 0) at the top-left
// corner of that pixel; vision/apriltag_detector.cc shifts them by -0.5 px.
//
// Camera frame `cam`: x right, y down, z forward (optical axis). Transforms are
// named target_from_source: p_in_cam = cam_from_rig * p_in_rig.
//
// Projection of p_in_cam = (X, Y, Z), Z > 0:
//   x = X/Z, y = Y/Z, r2 = x^2 + y^2
//   radial = (1 + k1 r2 + k2 r2^2 + k3 r2^3) / (1 + k4 r2 + k5 r2^2 + k6 r2^3)
//   xd = x radial + 2 p1 x y + p2 (r2 + 2 x^2)
//   yd = y radial + p1 (r2 + 2 y^2) + 2 p2 x y
//   u = fx xd + cx,  v = fy yd + cy

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <limits>
#include <string>
#include <vector>

#include "data/rigid3.h"

namespace kincal {

// Layout of the parameter block that ProjectPoint reads and the calibration
// optimises: fx, fy, cx, cy, k1, k2, p1, p2, k3, k4, k5, k6.
enum IntrinsicIndex : int {
  kFx = 0,
  kFy,
  kCx,
  kCy,
  kK1,
  kK2,
  kP1,
  kP2,
  kK3,
  kK4,
  kK5,
  kK6,
  kNumIntrinsics  // = 12
};

struct CameraIntrinsics {
  std::string name;
  int width = 0;                          // px
  int height = 0;                         // px
  double fx = 0, fy = 0, cx = 0, cy = 0;  // px, OpenCV pixel centres
  // OpenCV order k1, k2, p1, p2[, k3[, k4, k5, k6]]: 0, 4, 5 or 8 numbers.
  std::vector<double> distortion;

  // fx, fy, cx, cy, k1..k6 (missing coefficients = 0), for ProjectPoint.
  std::array<double, kNumIntrinsics> ToArray() const {
    std::array<double, kNumIntrinsics> a{};
    a[kFx] = fx;
    a[kFy] = fy;
    a[kCx] = cx;
    a[kCy] = cy;
    for (size_t i = 0; i < distortion.size() && i < 8; ++i)
      a[kK1 + i] = distortion[i];
    return a;
  }
  // Inverse of ToArray; keeps `num_distortion` coefficients (0, 4, 5 or 8).
  static CameraIntrinsics FromArray(const double* a, int num_distortion) {
    CameraIntrinsics c;
    c.fx = a[kFx];
    c.fy = a[kFy];
    c.cx = a[kCx];
    c.cy = a[kCy];
    c.distortion.assign(a + kK1, a + kK1 + num_distortion);
    return c;
  }
  // The 3x3 camera matrix K.
  Eigen::Matrix3d K() const {
    Eigen::Matrix3d k;
    k << fx, 0, cx, 0, fy, cy, 0, 0, 1;
    return k;
  }
};

using CameraPose = Rigid3;

// Applies distortion to normalized coordinates (x, y) = (X/Z, Y/Z).
// `dist` = k1, k2, p1, p2, k3, k4, k5, k6 (8 values, unused = 0).
template <typename T>
inline void DistortNormalized(const T* dist, const T& x, const T& y, T* xd,
                              T* yd) {
  const T& k1 = dist[0];
  const T& k2 = dist[1];
  const T& p1 = dist[2];
  const T& p2 = dist[3];
  const T& k3 = dist[4];
  const T& k4 = dist[5];
  const T& k5 = dist[6];
  const T& k6 = dist[7];
  const T r2 = x * x + y * y;
  const T r4 = r2 * r2;
  const T r6 = r4 * r2;
  const T radial = (T(1) + k1 * r2 + k2 * r4 + k3 * r6) /
                   (T(1) + k4 * r2 + k5 * r4 + k6 * r6);
  const T xy2 = T(2) * x * y;
  *xd = x * radial + p1 * xy2 + p2 * (r2 + T(2) * x * x);
  *yd = y * radial + p1 * (r2 + T(2) * y * y) + p2 * xy2;
}

// Projects p_in_cam (3 values) to pixel (2 values). `intrinsics` has the
// kNumIntrinsics layout above. Returns false (pixel untouched) when the point
// is not in front of the camera (Z <= 0). Templated for Ceres autodiff; never
// throws.
template <typename T>
inline bool ProjectPoint(const T* intrinsics, const T* p_in_cam, T* pixel) {
  if (!(p_in_cam[2] > T(0))) return false;
  const T x = p_in_cam[0] / p_in_cam[2];
  const T y = p_in_cam[1] / p_in_cam[2];
  T xd, yd;
  DistortNormalized(intrinsics + kK1, x, y, &xd, &yd);
  pixel[0] = intrinsics[kFx] * xd + intrinsics[kCx];
  pixel[1] = intrinsics[kFy] * yd + intrinsics[kCy];
  return true;
}

// Plain-double projection; returns NaN pixel when behind the camera.
inline Eigen::Vector2d Project(const CameraIntrinsics& cam,
                               const Eigen::Vector3d& p_in_cam) {
  const std::array<double, kNumIntrinsics> a = cam.ToArray();
  Eigen::Vector2d pixel;
  if (!ProjectPoint(a.data(), p_in_cam.data(), pixel.data())) {
    pixel.setConstant(std::numeric_limits<double>::quiet_NaN());
  }
  return pixel;
}

// Removes distortion: pixel -> normalized coordinates (x, y) with
// Project(cam, (x, y, 1)) == pixel. Iterative (Gauss-Newton on the forward
// model, 20 iterations max); accurate to ~1e-12 within the calibrated field.
Eigen::Vector2d UndistortPixel(const CameraIntrinsics& cam,
                               const Eigen::Vector2d& pixel);

// The pixel of `cam` without its distortion (the ideal pinhole image,
// fx, fy, cx, cy kept), where straight lines in space are straight:
// K * UndistortPixel(cam, pixel).
inline Eigen::Vector2d PinholePixel(const CameraIntrinsics& cam,
                                    const Eigen::Vector2d& pixel) {
  const Eigen::Vector2d xy = UndistortPixel(cam, pixel);
  return Eigen::Vector2d(cam.fx * xy.x() + cam.cx, cam.fy * xy.y() + cam.cy);
}

// Inverse of PinholePixel: the distorted pixel of a pinhole pixel.
inline Eigen::Vector2d DistortedPixel(const CameraIntrinsics& cam,
                                      const Eigen::Vector2d& pinhole) {
  return Project(cam, Eigen::Vector3d((pinhole.x() - cam.cx) / cam.fx,
                                      (pinhole.y() - cam.cy) / cam.fy, 1.0));
}

// The unit-length ray in `cam` through `pixel` (z > 0).
inline Eigen::Vector3d Unproject(const CameraIntrinsics& cam,
                                 const Eigen::Vector2d& pixel) {
  const Eigen::Vector2d xy = UndistortPixel(cam, pixel);
  return Eigen::Vector3d(xy.x(), xy.y(), 1.0).normalized();
}

}  // namespace kincal

#endif  // KINCAL_CAMCAL_CAMERA_MODEL_H_
