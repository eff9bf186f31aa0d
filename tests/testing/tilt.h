#ifndef KINCAL_TESTS_TESTING_TILT_H_
#define KINCAL_TESTS_TESTING_TILT_H_

// A tool pose tilted about a point fixed in the tool: the hand-held and
// pivot sessions that the target tests, the Monte Carlo and the LAB.md
// stand-ins render.

#include <Eigen/Geometry>
#include <cmath>

#include "data/rigid3.h"

namespace kincal::testing {

// `pose` turned about x then y (deg, rig axes) about the point
// fixed_in_tool (tool frame, mm), which stays where it was.
inline Rigid3 TiltedAbout(const Rigid3& pose, double about_x_deg,
                          double about_y_deg,
                          const Eigen::Vector3d& fixed_in_tool) {
  Rigid3 out;
  out.R =
      (Eigen::AngleAxisd(about_x_deg * M_PI / 180, Eigen::Vector3d::UnitX()) *
       Eigen::AngleAxisd(about_y_deg * M_PI / 180, Eigen::Vector3d::UnitY()))
          .toRotationMatrix() *
      pose.R;
  out.t = pose * fixed_in_tool - out.R * fixed_in_tool;
  return out;
}

}  // namespace kincal::testing

#endif  // KINCAL_TESTS_TESTING_TILT_H_
