#include "synth/rig_placement.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "data/error.h"

namespace kincal {

Rigid3 PlaceRigFacingTips(const std::vector<Eigen::Matrix4d>& base_from_tip,
                          const Rig& rig, const Rigid3& tip_from_tool,
                          double in_view, double* distance_mm) {
  constexpr double kMinDistanceMm = 450.0;  // the target's working distance
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero(),
                  mean_z = Eigen::Vector3d::Zero();
  for (const Eigen::Matrix4d& m : base_from_tip) {
    centroid += m.block<3, 1>(0, 3);
    mean_z += m.block<3, 3>(0, 0) * tip_from_tool.R.col(2);
  }
  if (!base_from_tip.empty()) {
    centroid /= static_cast<double>(base_from_tip.size());
  }
  const Eigen::Vector3d z =
      mean_z.norm() > 1e-6 ? mean_z.normalized() : Eigen::Vector3d(0, 0, -1);
  const Eigen::Vector3d e = std::abs(z.z()) < 0.9 ? Eigen::Vector3d::UnitZ()
                                                  : Eigen::Vector3d::UnitX();
  const Eigen::Vector3d x = z.cross(e).normalized();
  const Eigen::Vector3d y = z.cross(x);
  const CameraIntrinsics& cam = rig.cameras.at(0).intrinsics;
  const double tan_half =
      0.8 * std::min(cam.width / (2.0 * cam.fx), cam.height / (2.0 * cam.fy));
  // The distance each tip needs to be in view; the in_view quantile of them.
  std::vector<double> needed;
  for (const Eigen::Matrix4d& m : base_from_tip) {
    const Eigen::Vector3d d = m.block<3, 1>(0, 3) - centroid;
    needed.push_back(std::hypot(d.dot(x), d.dot(y)) / tan_half - d.dot(z));
  }
  double distance = kMinDistanceMm;
  if (!needed.empty()) {
    std::sort(needed.begin(), needed.end());
    const double share = std::clamp(in_view, 0.0, 1.0);
    distance = std::max(
        distance, needed[static_cast<size_t>(share * (needed.size() - 1))]);
  }
  if (distance_mm != nullptr) *distance_mm = distance;
  Rigid3 base_from_rig;
  base_from_rig.R.col(0) = x;
  base_from_rig.R.col(1) = y;
  base_from_rig.R.col(2) = z;
  base_from_rig.t = centroid - distance * z;
  return base_from_rig.Inverse();
}

Rig RigWithCameras(const Rig& stereo, int num_cameras, double aim_mm) {
  if (stereo.cameras.size() != 2 || num_cameras < 1 || num_cameras > 3) {
    throw InputError(
        "rendered rigs have 1, 2 or 3 cameras (from a stereo "
        "pair); got " +
        std::to_string(num_cameras));
  }
  Rig rig = stereo;
  rig.cameras.resize(std::min(num_cameras, 2));
  if (num_cameras == 3) {
    Camera top = stereo.cameras[0];
    top.intrinsics.name = "top";
    top.intrinsics.cx += 4.0;
    top.intrinsics.cy -= 3.0;
    const Eigen::Vector3d centre(0, -120, 0);
    top.cam_from_rig.R =
        Eigen::AngleAxisd(std::atan2(120.0, aim_mm), Eigen::Vector3d::UnitX())
            .toRotationMatrix();
    top.cam_from_rig.t = -(top.cam_from_rig.R * centre);
    rig.cameras.push_back(top);
  }
  return rig;
}

}  // namespace kincal
