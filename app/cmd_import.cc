// kincal import: converts public real-data sets into observations.csv, and
// a Universal Robots kinematics YAML into robot.yaml.
//   kincal import ipa-ur10 --in Series_C/measurements_random_poses.csv --out
//   O.csv kincal import mukca --dir mukca/data/panda_6/front --out O.csv
// and mrcal camera models into rig.yaml (kincal import cameramodel).

#include <cstdio>
#include <fstream>
#include <memory>
#include <sstream>

#include "app/app_util.h"
#include "app/command.h"
#include "calib/ur_calibration.h"
#include "camcal/cameramodel.h"
#include "data/atomic_file.h"
#include "data/error.h"
#include "data/import_ipa.h"
#include "data/import_mukca.h"
#include "data/urdf.h"

namespace kincal::app {
namespace {

struct ImportArgs {
  std::string in, dir, out, robot, root, tip;
  int every = 1;
  std::string series;   // --series: the label of every row ("" = none)
  bool append = false;  // --append: add the rows to an existing --out
  bool json = false;
};

// Joint names from --robot when given, else the data set's defaults.
std::vector<std::string> JointNames(const ImportArgs& args,
                                    const std::vector<std::string>& fallback) {
  if (args.robot.empty()) return fallback;
  return ReadRobot(args.robot, args.root, args.tip).JointNames();
}

// Every N-th row, each labelled with `series` when given (spec v3 column
// `series`: the rows of one measurement campaign).
Observations EveryNth(const Observations& obs, int every,
                      const std::string& series) {
  Require(every >= 1, "--every must be >= 1");
  std::vector<int> keep;
  for (int i = 0; i < static_cast<int>(obs.rows.size()); i += every) {
    keep.push_back(i);
  }
  Observations out = Subset(obs, keep);
  if (series.empty()) return out;
  for (Observation& o : out.rows) {
    o.series = series;
    o.pose = series + "-" + o.pose;  // unique across concatenated series
  }
  return out;
}

// With --append, the rows of the existing --out first, the new rows after
// them (columns merged by name).
int Finish(const ImportArgs& args, const Observations& imported,
           std::vector<std::string> comment) {
  Observations obs = imported;
  if (args.append && std::ifstream(args.out).good()) {
    obs = ReadObservationsCsv(args.out, imported.joint_names);
    for (const Observation& o : imported.rows) obs.rows.push_back(o);
    comment.insert(comment.begin(), "appended to the rows of " + args.out);
    // Re-parse the result: duplicate pose ids and mixed columns are input
    // errors of the concatenation.
    ParseObservationsCsv(FormatObservationsCsv(obs, comment), args.out,
                         imported.joint_names);
  }
  WriteFileAtomic(args.out, FormatObservationsCsv(obs, comment));
  if (args.json) {
    PrintJson({{"rows", obs.rows.size()},
               {"with_points", obs.CountWithPoints()},
               {"with_fixed_point", obs.CountWithFixedPoint()},
               {"joints", obs.joint_names},
               {"out", args.out}});
  } else {
    std::printf("kincal import: %zu rows -> %s\n", obs.rows.size(),
                args.out.c_str());
  }
  return 0;
}

int RunIpa(const ImportArgs& args) {
  const IpaSeries s =
      ReadIpaSeries(args.in, JointNames(args, IpaUr10JointNames()));
  const Observations obs = EveryNth(s.observations, args.every, args.series);
  std::ostringstream c;
  c << "imported from " << args.in
    << " (ipa-robot-accuracy UR10, Landgraf et al. 2021, MIT): joint angles "
       "rad -> deg, Leica T-Mac position in mm (tracker frame)";
  std::vector<std::string> comment = {c.str()};
  if (args.every > 1) {
    comment.push_back("every " + std::to_string(args.every) +
                      "th row kept; pose ids are the source row numbers");
  }
  if (!s.has_time)
    comment.push_back("no t column: the file's timestamps are truncated");
  return Finish(args, obs, comment);
}

int RunMukca(const ImportArgs& args) {
  const Observations obs =
      EveryNth(ReadMukcaDir(args.dir, JointNames(args, PandaJointNames())),
               args.every, args.series);
  return Finish(args, obs,
                {"imported from " + args.dir +
                 " (MUKCa, platonics-delft/kinematics_calibration, MIT): "
                 "hole_0.csv, hole_1.csv joint sets rad -> deg; sockets "
                 "50 mm apart (use --fixed-distance hole_0,hole_1,50)"});
}

struct UrImportArgs {
  std::string in, out, name = "UR";
  bool json = false;
};

int RunUrCalibration(const UrImportArgs& args) {
  const UrKinematics k = ReadUrKinematicsYaml(args.in);
  const Robot robot = RobotFromUrKinematics(k, args.name);
  WriteFileAtomic(
      args.out,
      FormatRobotYaml(
          robot,
          {"imported from " + args.in + " (Universal Robots kinematics YAML" +
               (k.hash.empty() ? std::string() : ", " + k.hash) +
               "): each joint's origin as a urdf row, m -> mm, rad -> deg",
           "base frame: the controller's Base (ROS base_link_inertia); the "
           "tool row ends at tool0 (zero TCP): put the tool's TCP after it"}));
  if (args.json) {
    PrintJson({{"out", args.out},
               {"robot", robot.name},
               {"joints", robot.JointNames()},
               {"hash", k.hash}});
  } else {
    std::printf("kincal import ur-calibration: %s -> %s\n", args.in.c_str(),
                args.out.c_str());
  }
  return 0;
}

struct CameraModelImportArgs {
  std::vector<std::string> cameras;  // NAME=FILE
  std::string out;
  double unit_mm = 0;
  bool json = false;
};

int RunCameraModelImport(const CameraModelImportArgs& args) {
  std::vector<std::pair<std::string, CameraModelFile>> models;
  for (const std::string& spec : args.cameras) {
    const size_t eq = spec.find('=');
    if (eq == std::string::npos || eq == 0 || eq + 1 == spec.size()) {
      throw InputError("--camera '" + spec + "': expected NAME=FILE");
    }
    models.emplace_back(spec.substr(0, eq),
                        ReadCameraModel(spec.substr(eq + 1)));
  }
  const Rig rig = RigFromCameraModels(models, args.unit_mm);
  WriteRigYaml(args.out, rig);
  if (args.json) {
    nlohmann::json names = nlohmann::json::array();
    for (const Camera& cam : rig.cameras) names.push_back(cam.intrinsics.name);
    PrintJson({{"out", args.out},
               {"cameras", names},
               {"unit_mm", args.unit_mm},
               {"baseline_mm", rig.BaselineMm()}});
  } else {
    std::printf("kincal import cameramodel: %zu camera(s) -> %s\n",
                rig.cameras.size(), args.out.c_str());
  }
  return 0;
}

void CommonOptions(CLI::App* sub, ImportArgs* args) {
  sub->add_option("--out", args->out, "observations.csv to write")->required();
  AddRobotOptions(sub, &args->robot, &args->root, &args->tip,
                  "robot file whose joint names the columns map to (in order)");
  sub->add_option("--every", args->every, "keep every N-th row")
      ->capture_default_str();
  sub->add_flag("--append", args->append,
                "add the rows to those of --out when it exists (one file of "
                "several series: give each its --series label)");
  sub->add_option("--series", args->series,
                  "label every row with this series (column `series`: one "
                  "measuring frame per campaign when files are "
                  "concatenated)");
  sub->add_flag("--json", args->json, "print one JSON object");
}

}  // namespace

void AddImportCommand(CLI::App& app, Runner* run) {
  CLI::App* sub = app.add_subcommand(
      "import", "Convert public real-data sets into observations.csv");
  sub->require_subcommand(1);

  auto ipa = std::make_shared<ImportArgs>();
  CLI::App* s1 = sub->add_subcommand(
      "ipa-ur10",
      "UR10 laser-tracker series of ipa-robot-accuracy (';', decimal commas)");
  s1->add_option("--in", ipa->in, "Series_X/measurements_*.csv")->required();
  CommonOptions(s1, ipa.get());
  s1->footer(
      HelpFooter("Example:\n  kincal import ipa-ur10 --in "
                 "../shared/data/ipa-robot-accuracy/Series_C/"
                 "measurements_random_poses.csv --robot data/robots/ur10.yaml "
                 "--out ur10_C.csv"));
  s1->callback([run, ipa] { *run = [ipa] { return RunIpa(*ipa); }; });

  auto mukca = std::make_shared<ImportArgs>();
  CLI::App* s2 = sub->add_subcommand(
      "mukca", "MUKCa Panda socket recording (hole_0.csv, hole_1.csv)");
  s2->add_option("--dir", mukca->dir, "folder with hole_0.csv and hole_1.csv")
      ->required();
  CommonOptions(s2, mukca.get());
  s2->footer(HelpFooter(
      "Example:\n  kincal import mukca --dir "
      "../shared/data/mukca/data/panda_6/front --out panda_front.csv"));
  s2->callback([run, mukca] { *run = [mukca] { return RunMukca(*mukca); }; });

  auto ur = std::make_shared<UrImportArgs>();
  CLI::App* s3 = sub->add_subcommand(
      "ur-calibration",
      "Universal Robots kinematics YAML (ur_description "
      "default_kinematics.yaml, ur_calibration's output) -> robot.yaml "
      "(convention urdf, tool row = tool0)");
  s3->add_option("--in", ur->in, "kinematics YAML")->required();
  s3->add_option("--out", ur->out, "robot.yaml to write")->required();
  s3->add_option("--name", ur->name, "robot name")->capture_default_str();
  s3->add_flag("--json", ur->json, "print one JSON object");
  s3->footer(HelpFooter(
      "Example:\n  kincal import ur-calibration --in "
      "my_robot_calibration.yaml --name UR10 --out ur10_factory.yaml"));
  s3->callback([run, ur] { *run = [ur] { return RunUrCalibration(*ur); }; });

  auto cm = std::make_shared<CameraModelImportArgs>();
  CLI::App* s4 = sub->add_subcommand(
      "cameramodel",
      "mrcal .cameramodel files (LENSMODEL_PINHOLE, OPENCV4/5/8) -> rig.yaml; "
      "the first camera is the rig frame");
  s4->add_option("--camera", cm->cameras,
                 "NAME=FILE.cameramodel, once per camera, first = reference")
      ->required();
  s4->add_option("--unit-mm", cm->unit_mm,
                 "length of one unit of the models' translations in mm "
                 "(1000 for metres, 1 for mm)")
      ->required();
  s4->add_option("--out", cm->out, "rig.yaml to write")->required();
  s4->add_flag("--json", cm->json, "print one JSON object");
  s4->footer(HelpFooter(
      "Example:\n  kincal import cameramodel --camera left=left.cameramodel "
      "--camera right=right.cameramodel --unit-mm 1000 --out rig.yaml"));
  s4->callback(
      [run, cm] { *run = [cm] { return RunCameraModelImport(*cm); }; });
}

}  // namespace kincal::app
