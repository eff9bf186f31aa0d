#include "calib/ur_calibration.h"

#include <Eigen/Geometry>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <sstream>

#include "calib/urdf_export.h"
#include "data/atomic_file.h"
#include "data/error.h"
#include "data/provenance.h"
#include "data/yaml_util.h"

namespace kincal {

const std::array<const char*, kUrJoints> kUrEntryNames = {
    "shoulder", "upper_arm", "forearm", "wrist_1", "wrist_2", "wrist_3"};
const std::array<const char*, kUrJoints> kUrJointNames = {
    "shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint",
    "wrist_1_joint",      "wrist_2_joint",       "wrist_3_joint"};

namespace {

constexpr double kRadToDeg = 180.0 / M_PI;

Eigen::Matrix4d RotZ(double a) { return internal::RotZ(a); }
Eigen::Matrix4d RotX(double a) { return internal::RotX(a); }
Eigen::Matrix4d RotY(double a) { return internal::RotY(a); }
Eigen::Matrix4d Trans(double x, double y, double z) {
  return internal::Trans(x, y, z);
}

// URDF <origin>: T(xyz) Rz(yaw) Ry(pitch) Rx(roll).
Eigen::Matrix4d Origin(const Eigen::Vector3d& xyz, const Eigen::Vector3d& rpy) {
  return Trans(xyz.x(), xyz.y(), xyz.z()) * RotZ(rpy.z()) * RotY(rpy.y()) *
         RotX(rpy.x());
}

// A joint row split around its motion: A(q) = pre Rz(q) post.
struct SplitRow {
  Eigen::Matrix4d pre = Eigen::Matrix4d::Identity();
  Eigen::Matrix4d post = Eigen::Matrix4d::Identity();
};

SplitRow Split(Convention convention, const RowBlock& p,
               const Eigen::Vector3d& axis) {
  SplitRow s;
  switch (convention) {
    case Convention::kDh:  // Rz(theta + q) Tz(d) Tx(a) Rx(alpha) Ry(beta)
      s.pre = RotZ(p[0]) * Trans(0, 0, p[1]);
      s.post = Trans(p[2], 0, 0) * RotX(p[3]) * RotY(p[4]);
      break;
    case Convention::kMdh:  // Rx(alpha) Ry(beta) Tx(a) Rz(theta + q) Tz(d)
      s.pre = RotX(p[3]) * RotY(p[4]) * Trans(p[2], 0, 0) * RotZ(p[0]) *
              Trans(0, 0, p[1]);
      break;
    case Convention::kUrdf: {  // T(xyz) Rzyx R(axis, q) = [.. C] Rz(q) C^T
      Eigen::Matrix4d c = Eigen::Matrix4d::Identity();
      c.block<3, 3>(0, 0) = Eigen::Quaterniond::FromTwoVectors(
                                Eigen::Vector3d::UnitZ(), axis.normalized())
                                .toRotationMatrix();
      s.pre = Origin(Eigen::Vector3d(p[0], p[1], p[2]),
                     Eigen::Vector3d(p[3], p[4], p[5])) *
              c;
      s.post = c.transpose();
      break;
    }
  }
  return s;
}

// Rounded to a multiple of 1 / `per_unit` (an exact power of ten): the
// rounding noise of products, such as 7e-18 m for cos(pi/2) or
// -0.5722999999999999 m, is not written.
double Rounded(double v, double per_unit) {
  const double r = std::round(v * per_unit) / per_unit;
  return r == 0.0 ? 0.0 : r;
}

// Angles below 1e-12 (rad or deg) are rounding noise: 0.
double ZeroIfTiny(double v) { return std::abs(v) < 1e-12 ? 0.0 : v; }

// Lengths rounded to 1e-12 m (1e-9 mm); angles below 1e-12 rad are 0.
UrKinematicsEntry EntryFromTransform(const Eigen::Matrix4d& m_mm) {
  UrKinematicsEntry e;
  const Eigen::Vector3d rpy = MatrixToRpy(m_mm.block<3, 3>(0, 0));
  for (int i = 0; i < 3; ++i) {
    e.xyz_m[i] = Rounded(m_mm(i, 3) / 1000.0, 1e12);
    e.rpy_rad[i] = ZeroIfTiny(rpy[i]);
  }
  return e;
}

void RequireUrArm(const Chain& chain) {
  Require(chain.num_joints() == kUrJoints,
          "robot '" + chain.name + "' has " +
              std::to_string(chain.num_joints()) +
              " joints; Universal Robots' kinematics file describes arms of "
              "exactly 6 revolute joints");
  for (int k = 0; k < kUrJoints; ++k) {
    Require(chain.rows[k].type == JointType::kRevolute,
            "joint " + std::to_string(k + 1) + " ('" + chain.rows[k].name +
                "') of robot '" + chain.name + "' is " +
                ToString(chain.rows[k].type) +
                "; Universal Robots' kinematics file describes arms of "
                "exactly 6 revolute joints");
  }
}

std::string Fixed(double v, int digits) {
  if (std::abs(v) < 0.5 * std::pow(10.0, -digits)) v = 0.0;  // no "-0.0000"
  return FormatFixed(v, digits);
}

std::string TcpText(const UrTcp& tcp) {
  const Eigen::Vector3d& p = tcp.xyz_mm;
  const Eigen::Vector3d& r = tcp.rotation_vector_rad;
  return "x " + Fixed(p.x(), 4) + ", y " + Fixed(p.y(), 4) + ", z " +
         Fixed(p.z(), 4) + " mm; rotation vector rx " + Fixed(r.x(), 6) +
         ", ry " + Fixed(r.y(), 6) + ", rz " + Fixed(r.z(), 6) + " rad (" +
         Fixed(r.x() * kRadToDeg, 4) + ", " + Fixed(r.y() * kRadToDeg, 4) +
         ", " + Fixed(r.z() * kRadToDeg, 4) + " deg)";
}

std::vector<std::string> HeaderComment(const Robot& robot,
                                       const std::string& robot_file,
                                       UrRobotBase base,
                                       const UrCalibrationExport& e) {
  std::vector<std::string> c = {
      "written by " + ToolVersion() + ": " + CommandLine(),
      "Universal Robots kinematics (ur_description "
      "config/<model>/default_kinematics.yaml form) of robot '" +
          robot.name + "' (" + ToString(robot.convention) + " in " +
          robot_file + ").",
      "Per joint: its <origin> in the description, x y z in m, roll pitch "
      "yaw in rad (URDF: Rz(yaw) Ry(pitch) Rx(roll)); the joint turns about "
      "its z axis after it.",
      base == UrRobotBase::kBase
          ? "Base frame: the controller's Base (ROS `base`, base_link_inertia "
            "= base_link turned 180 deg about z), the robot file's base frame."
          : "Base frame: the robot file's base is ROS base_link (--robot-base "
            "base_link); the entries start at base_link_inertia, base_link "
            "turned 180 deg about z.",
      "Use: ur_robot_driver kinematics_params_file:=<this file> (ROS 2) or "
      "kinematics_config:=<this file> (ROS 1).",
      "TCP offset to set on the pendant (tip in the tool flange frame "
      "tool0; includes what the robot file has after the last joint's "
      "motion): " +
          TcpText(e.tcp)};
  if (!robot.extensions.empty()) {
    c.push_back(
        "NOT EXPORTED (joint error models: the file and the controller have "
        "no field for them; kincal compensate applies them to targets):");
    for (const Extension& x : robot.extensions) {
      c.push_back("  " + DescribeExtension(x));
    }
  }
  return c;
}

// A UR arm at zero joint angles reaches out along -x of the controller's
// Base (the upper arm and forearm have negative DH a) and along +x of
// base_link: a flange far out on the other side names the likely mix-up.
void CheckBaseFrame(const Chain& chain, UrRobotBase base, Warnings* warnings) {
  const Eigen::Vector3d flange =
      BaseFromTipAt(chain, std::vector<double>(kUrJoints, 0.0))
          .block<3, 1>(0, 3);
  const double out = base == UrRobotBase::kBase ? flange.x() : -flange.x();
  if (out > 100.0 && std::abs(flange.x()) > std::abs(flange.y())) {
    const bool at_base = base == UrRobotBase::kBase;
    warnings->Add(
        "ur_base_frame",
        "at zero joint angles the tip of robot '" + chain.name +
            "' is at x = " + Fixed(flange.x(), 1) +
            " mm in its base frame; a UR arm at zero "
            "reaches along " +
            (at_base ? "-x of the controller's Base" : "+x of base_link") +
            ": is the robot file's base " +
            (at_base
                 ? "ROS base_link? then give --robot-base base_link"
                 : "the controller's Base? then leave --robot-base at base"));
  }
}

std::uint64_t Fnv1a(const std::string& text) {
  std::uint64_t h = 14695981039346656037ull;
  for (unsigned char ch : text) {
    h ^= ch;
    h *= 1099511628211ull;
  }
  return h;
}

}  // namespace

Eigen::Matrix4d UrEntryTransform(const UrKinematicsEntry& entry) {
  return Origin(entry.xyz_m * 1000.0, entry.rpy_rad);
}

Eigen::Matrix4d UrBaseLinkFromBase() {
  return Origin(Eigen::Vector3d::Zero(), Eigen::Vector3d(0, 0, M_PI));
}

Eigen::Matrix4d UrWrist3FromFlange() {
  return Origin(Eigen::Vector3d::Zero(),
                Eigen::Vector3d(0, -M_PI / 2.0, -M_PI / 2.0));
}

Eigen::Matrix4d UrWrist3FromTool0() {
  return UrWrist3FromFlange() *
         Origin(Eigen::Vector3d::Zero(),
                Eigen::Vector3d(M_PI / 2.0, M_PI, M_PI / 2.0));
}

UrDescriptionPose UrDescriptionFk(const UrKinematics& kinematics,
                                  const std::vector<double>& q_rad) {
  KINCAL_CHECK(static_cast<int>(q_rad.size()) == kUrJoints,
               "6 joint values, got " << q_rad.size());
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  for (int k = 0; k < kUrJoints; ++k) {
    m = m * UrEntryTransform(kinematics.entries[k]) * RotZ(q_rad[k]);
  }
  UrDescriptionPose pose;
  pose.base_from_wrist3 = m;
  pose.base_from_flange = m * UrWrist3FromFlange();
  pose.base_from_tool0 = m * UrWrist3FromTool0();
  return pose;
}

UrTcp TcpFromTransform(const Eigen::Matrix4d& tool0_from_tip) {
  UrTcp tcp;
  const Eigen::AngleAxisd aa(Eigen::Matrix3d(tool0_from_tip.block<3, 3>(0, 0)));
  for (int i = 0; i < 3; ++i) {  // rounding noise (1e-15) written as 0
    tcp.xyz_mm[i] = Rounded(tool0_from_tip(i, 3), 1e9);
    tcp.rotation_vector_rad[i] = ZeroIfTiny(aa.axis()[i] * aa.angle());
  }
  return tcp;
}

UrKinematics UrKinematicsFromChain(const Chain& chain,
                                   Eigen::Matrix4d* tool0_from_tip,
                                   UrRobotBase base) {
  RequireUrArm(chain);
  UrKinematics k;
  // Entry 1 starts at `base`: a robot file based at base_link is moved.
  Eigen::Matrix4d post_prev = Eigen::Matrix4d::Identity();
  if (base == UrRobotBase::kBaseLink)
    post_prev = UrBaseLinkFromBase().inverse();
  for (int j = 0; j < kUrJoints; ++j) {
    const SplitRow s =
        Split(chain.convention, chain.rows[j].p, chain.rows[j].axis);
    k.entries[j] = EntryFromTransform(post_prev * s.pre);
    post_prev = s.post;
  }
  const ChainRow& tool = chain.rows[chain.tool_row()];
  const Eigen::Matrix4d wrist3_from_tip =
      post_prev *
      RowTransform<double>(chain.convention, tool, tool.p.data(), 0.0);
  if (tool0_from_tip != nullptr) {
    *tool0_from_tip = UrWrist3FromTool0().inverse() * wrist3_from_tip;
  }
  k.hash = UrKinematicsHash(k);
  return k;
}

std::string UrKinematicsHash(const UrKinematics& kinematics) {
  std::string text;
  for (const UrKinematicsEntry& e : kinematics.entries) {
    for (int i = 0; i < 3; ++i) text += FormatDouble(e.xyz_m[i]) + ";";
    for (int i = 0; i < 3; ++i) text += FormatDouble(e.rpy_rad[i]) + ";";
  }
  return "calib_" + std::to_string(Fnv1a(text));
}

UrCalibrationExport ExportUrCalibration(const Robot& robot,
                                        const std::string& robot_file,
                                        UrRobotBase base, Warnings* warnings) {
  const Chain chain = Chain::FromRobot(robot);
  UrCalibrationExport out;
  out.kinematics = UrKinematicsFromChain(chain, &out.tool0_from_tip, base);
  if (warnings != nullptr) CheckBaseFrame(chain, base, warnings);
  out.tcp = TcpFromTransform(out.tool0_from_tip);
  for (const Extension& e : robot.extensions) {
    out.not_exported.push_back(DescribeExtension(e));
  }
  out.not_exported.push_back(
      "tool (not part of UR's kinematics): set as the pendant's TCP offset " +
      TcpText(out.tcp));
  out.yaml = FormatUrKinematicsYaml(
      out.kinematics, HeaderComment(robot, robot_file, base, out));
  return out;
}

std::string FormatUrKinematicsYaml(const UrKinematics& kinematics,
                                   const std::vector<std::string>& comment) {
  std::ostringstream os;
  for (const std::string& c : comment) os << "# " << c << "\n";
  os << "kinematics:\n";
  static const char* kKeys[6] = {"x", "y", "z", "roll", "pitch", "yaw"};
  for (int j = 0; j < kUrJoints; ++j) {
    const UrKinematicsEntry& e = kinematics.entries[j];
    os << "  " << kUrEntryNames[j] << ":\n";
    for (int i = 0; i < 6; ++i) {
      const double v = i < 3 ? e.xyz_m[i] : e.rpy_rad[i - 3];
      os << "    " << kKeys[i] << ": " << FormatDouble(v == 0.0 ? 0.0 : v)
         << "\n";
    }
  }
  os << "  hash: " << kinematics.hash << "\n";
  return os.str();
}

UrKinematics ParseUrKinematicsYaml(const std::string& text,
                                   const std::string& file_label) {
  const YamlReader reader(file_label);
  const YAML::Node doc = reader.Load(text);
  reader.ExpectMap(doc, "kinematics file");
  const YAML::Node kin = reader.Required(doc, "kinematics", "kinematics file");
  reader.ExpectMap(kin, "kinematics");
  reader.CheckKeys(kin,
                   {"shoulder", "upper_arm", "forearm", "wrist_1", "wrist_2",
                    "wrist_3", "hash"},
                   "kinematics");
  UrKinematics k;
  for (int j = 0; j < kUrJoints; ++j) {
    const std::string what = std::string("kinematics.") + kUrEntryNames[j];
    const YAML::Node e = reader.Required(kin, kUrEntryNames[j], "kinematics");
    reader.ExpectMap(e, what);
    reader.CheckKeys(e, {"x", "y", "z", "roll", "pitch", "yaw"}, what);
    static const char* kKeys[6] = {"x", "y", "z", "roll", "pitch", "yaw"};
    for (int i = 0; i < 6; ++i) {
      const double v = reader.Number(reader.Required(e, kKeys[i], what),
                                     what + "." + kKeys[i]);
      if (i < 3) {
        k.entries[j].xyz_m[i] = v;
      } else {
        k.entries[j].rpy_rad[i - 3] = v;
      }
    }
    // A length over 5 m or an angle over 2 pi is not a UR arm in m / rad.
    for (int i = 0; i < 3; ++i) {
      if (std::abs(k.entries[j].xyz_m[i]) > 5.0) {
        reader.Fail(e[kKeys[i]], what + "." + kKeys[i] +
                                     " is over 5 m: the file holds metres");
      }
      if (std::abs(k.entries[j].rpy_rad[i]) > 2.0 * M_PI + 1e-9) {
        reader.Fail(e[kKeys[i + 3]], what + "." + kKeys[i + 3] +
                                         " is over 2 pi: the file holds "
                                         "radians");
      }
    }
  }
  if (kin["hash"]) k.hash = reader.String(kin["hash"], "kinematics.hash");
  return k;
}

UrKinematics ReadUrKinematicsYaml(const std::string& path) {
  return ParseUrKinematicsYaml(ReadFile(path), path);
}

Robot RobotFromUrKinematics(const UrKinematics& kinematics,
                            const std::string& name,
                            const Eigen::Matrix4d& tool0_from_tip) {
  Robot r;
  r.name = name;
  r.convention = Convention::kUrdf;
  r.gravity = Eigen::Vector3d(0, 0, -1);
  for (int j = 0; j < kUrJoints; ++j) {
    RobotRow row;
    row.name = kUrJointNames[j];
    row.type = JointType::kRevolute;
    for (int i = 0; i < 3; ++i) {  // mm to 1e-9, as the file's 1e-12 m
      row.xyz_mm[i] = Rounded(kinematics.entries[j].xyz_m[i] * 1000.0, 1e9);
      row.rpy_deg[i] = ZeroIfTiny(kinematics.entries[j].rpy_rad[i] * kRadToDeg);
    }
    row.lower = -360.0;
    row.upper = 360.0;
    r.joints.push_back(row);
  }
  const Eigen::Matrix4d wrist3_from_tip = UrWrist3FromTool0() * tool0_from_tip;
  r.tool.name = "tool";
  r.tool.type = JointType::kFixed;
  const Eigen::Vector3d tool_rpy =
      MatrixToRpy(wrist3_from_tip.block<3, 3>(0, 0)) * kRadToDeg;
  for (int i = 0; i < 3; ++i) {
    r.tool.xyz_mm[i] = Rounded(wrist3_from_tip(i, 3), 1e9);
    r.tool.rpy_deg[i] = ZeroIfTiny(tool_rpy[i]);
  }
  return r;
}

}  // namespace kincal
