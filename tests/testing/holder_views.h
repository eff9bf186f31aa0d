#ifndef KINCAL_TESTS_TESTING_HOLDER_VIEWS_H_
#define KINCAL_TESTS_TESTING_HOLDER_VIEWS_H_

// Views of a tag holder for the tracker's render tests (our renderer and
// POV-Ray's): random holder poses in the example rig's common view, the
// issue's reference tip from plain corners (triangulation + rigid fit), and
// the RMS of the errors.

#include <Eigen/Geometry>
#include <cmath>
#include <random>
#include <vector>

#include "camcal/rig.h"
#include "data/rigid3.h"
#include "vision/apriltag_detector.h"
#include "vision/target.h"
#include "vision/triangulate.h"

namespace kincal {

inline double Rms(const std::vector<double>& v) {
  double s = 0;
  for (double x : v) s += x * x;
  return v.empty() ? 0 : std::sqrt(s / v.size());
}

// The holder facing the rig (tool z into the tags ~ rig z), tilted by up to
// max_tilt about a random axis in the image plane, turned in-plane at
// random, placed in the common view ~450 mm away.
inline Rigid3 RandomPose(std::mt19937_64* rng, double max_tilt_deg) {
  std::uniform_real_distribution<double> u(-1, 1);
  const double spin = M_PI * u(*rng);
  const double tilt = max_tilt_deg * M_PI / 180 * std::abs(u(*rng));
  const double axis = M_PI * u(*rng);
  Rigid3 r;
  r.R = (Eigen::AngleAxisd(tilt,
                           Eigen::Vector3d(std::cos(axis), std::sin(axis), 0)) *
         Eigen::AngleAxisd(spin, Eigen::Vector3d::UnitZ()))
            .toRotationMatrix();
  r.t = Eigen::Vector3d(60 + 30 * u(*rng), 25 * u(*rng), 440 + 40 * u(*rng));
  return r;
}

// The reference: corners seen in both cameras triangulated, then a
// rigid (Umeyama, no scale) fit of the target's corners to them.
inline bool TriangulatedRigidTip(
    const Rig& rig, const Target& target,
    const std::vector<std::vector<TagDetection>>& dets, Eigen::Vector3d* tip) {
  std::vector<Eigen::Vector3d> a, b;
  for (const StereoCorner& c : MatchTagCorners(dets[0], dets[1])) {
    const TargetTag* tag = target.FindTag(c.tag_id);
    if (tag == nullptr) continue;
    const TriangulatedPoint p = TriangulatePoint(rig, {{0, c.px0}, {1, c.px1}});
    if (!p.ok) continue;
    a.push_back(tag->CornerInTool(c.corner));
    b.push_back(p.p_in_rig);
  }
  if (a.size() < 6) return false;
  Eigen::Matrix3Xd from(3, a.size()), to(3, b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    from.col(i) = a[i];
    to.col(i) = b[i];
  }
  const Eigen::Matrix4d rig_from_tool = Eigen::umeyama(from, to, false);
  *tip = rig_from_tool.topLeftCorner<3, 3>() * target.tip_in_tool +
         rig_from_tool.topRightCorner<3, 1>();
  return true;
}

}  // namespace kincal

#endif  // KINCAL_TESTS_TESTING_HOLDER_VIEWS_H_
