#ifndef KINCAL_CALIB_UR_CALIBRATION_H_
#define KINCAL_CALIB_UR_CALIBRATION_H_

// Universal Robots' kinematics YAML <-> kincal robots.
//
// The file is the one Universal Robots' ROS description reads
// (ur_description config/<model>/default_kinematics.yaml, or the file that
// ur_calibration extracts from a controller): `kinematics:` with six entries
// shoulder, upper_arm, forearm, wrist_1, wrist_2, wrist_3, each
// `x, y, z` (m) and `roll, pitch, yaw` (rad), and a `hash` string.
//
// ur_description (urdf/ur_macro.xacro) builds the arm from them as
//   base_link -(rpy 0 0 pi)-> base_link_inertia
//     -[shoulder]-> Rz(q1) shoulder_link -[upper_arm]-> Rz(q2) upper_arm_link
//     -[forearm]-> Rz(q3) forearm_link -[wrist_1]-> Rz(q4) wrist_1_link
//     -[wrist_2]-> Rz(q5) wrist_2_link -[wrist_3]-> Rz(q6) wrist_3_link
//     -(rpy 0 -pi/2 -pi/2)-> flange -(rpy pi/2 pi pi/2)-> tool0
// where each entry [e] is the joint's <origin xyz rpy>, i.e.
// T(x, y, z) Rz(yaw) Ry(pitch) Rx(roll) (URDF), and every joint turns about
// its own z axis. base_link_inertia has the orientation of the controller's
// Base frame (ROS `base`, also base_link turned pi about z) and is the base
// frame of kincal's UR robots (data/robots/ur10.yaml: UR's standard DH).
// wrist_3_link is the DH frame after joint 6; tool0 (wrist_3_link turned
// pi about z) is the controller's tool flange frame, its all-zeros TCP: the
// pendant's TCP offset is given in it.
//
// Export (any kincal convention): a joint row is split into a part before
// its motion and a part after it, A_k(q) = pre_k Rz(q) post_k:
//   dh:   pre = Rz(theta) Tz(d),               post = Tx(a) Rx(alpha) Ry(beta)
//   mdh:  pre = Rx(alpha) Ry(beta) Tx(a) Rz(theta) Tz(d),  post = I
//   urdf: pre = T(xyz) Rz(yaw) Ry(pitch) Rx(roll) C,  post = C^T, where C
//         turns z onto the joint's axis
// so entry 1 = pre_1, entry k = post_{k-1} pre_k (the form ur_calibration
// writes for the controller's DH: [Tx(a) Rx(alpha)] [Rz(theta) Tz(d)]), and
// post_6 times the tool row, which the description has no field for, becomes
// the TCP offset in tool0. ur_calibration drops post_6 (a6, alpha6); here it
// is kept in the TCP so that tool0 * TCP is the robot file's tip exactly.
// Joint error models (extensions) have no field in the file: listed as not
// exported.

#include <Eigen/Core>
#include <array>
#include <string>
#include <vector>

#include "calib/chain.h"
#include "data/robot.h"
#include "data/warnings.h"

