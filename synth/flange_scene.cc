#include "synth/flange_scene.h"

#include <algorithm>
#include <cmath>

#include "synth/render.h"

namespace kincal {
namespace {

// The reference camera of a rig at base_from_tip_i * tip_from_rig, and
// whether it holds a point near its view's centre at the working distance.
struct Views {
  Views(const std::vector<Eigen::Matrix4d>& base_from_tip, const Rig& rig,
        const Rigid3& tip_from_rig, double distance_mm)
      : distance(distance_mm) {
    const Camera& cam = rig.cameras.at(0);
    const Rigid3 rig_from_cam = cam.cam_from_rig.Inverse();
    const double tan_half =
        0.6 * std::min(cam.intrinsics.width / (2.0 * cam.intrinsics.fx),
                       cam.intrinsics.height / (2.0 * cam.intrinsics.fy));
    cos_max = 1.0 / std::sqrt(1.0 + tan_half * tan_half);
    for (const Eigen::Matrix4d& m : base_from_tip) {
      const Rigid3 base_from_cam =
          Rigid3::FromMatrix(m) * tip_from_rig * rig_from_cam;
      centre.push_back(base_from_cam.t);
      axis.push_back(base_from_cam.R.col(2));
    }
  }
  bool Holds(const Eigen::Vector3d& p, size_t j) const {
    const Eigen::Vector3d d = p - centre[j];
    const double r = d.norm();
    return r > 0.6 * distance && r < 1.5 * distance &&
           d.dot(axis[j]) > cos_max * r;
  }
  double distance = 0.0, cos_max = 1.0;
  std::vector<Eigen::Vector3d> centre, axis;
};

Eigen::Vector3d BoardMiddle(const Target& board) {
  Eigen::Vector3d middle = Eigen::Vector3d::Zero();
  for (const TargetTag& tag : board.tags) middle += tag.tool_from_tag.t;
  if (!board.tags.empty()) middle /= static_cast<double>(board.tags.size());
  return middle;
}

}  // namespace

std::vector<int> PosesSeeingBoard(
    const std::vector<Eigen::Matrix4d>& base_from_tip, const Rig& rig,
    const Rigid3& tip_from_rig, const Target& board,
    const Rigid3& base_from_board, double distance_mm, int min_tags) {
  const Views views(base_from_tip, rig, tip_from_rig, distance_mm);
  const Eigen::Vector3d p = base_from_board * BoardMiddle(board);
  const Eigen::Vector3d z = base_from_board.R.col(2);
  const double cos_oblique = std::cos(60.0 * M_PI / 180.0);
  std::vector<int> seen;
  for (size_t j = 0; j < base_from_tip.size(); ++j) {
    if (!views.Holds(p, j) ||
        (p - views.centre[j]).normalized().dot(z) < cos_oblique) {
      continue;
    }
    const Rigid3 rig_from_board =
        (Rigid3::FromMatrix(base_from_tip[j]) * tip_from_rig).Inverse() *
        base_from_board;
    int tags = 0;
    for (const TagTruth& t :
         ProjectTargetCorners(rig.cameras.at(0), board, rig_from_board)) {
      tags += t.visible;
    }
    if (tags >= min_tags) seen.push_back(static_cast<int>(j));
  }
  return seen;
}

FlangeBoardPlacement PlaceBoardForFlangeRig(
    const std::vector<Eigen::Matrix4d>& base_from_tip, const Rig& rig,
    const Rigid3& tip_from_rig, const Target& board, double distance_mm,
    int min_tags) {
  const Views views(base_from_tip, rig, tip_from_rig, distance_mm);
  const size_t n = views.centre.size();
  // The candidate point held by the most views (at most ~2000 candidates,
  // each counted over every view).
  const size_t stride = std::max<size_t>(1, n / 2000);
  size_t best = 0, best_count = 0;
  for (size_t i = 0; i < n; i += stride) {
    const Eigen::Vector3d p = views.centre[i] + distance_mm * views.axis[i];
    size_t count = 0;
    for (size_t j = 0; j < n; ++j) count += views.Holds(p, j);
    if (count > best_count) {
      best_count = count;
      best = i;
    }
  }
  FlangeBoardPlacement out;
  out.distance_mm = distance_mm;
  if (n == 0) return out;
  // Facing those views on average, its middle at the point.
  const Eigen::Vector3d p = views.centre[best] + distance_mm * views.axis[best];
  Eigen::Vector3d z = Eigen::Vector3d::Zero();
  for (size_t j = 0; j < n; ++j) {
    if (views.Holds(p, j)) z += (p - views.centre[j]).normalized();
  }
  z.normalize();
  const Eigen::Vector3d e = std::abs(z.z()) < 0.9 ? Eigen::Vector3d::UnitZ()
                                                  : Eigen::Vector3d::UnitX();
  const Eigen::Vector3d x = e.cross(z).normalized();
  Rigid3& b = out.base_from_board;
  b.R.col(0) = x;
  b.R.col(1) = z.cross(x);
  b.R.col(2) = z;
  b.t = p - b.R * BoardMiddle(board);
  out.seen = PosesSeeingBoard(base_from_tip, rig, tip_from_rig, board, b,
                              distance_mm, min_tags);
  return out;
}

}  // namespace kincal
