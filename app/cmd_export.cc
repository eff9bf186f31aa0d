// kincal export urdf | dh | ur-calibration: the (calibrated) robot model in
// another convention, with the same forward kinematics (calib/urdf_export.h,
// calib/ur_calibration.h).

#include <cstdio>
#include <memory>

#include "app/app_util.h"
#include "app/command.h"
#include "calib/ur_calibration.h"
#include "calib/urdf_export.h"
#include "data/atomic_file.h"
#include "data/robot.h"
#include "data/urdf.h"

namespace kincal::app {
namespace {

struct ExportArgs {
  std::string robot, out, root, tip;
  std::string robot_base = "base";  // ur-calibration
  bool json = false;
};

int RunExportUrdf(const ExportArgs& args) {
  const Robot robot = ReadRobot(args.robot, args.root, args.tip);
  const UrdfExport e = ExportUrdf(robot);
  WriteFileAtomic(args.out, e.xml);
  if (args.json) {
    PrintJson({{"out", args.out},
               {"robot", robot.name},
               {"joints", robot.joints.size()},
               {"convention_in", ToString(robot.convention)},
               {"not_exported", e.not_exported},
               {"placeholders", e.placeholders}});
    return 0;
  }
  std::printf("kincal export urdf: %s (%zu joints, from %s) -> %s\n",
              robot.name.c_str(), robot.joints.size(),
              ToString(robot.convention), args.out.c_str());
  for (const std::string& s : e.not_exported) {
    std::printf("  not exported (URDF cannot express it): %s\n", s.c_str());
  }
  for (const std::string& s : e.placeholders) {
    std::printf("  placeholder: %s\n", s.c_str());
  }
  return 0;
}

int RunExportDh(const ExportArgs& args) {
  const Robot robot = ReadRobot(args.robot, args.root, args.tip);
  const Robot dh = ConvertToDh(robot);
  WriteFileAtomic(args.out,
                  FormatRobotYaml(dh, {"standard DH form of " + args.robot +
                                       " (same forward kinematics)"}));
  if (args.json) {
    PrintJson({{"out", args.out},
               {"robot", dh.name},
               {"joints", dh.joints.size()},
               {"convention_in", ToString(robot.convention)}});
    return 0;
  }
  std::printf("kincal export dh: %s (%zu joints, from %s) -> %s\n",
              dh.name.c_str(), dh.joints.size(), ToString(robot.convention),
              args.out.c_str());
  return 0;
}

nlohmann::json TcpJson(const UrTcp& tcp) {
  const Eigen::Vector3d deg = tcp.rotation_vector_rad * (180.0 / M_PI);
  return {{"x_mm", tcp.xyz_mm.x()},
          {"y_mm", tcp.xyz_mm.y()},
          {"z_mm", tcp.xyz_mm.z()},
          {"rotation_vector_rad",
           {tcp.rotation_vector_rad.x(), tcp.rotation_vector_rad.y(),
            tcp.rotation_vector_rad.z()}},
          {"rotation_vector_deg", {deg.x(), deg.y(), deg.z()}}};
}

int RunExportUrCalibration(const ExportArgs& args) {
  const Robot robot = ReadRobot(args.robot, args.root, args.tip);
  Warnings warnings = CommandWarnings();
  const UrCalibrationExport e = ExportUrCalibration(
      robot, args.robot,
      args.robot_base == "base_link" ? UrRobotBase::kBaseLink
                                     : UrRobotBase::kBase,
      &warnings);
  WriteFileAtomic(args.out, e.yaml);
  if (args.json) {
    nlohmann::json j = {{"out", args.out},
                        {"robot", robot.name},
                        {"convention_in", ToString(robot.convention)},
                        {"robot_base", args.robot_base},
                        {"hash", e.kinematics.hash},
                        {"tcp", TcpJson(e.tcp)},
                        {"not_exported", e.not_exported}};
    AddWarnings(warnings, &j);
    PrintJson(j);
    return 0;
  }
  std::printf("kincal export ur-calibration: %s (from %s) -> %s (%s)\n",
              robot.name.c_str(), ToString(robot.convention), args.out.c_str(),
              e.kinematics.hash.c_str());
  for (const std::string& s : e.not_exported) {
    std::printf("  not exported: %s\n", s.c_str());
  }
  return 0;
}

void AddCommon(CLI::App* sub, ExportArgs* args, const char* out_help) {
  AddRobotOptions(
      sub, &args->robot, &args->root, &args->tip,
      "robot.yaml (dh, mdh or urdf rows; calibrated or not) or .urdf",
      "URDF root link (default: the root)",
      "URDF tip link (default: the deepest leaf of a chain)")
      ->required();
  sub->add_option("--out", args->out, out_help)->required();
  sub->add_flag("--json", args->json, "print one JSON object on stdout");
}

}  // namespace

void AddExportCommand(CLI::App& app, Runner* run) {
  CLI::App* exp = app.add_subcommand(
      "export", "Write the robot model in another format, same kinematics");
  exp->require_subcommand(1);

  auto urdf_args = std::make_shared<ExportArgs>();
  CLI::App* urdf = exp->add_subcommand(
      "urdf",
      "Write the robot as URDF (metres, radians) whose forward kinematics "
      "equals the robot file's. Model extensions URDF cannot express "
      "(backlash, compliance, cyclic, gain, drift) are listed in a comment "
      "and in JSON 'not_exported'. Joints without limits: revolute -> "
      "continuous, prismatic -> placeholder limit [-1, 1] m (listed).");
  AddCommon(urdf, urdf_args.get(), "URDF file to write (atomically)");
  urdf->footer(
      "Example:\n"
      "  kincal calibrate --robot data/robots/ur10.yaml --obs obs.csv "
      "--out cal.yaml\n"
      "  kincal export urdf --robot cal.yaml --out ur10_calibrated.urdf\n"
      "  check_urdf ur10_calibrated.urdf\n"
      "Units: robot.yaml in mm and deg; the URDF in metres and radians (its "
      "own convention).");
  urdf->callback([run, urdf_args] {
    *run = [urdf_args] { return RunExportUrdf(*urdf_args); };
  });

  auto dh_args = std::make_shared<ExportArgs>();
  CLI::App* dh = exp->add_subcommand(
      "dh",
      "Write the robot (e.g. a URDF) as robot.yaml in standard DH (mm, deg) "
      "with the same forward kinematics. Needs joint 1 to move about the "
      "base z axis; exit 2 with the axis found otherwise.");
  AddCommon(dh, dh_args.get(), "robot.yaml to write (atomically)");
  dh->footer(
      "Example:\n"
      "  kincal export dh --robot panda.urdf --tip ball_link --out "
      "panda_dh.yaml\n"
      "Units: the URDF in metres and radians; robot.yaml in mm and deg.");
  dh->callback(
      [run, dh_args] { *run = [dh_args] { return RunExportDh(*dh_args); }; });

  auto ur_args = std::make_shared<ExportArgs>();
  CLI::App* ur = exp->add_subcommand(
      "ur-calibration",
      "Write a UR robot's geometry as the kinematics YAML of Universal "
      "Robots' ROS description (ur_description default_kinematics.yaml form: "
      "per joint x y z in m, roll pitch yaw in rad, and a hash), for "
      "ur_robot_driver's kinematics_params_file. The tool becomes the "
      "pendant's TCP offset (in JSON 'tcp' and in a comment); model "
      "extensions have no field there and are listed in 'not_exported'. "
      "Exit 2 unless the robot has exactly 6 revolute joints.");
  AddCommon(ur, ur_args.get(), "kinematics YAML to write (atomically)");
  ur->add_option("--robot-base", ur_args->robot_base,
                 "the robot file's base frame: base (the controller's Base, "
                 "UR's DH, data/robots/ur10.yaml) or base_link (ROS, e.g. "
                 "ur_description's URDF from base_link)")
      ->check(CLI::IsMember({"base", "base_link"}))
      ->capture_default_str();
  ur->footer(
      "Example:\n"
      "  kincal export ur-calibration --robot data/robots/ur10.yaml --out "
      "ur10_kinematics.yaml --json\n"
      "  ros2 launch ur_robot_driver ur_control.launch.py ur_type:=ur10 "
      "robot_ip:=<ip> kinematics_params_file:=$PWD/ur10_kinematics.yaml\n"
      "Units: robot.yaml in mm and deg; the kinematics file in metres and "
      "radians; the TCP in mm and a rotation vector (rad, deg).");
  ur->callback([run, ur_args] {
    *run = [ur_args] { return RunExportUrCalibration(*ur_args); };
  });
}

}  // namespace kincal::app
