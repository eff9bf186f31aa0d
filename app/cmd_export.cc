// kincal export urdf | dh: the (calibrated) robot model in another
// convention, with the same forward kinematics (calib/urdf_export.h).

#include <cstdio>
#include <memory>

#include "app/app_util.h"
#include "app/command.h"
#include "calib/urdf_export.h"
#include "data/atomic_file.h"
#include "data/robot.h"
#include "data/urdf.h"

namespace kincal::app {
namespace {

struct ExportArgs {
  std::string robot, out, root, tip;
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
}

}  // namespace kincal::app
