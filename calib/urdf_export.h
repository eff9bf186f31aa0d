#ifndef KINCAL_CALIB_URDF_EXPORT_H_
#define KINCAL_CALIB_URDF_EXPORT_H_

// Conversions between the robot file's conventions and URDF, exact in the
// forward kinematics (docs/CONVENTIONS.md, "DH variants"):
//
//   * DH / MDH / URDF robot -> URDF text (`kincal export urdf`). A standard DH
//     row A = M(q) F (the joint motion M about/along z comes first, F =
//     Rz(theta) Tz(d) Tx(a) Rx(alpha) Ry(beta) is fixed), so joint k+1's URDF
//     origin is F_k and the tool becomes a fixed joint with origin F_n A_tool.
//     A modified DH row is A = F M, so its URDF origin is F itself. URDF
//     metres and radians; numbers written with 17 significant digits.
//   * any robot -> standard DH (`kincal export dh`): the joint axes at q = 0
//     are lines in space; the DH frames follow their common normals, and the
//     tool row (theta, d) reaches the tip frame with its z axis. Standard DH
//     can express this only when joint 1 moves about (or along) the base z
//     axis itself; otherwise InputError says so.
//
// Model extensions (backlash, compliance, cyclic errors, gain, drift) act on
// joint readings or on time; URDF has no field for them. They are listed in
// `not_exported` and in a comment of the URDF. axis_tilt (a row's beta) is
// geometry and is exported.

#include <Eigen/Core>
#include <string>
#include <vector>

#include "data/robot.h"

namespace kincal {

struct UrdfExport {
  std::string xml;  // the URDF document
  // One line per model extension URDF cannot express, e.g.
  // "backlash j3: width 0.151 deg".
  std::vector<std::string> not_exported;
  // Made-up values URDF requires (limits, effort, velocity), e.g.
  // "j1: no limits in the robot file; URDF limit [-1, 1] m written".
  std::vector<std::string> placeholders;
};

// The robot as a URDF chain base_link -> ... -> tip. `comment` lines go into
// the header comment (provenance is added).
UrdfExport ExportUrdf(const Robot& robot);

// The same kinematics as a standard DH robot (joint names, types, limits,
// bounds and extensions kept). Throws InputError when joint 1's axis is not
// the base z axis (with the axis found).
Robot ConvertToDh(const Robot& robot);

// R = Rz(yaw) Ry(pitch) Rx(roll) -> (roll, pitch, yaw) in rad (URDF rpy),
// exact also at pitch = +-90 deg (roll set to 0 there).
Eigen::Vector3d MatrixToRpy(const Eigen::Matrix3d& r);

// One model extension in words for `not_exported` lists, e.g.
// "backlash j3: width=0.151".
std::string DescribeExtension(const Extension& e);

}  // namespace kincal

#endif  // KINCAL_CALIB_URDF_EXPORT_H_
