#include "vision/pose_uncertainty.h"

#include <Eigen/Dense>
#include <Eigen/Geometry>
#include <vector>

namespace kincal {
namespace {

// rig_from_tool moved by `delta`: rotation vector delta[0..2] applied in the
// tool frame, translation delta[3..5] added in the rig frame.
Rigid3 Perturbed(const Rigid3& rig_from_tool,
                 const Eigen::Matrix<double, 6, 1>& delta) {
  Rigid3 p = rig_from_tool;
  const Eigen::Vector3d w = delta.head<3>();
  if (w.norm() > 0) {
    p.R = rig_from_tool.R *
          Eigen::AngleAxisd(w.norm(), w.normalized()).toRotationMatrix();
  }
  p.t += delta.tail<3>();
  return p;
}

// The used corners' pixels for a pose (same order for every pose).
Eigen::VectorXd Pixels(const Rig& rig, const Target& target,
                       const ToolPoseResult& pose,
                       const Rigid3& rig_from_tool) {
  std::vector<double> px;
  for (const TagObservationResult& t : pose.tags) {
    const TargetTag* tag = target.FindTag(t.tag_id);
    if (!t.used || tag == nullptr) continue;
    const Camera& cam = rig.cameras[t.camera];
    for (int k = 0; k < 4; ++k) {
      if (!t.corner_used[k]) continue;
      const Eigen::Vector3d p =
          cam.cam_from_rig * (rig_from_tool * tag->CornerInTool(k));
      const Eigen::Vector2d uv = Project(cam.intrinsics, p);
      px.push_back(uv.x());
      px.push_back(uv.y());
    }
  }
  return Eigen::Map<Eigen::VectorXd>(px.data(), px.size());
}

}  // namespace

TipUncertainty TipUncertaintyOf(const Rig& rig, const Target& target,
                                const ToolPoseResult& pose, double sigma_px) {
  TipUncertainty out;
  if (!pose.found) return out;
  const Eigen::VectorXd p0 = Pixels(rig, target, pose, pose.rig_from_tool);
  if (p0.size() < 8) return out;  // fewer than 4 corners: no 6-dof pose
  // Central differences: 1e-6 rad and 1e-4 mm steps.
  Eigen::MatrixXd J(p0.size(), 6);
  Eigen::Matrix<double, 3, 6> J_tip;
  for (int i = 0; i < 6; ++i) {
    const double h = i < 3 ? 1e-6 : 1e-4;
    Eigen::Matrix<double, 6, 1> d = Eigen::Matrix<double, 6, 1>::Zero();
    d(i) = h;
    const Rigid3 plus = Perturbed(pose.rig_from_tool, d);
    const Rigid3 minus = Perturbed(pose.rig_from_tool, -d);
    J.col(i) =
        (Pixels(rig, target, pose, plus) - Pixels(rig, target, pose, minus)) /
        (2 * h);
    J_tip.col(i) =
        (plus * target.tip_in_tool - minus * target.tip_in_tool) / (2 * h);
  }
  const Eigen::Matrix<double, 6, 6> H = J.transpose() * J;
  Eigen::FullPivLU<Eigen::Matrix<double, 6, 6>> lu(H);
  if (!lu.isInvertible()) return out;
  const Eigen::Matrix<double, 6, 6> C = sigma_px * sigma_px * lu.inverse();
  out.covariance = J_tip * C * J_tip.transpose();
  const Eigen::Vector3d tip = pose.rig_from_tool * target.tip_in_tool;
  const Eigen::Vector3d centre = rig.cameras[0].cam_from_rig.Inverse().t;
  const Eigen::Vector3d sight = (tip - centre).normalized();
  out.depth_sigma_mm =
      std::sqrt(std::max(0.0, sight.dot(out.covariance * sight)));
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(out.covariance);
  out.max_sigma_mm = std::sqrt(std::max(0.0, eig.eigenvalues().maxCoeff()));
  out.ok = true;
  return out;
}

}  // namespace kincal