namespace kincal {

constexpr int kUrJoints = 6;
// The entry names of the file, in chain order.
extern const std::array<const char*, kUrJoints> kUrEntryNames;
// UR's joint names (ur_description), in chain order.
extern const std::array<const char*, kUrJoints> kUrJointNames;

struct UrKinematicsEntry {
  Eigen::Vector3d xyz_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d rpy_rad = Eigen::Vector3d::Zero();  // roll, pitch, yaw
};

struct UrKinematics {
  std::array<UrKinematicsEntry, kUrJoints> entries;
  std::string hash;  // "calib_<digits>"; empty when a file has none
};

// The pendant's TCP offset: the tip in tool0, mm and rotation vector (rad).
struct UrTcp {
  Eigen::Vector3d xyz_mm = Eigen::Vector3d::Zero();
  Eigen::Vector3d rotation_vector_rad = Eigen::Vector3d::Zero();
};

struct UrCalibrationExport {
  UrKinematics kinematics;
  UrTcp tcp;
  Eigen::Matrix4d tool0_from_tip = Eigen::Matrix4d::Identity();  // mm
  // Everything the file cannot take: one line per extension, then the tool.
  std::vector<std::string> not_exported;
  std::string yaml;  // the file, with its comment header
};

// Which frame of the description the robot file's base frame is: `base`
// (base_link_inertia, the controller's Base: UR's DH, data/robots/ur10.yaml)
// or `base_link` (ROS REP-103, e.g. a chain read from ur_description's URDF
// with root base_link).
enum class UrRobotBase { kBase, kBaseLink };

// The six entries (and tool0_from_tip, mm) of a chain with six revolute
// joints; the joint error models are ignored. Throws InputError naming why
// when the chain is not a 6-revolute-joint arm.
UrKinematics UrKinematicsFromChain(const Chain& chain,
                                   Eigen::Matrix4d* tool0_from_tip,
                                   UrRobotBase base = UrRobotBase::kBase);

// The export of `robot` (`robot_file` is named in the comment header).
// `warnings` (may be null) gets "ur_base_frame" when the arm at zero joint
// angles points along +x of the stated base: in the controller's Base a UR
// arm at zero points along -x, in base_link along +x.
UrCalibrationExport ExportUrCalibration(const Robot& robot,
                                        const std::string& robot_file,
                                        UrRobotBase base = UrRobotBase::kBase,
                                        Warnings* warnings = nullptr);

// Deterministic hash of the 36 values (FNV-1a, 64 bit, over their shortest
// round-trip text): "calib_<decimal>".
std::string UrKinematicsHash(const UrKinematics& kinematics);

// One entry's <origin> as a transform (translation in mm).
Eigen::Matrix4d UrEntryTransform(const UrKinematicsEntry& entry);
// The description's fixed frames (translation in mm): base_link_from_base
// (base_link -> base_link_inertia), wrist_3_link -> flange, wrist_3_link ->
// tool0.
Eigen::Matrix4d UrBaseLinkFromBase();
Eigen::Matrix4d UrWrist3FromFlange();
Eigen::Matrix4d UrWrist3FromTool0();

// Forward kinematics of the description, in its `base` frame
// (base_link_inertia), joint angles in rad, translation in mm.
struct UrDescriptionPose {
  Eigen::Matrix4d base_from_wrist3;
  Eigen::Matrix4d base_from_flange;
  Eigen::Matrix4d base_from_tool0;
};
UrDescriptionPose UrDescriptionFk(const UrKinematics& kinematics,
                                  const std::vector<double>& q_rad);

// The pendant TCP of a tool0_from_tip transform (mm).
UrTcp TcpFromTransform(const Eigen::Matrix4d& tool0_from_tip);

// Reads a kinematics YAML (InputError with file:line:column on bad content).
UrKinematics ParseUrKinematicsYaml(const std::string& text,
                                   const std::string& file_label);
UrKinematics ReadUrKinematicsYaml(const std::string& path);

// The file text: "# " + each comment line, then `kinematics:` (values with
// 17 significant digits where needed) and `hash`.
std::string FormatUrKinematicsYaml(const UrKinematics& kinematics,
                                   const std::vector<std::string>& comment);

// A kincal robot (convention urdf, base = `base`, mm and deg) with the
// description's kinematics: joints named as UR's, limits +-360 deg, the
// tool row = tool0 (or `tool0_from_tip`, mm).
Robot RobotFromUrKinematics(
    const UrKinematics& kinematics, const std::string& name,
    const Eigen::Matrix4d& tool0_from_tip = Eigen::Matrix4d::Identity());

}  // namespace kincal

#endif  // KINCAL_CALIB_UR_CALIBRATION_H_
