#include "synth/flange_scene.h"

#include <algorithm>
#include <cmath>

#include "synth/render.h"

namespace kincal {

FlangeBoardPlacement PlaceBoardForFlangeRig(
    const std::vector<Eigen::Matrix4d>& base_from_tip, const Rig& rig,
    const Rigid3& tip_from_rig, const Target& board, double distance_mm,
    int min_tags) {
  const Camera& cam = rig.cameras.at(0);
  const Rigid3 rig_from_cam = cam.cam_from_rig.Inverse();
  const double tan_half =
      0.6 * std::min(cam.intrinsics.width / (2.0 * cam.intrinsics.fx),
                     cam.intrinsics.height / (2.0 * cam.intrinsics.fy));
  const double cos_max = 1.0 / std::sqrt(1.0 + tan_half * tan_half);
  // Reference cameras in the base: centre and optical axis.
  std::vector<Eigen::Vector3d> centre, axis;
  for (const Eigen::Matrix4d& m : base_from_tip) {
    const Rigid3 base_from_cam =
        Rigid3::FromMatrix(m) * tip_from_rig * rig_from_cam;
    centre.push_back(base_from_cam.t);
    axis.push_back(base_from_cam.R.col(2));
  }
  auto views = [&](const Eigen::Vector3d& p, size_t j) {
    const Eigen::Vector3d d = p - centre[j];
    const double r = d.norm();
    return r > 0.6 * distance_mm && r < 1.5 * distance_mm &&
           d.dot(axis[j]) > cos_max * r;
  };
  // The candidate point seen by the most views.
  size_t best = 0, best_count = 0;
  for (size_t i = 0; i < centre.size(); ++i) {
    const Eigen::Vector3d p = centre[i] + distance_mm * axis[i];
    size_t count = 0;
    for (size_t j = 0; j < centre.size(); ++j) count += views(p, j);
    if (count > best_count) {
      best_count = count;
      best = i;
    }
  }
  FlangeBoardPlacement out;
  out.distance_mm = distance_mm;
  if (centre.empty()) return out;
  const Eigen::Vector3d p = centre[best] + distance_mm * axis[best];
  Eigen::Vector3d z = Eigen::Vector3d::Zero();
  for (size_t j = 0; j < centre.size(); ++j) {
    if (views(p, j)) z += (p - centre[j]).normalized();
  }
  z.normalize();
  const Eigen::Vector3d e = std::abs(z.z()) < 0.9 ? Eigen::Vector3d::UnitZ()
                                                  : Eigen::Vector3d::UnitX();
  const Eigen::Vector3d x = e.cross(z).normalized();
  Rigid3& b = out.base_from_board;
  b.R.col(0) = x;
  b.R.col(1) = z.cross(x);
  b.R.col(2) = z;
  Eigen::Vector3d middle = Eigen::Vector3d::Zero();
  for (const TargetTag& tag : board.tags) middle += tag.tool_from_tag.t;
  if (!board.tags.empty()) middle /= static_cast<double>(board.tags.size());
  b.t = p - b.R * middle;
  for (size_t j = 0; j < centre.size(); ++j) {
    const Rigid3 rig_from_board =
        (Rigid3::FromMatrix(base_from_tip[j]) * tip_from_rig).Inverse() * b;
    int tags = 0;
    for (const TagTruth& t : ProjectTargetCorners(cam, board, rig_from_board)) {
      tags += t.visible;
    }
    if (tags >= min_tags) out.seen.push_back(static_cast<int>(j));
  }
  return out;
}

}  // namespace kincal
