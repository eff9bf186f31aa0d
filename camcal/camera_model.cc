#include "camcal/camera_model.h"

#include <ceres/jet.h>

#include <cmath>

namespace kincal {

Eigen::Vector2d UndistortPixel(const CameraIntrinsics& cam,
                               const Eigen::Vector2d& pixel) {
  using Jet = ceres::Jet<double, 2>;
  const std::array<double, kNumIntrinsics> a = cam.ToArray();
  std::array<Jet, 8> dist;
  for (int i = 0; i < 8; ++i) dist[i] = Jet(a[kK1 + i]);
  // Target in distorted normalized coordinates.
  const Eigen::Vector2d target((pixel.x() - cam.cx) / cam.fx,
                               (pixel.y() - cam.cy) / cam.fy);
  Eigen::Vector2d xy = target;  // start at the distorted point
  for (int iter = 0; iter < 20; ++iter) {
    const Jet x(xy.x(), 0);
    const Jet y(xy.y(), 1);
    Jet xd, yd;
    DistortNormalized(dist.data(), x, y, &xd, &yd);
    const Eigen::Vector2d r(xd.a - target.x(), yd.a - target.y());
    Eigen::Matrix2d J;
    J << xd.v[0], xd.v[1], yd.v[0], yd.v[1];
    const Eigen::Vector2d step = J.partialPivLu().solve(r);
    if (!step.allFinite()) break;
    xy -= step;
    if (step.norm() < 1e-15) break;
  }
  return xy;
}

}  // namespace kincal
