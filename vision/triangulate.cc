#include "vision/triangulate.h"

#include <ceres/jet.h>

#include <Eigen/Dense>
#include <cmath>
#include <map>

#include "data/error.h"

namespace kincal {

std::vector<StereoCorner> MatchTagCorners(
    const std::vector<TagDetection>& view0,
    const std::vector<TagDetection>& view1) {
  std::map<int, int> count0, count1;
  for (const auto& d : view0) ++count0[d.id];
  for (const auto& d : view1) ++count1[d.id];
  std::vector<StereoCorner> out;
  for (const auto& a : view0) {
    if (count0[a.id] != 1 || count1[a.id] != 1) continue;
    for (const auto& b : view1) {
      if (b.id != a.id) continue;
      for (int k = 0; k < 4; ++k) {
        if (!a.usable[k] || !b.usable[k]) continue;
        out.push_back({a.id, k, a.corners[k], b.corners[k]});
      }
    }
  }
  return out;
}

TriangulatedPoint TriangulatePoint(
    const Rig& rig, const std::vector<PixelObservation>& observations,
    const TriangulationOptions& options) {
  TriangulatedPoint result;
  if (observations.size() < 2) return result;
  // DLT: for camera P = [R | t] and normalized (x, y):
  //   x (r3 . X + t3) - (r1 . X + t1) = 0,  y (r3 . X + t3) - (r2 . X + t2) =
  //   0.
  Eigen::MatrixXd A(2 * observations.size(), 4);
  for (size_t i = 0; i < observations.size(); ++i) {
    const int c = observations[i].camera;
    KINCAL_CHECK(c >= 0 && c < static_cast<int>(rig.cameras.size()),
                 "camera " << c << " of " << rig.cameras.size());
    const Camera& cam = rig.cameras[c];
    const Eigen::Vector2d xy =
        UndistortPixel(cam.intrinsics, observations[i].px);
    Eigen::Matrix<double, 3, 4> P;
    P.leftCols<3>() = cam.cam_from_rig.R;
    P.col(3) = cam.cam_from_rig.t;
    A.row(2 * i) = xy.x() * P.row(2) - P.row(0);
    A.row(2 * i + 1) = xy.y() * P.row(2) - P.row(1);
  }
  // Scale the translation column to keep A well conditioned (mm vs unit).
  const double scale = std::max(1.0, A.col(3).cwiseAbs().maxCoeff());
  A.col(3) /= scale;
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(A, Eigen::ComputeFullV);
  const Eigen::Vector4d h = svd.matrixV().col(3);
  if (std::abs(h(3)) < 1e-12) return result;
  Eigen::Vector3d X = h.head<3>() * (scale / h(3));
  if (!X.allFinite()) return result;

  using Jet = ceres::Jet<double, 3>;
  auto residuals = [&](const Eigen::Vector3d& p, Eigen::VectorXd* r,
                       Eigen::MatrixXd* J) {
    r->resize(2 * observations.size());
    if (J) J->resize(2 * observations.size(), 3);
    for (size_t i = 0; i < observations.size(); ++i) {
      const Camera& cam = rig.cameras[observations[i].camera];
      const auto K = cam.intrinsics.ToArray();
      Jet k[kNumIntrinsics];
      for (int j = 0; j < kNumIntrinsics; ++j) k[j] = Jet(K[j]);
      Jet pr[3], pc[3], px[2];
      for (int j = 0; j < 3; ++j) pr[j] = Jet(p(j), j);
      for (int j = 0; j < 3; ++j) {
        pc[j] = Jet(cam.cam_from_rig.t(j));
        for (int m = 0; m < 3; ++m) pc[j] += cam.cam_from_rig.R(j, m) * pr[m];
      }
      if (!ProjectPoint(k, pc, px)) return false;
      for (int j = 0; j < 2; ++j) {
        (*r)(2 * i + j) = px[j].a - observations[i].px(j);
        if (J) J->row(2 * i + j) = px[j].v.transpose();
      }
    }
    return true;
  };
  Eigen::VectorXd r;
  Eigen::MatrixXd J;
  if (!residuals(X, &r, nullptr)) return result;
  if (options.refine) {
    for (int iter = 0; iter < options.max_iterations; ++iter) {
      if (!residuals(X, &r, &J)) return result;
      const Eigen::Vector3d step =
          (J.transpose() * J).ldlt().solve(-J.transpose() * r);
      if (!step.allFinite()) break;
      Eigen::VectorXd r_new;
      if (!residuals(X + step, &r_new, nullptr) ||
          r_new.squaredNorm() > r.squaredNorm()) {
        break;
      }
      X += step;
      if (step.norm() < 1e-10) break;
    }
    if (!residuals(X, &r, nullptr)) return result;
  }
  result.ok = true;
  result.p_in_rig = X;
  result.rms_px = std::sqrt(r.squaredNorm() / observations.size());
  return result;
}

}  // namespace kincal
