// kincal compensate: the joint readings to command so that the modelled real
// robot reaches the targets (calib/compensate.h), as a joint CSV and
// optionally a controller program.

#include <Eigen/Geometry>
#include <chrono>
#include <cstdio>
#include <map>
#include <memory>
#include <sstream>

#include "app/app_util.h"
#include "app/command.h"
#include "calib/compensate.h"
#include "calib/evaluate.h"
#include "data/atomic_file.h"
#include "data/csv.h"
#include "data/error.h"
#include "data/observation_checks.h"
#include "data/provenance.h"
#include "data/rigid3.h"
#include "data/robot_program.h"
#include "data/targets_csv.h"
#include "data/urdf.h"
#include "data/yaml_util.h"

namespace kincal::app {
namespace {

struct CompensateArgs {
  std::string robot, root, tip, targets, obs, out, program, program_out;
  std::string frame = "base";
  std::vector<double> start;
  bool skip_unreachable = false;
  bool json = false;
  CompensateOptions options;
};

// Targets from a targets file: tips (and orientations) or a joint program.
std::vector<CompensateTarget> TargetsFromFile(const Robot& robot,
                                              const CompensateArgs& args,
                                              Warnings* warnings) {
  const TargetsFile file = ReadTargetsCsv(args.targets, robot.JointNames());
  std::vector<CompensateTarget> out;
  std::vector<std::vector<double>> readings;
  for (const TargetRow& row : file.rows) {
    CompensateTarget t;
    t.id = row.id;
    t.seed = row.joints;
    t.temp_c = row.temp_c;
    t.from_joints = file.program;
    t.target.position_mm = row.position_mm;
    if (row.has_rotation) {
      if (robot.joints.size() < 6) {
        throw InputError(args.targets, row.line, 1,
                         "rx, ry, rz: the robot has " +
                             std::to_string(robot.joints.size()) +
                             " joints, too few to reach an orientation; give "
                             "x, y, z only");
      }
      t.target.has_rotation = true;
      t.target.rotation =
          RotationMatrixFromVector(row.rotation_deg * M_PI / 180.0);
    }
    if (!row.joints.empty()) {
      for (size_t j = 0; j < row.joints.size(); ++j) {
        CheckReadingWithinLimits(robot.joints[j], row.joints[j], args.targets,
                                 row.line, args.robot);
      }
      readings.push_back(row.joints);
    }
    out.push_back(t);
  }
  if (!readings.empty()) {
    CheckJointUnits(robot, readings, args.targets, warnings);
  }
  return out;
}

// Targets from measured observations: each measured tip brought into the
// base frame by the frame the model registers on them, seeded with the
// readings the robot reached it with (the replay check).
std::vector<CompensateTarget> TargetsFromObservations(const Observations& obs,
                                                      const EvaluateResult& e) {
  const Rigid3 base_from_meas =
      Rigid3FromPoseBlock(e.state.meas_from_base.data()).Inverse();
  std::vector<CompensateTarget> out;
  for (int i : e.rows) {
    const Observation& o = obs.rows[i];
    CompensateTarget c;
    c.id = o.pose;
    c.seed = o.q;
    c.temp_c = o.temp_c;
    c.target.position_mm = base_from_meas * o.p_in_meas;
    out.push_back(c);
  }
  return out;
}

std::string JointCsv(const Robot& robot, const CompensateResult& r) {
  std::ostringstream os;
  os << "# written by " << ToolVersion() << ": " << CommandLine() << "\n";
  os << "target";
  for (const std::string& name : robot.JointNames()) os << "," << name;
  os << "\n";
  for (const CompensatedTarget& t : r.targets) {
    if (!t.reached) continue;
    os << CsvQuote(t.id);
    for (double q : t.q) os << "," << FormatDouble(q);
    os << "\n";
  }
  return os.str();
}

nlohmann::json TargetJson(const CompensatedTarget& t) {
  nlohmann::json j = {{"target", t.id},
                      {"reached", t.reached},
                      {"q", t.q},
                      {"q_nominal", t.q_nom},
                      {"residual_mm", Number(t.residual_mm)},
                      {"sigma_mm", Number(t.sigma_mm)},
                      {"predicted_mm", Number(t.predicted_mm)},
                      {"uncompensated_mm", Number(t.uncompensated_mm)},
                      {"extrapolated", t.extrapolated}};
  if (!t.why.empty()) j["why"] = t.why;
  if (t.rotation_residual_deg > 0) {
    j["rotation_residual_deg"] = Number(t.rotation_residual_deg);
  }
  return j;
}

// Text mode: the unreachable targets (the first 10) and, per reason of
// extrapolation (the joint or the temperature), how many targets and the
// first one.
void PrintTargetIssues(const CompensateResult& r) {
  int shown = 0;
  for (const auto& t : r.targets) {
    if (!t.reached && shown++ < 10) {
      std::printf("  unreachable %s: %s\n", t.id.c_str(), t.why.c_str());
    }
  }
  std::map<std::string, std::pair<int, std::string>> reasons;
  for (const auto& t : r.targets) {
    for (const auto& why : t.extrapolated) {
      const std::string key = why.substr(0, why.find(' '));
      auto& [count, first] = reasons[key];
      if (count++ == 0) first = t.id + ": " + why;
    }
  }
  for (const auto& [key, value] : reasons) {
    std::printf("  extrapolated (%s) at %d targets, e.g. %s\n", key.c_str(),
                value.first, value.second.c_str());
  }
}

int RunCompensate(const CompensateArgs& args) {
  const auto start = std::chrono::steady_clock::now();
  const Robot robot = ReadRobot(args.robot, args.root, args.tip);
  if (args.targets.empty() == args.obs.empty()) {
    throw InputError("give either --targets T.csv or --obs O.csv");
  }
  Warnings warnings = CommandWarnings();
  CompensateOptions options = args.options;
  options.targets_in_measuring_frame = args.frame == "measuring";
  if (!args.start.empty()) {
    if (args.start.size() != robot.joints.size()) {
      throw InputError("--start: expected " +
                       std::to_string(robot.joints.size()) +
                       " readings (one per joint), got " +
                       std::to_string(args.start.size()));
    }
    options.start = args.start;
  }
  std::vector<CompensateTarget> targets;
  EvaluateResult replay;
  double replay_nominal_rms = std::numeric_limits<double>::quiet_NaN();
  if (!args.obs.empty() && options.targets_in_measuring_frame) {
    throw InputError("--obs registers its own frame: leave out --frame");
  }
  if (!options.series.empty() && !options.targets_in_measuring_frame) {
    throw InputError("--series " + options.series +
                     " names a measuring frame: give it with --frame "
                     "measuring (targets in the base frame need none)");
  }
  if (!args.obs.empty()) {
    const Observations obs =
        ReadCheckedObservations(args.obs, robot, args.robot, &warnings);
    RequireOneSeries(obs, "compensate --obs");
    replay = Evaluate(robot, obs);
    if (robot.HasNominal()) {
      replay_nominal_rms = Evaluate(robot.Nominal(), obs).stats.rms_mm;
    }
    targets = TargetsFromObservations(obs, replay);
  } else {
    targets = TargetsFromFile(robot, args, &warnings);
  }
  // Every check and computation before the first write.
  CompensateResult r = Compensate(robot, targets, options);
  warnings.Append(r.warnings);
  std::vector<std::string> unreachable, extrapolated;
  for (const CompensatedTarget& t : r.targets) {
    if (!t.reached) unreachable.push_back(t.id);
    if (!t.extrapolated.empty()) extrapolated.push_back(t.id);
  }
  if (!unreachable.empty() && !args.skip_unreachable) {
    const CompensatedTarget* first = nullptr;
    for (const auto& t : r.targets) {
      if (!t.reached && first == nullptr) first = &t;
    }
    throw InputError(std::to_string(unreachable.size()) + " of " +
                     std::to_string(r.targets.size()) +
                     " targets cannot be reached; the first, " + first->id +
                     ": " + first->why +
                     ". Move the targets into the robot's reach or pass "
                     "--skip-unreachable to write the others");
  }
  std::string program_text, program_path;
  if (!args.program.empty()) {
    const ProgramFormat format = ParseProgramFormat(args.program);
    std::vector<std::string> ids;
    std::vector<std::vector<double>> rows;
    for (const CompensatedTarget& t : r.targets) {
      if (!t.reached) continue;
      ids.push_back(t.id);
      rows.push_back(t.q);
    }
    program_text = FormatJointProgram(format, robot, ids, rows,
                                      {"joint readings compensated by " +
                                       ToolVersion() + ": " + CommandLine()});
    program_path =
        args.program_out.empty()
            ? args.out.substr(0, args.out.rfind('.')) + ProgramExtension(format)
            : args.program_out;
  }
  WriteFileAtomic(args.out, JointCsv(robot, r));
  if (!program_path.empty()) WriteFileAtomic(program_path, program_text);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
          .count();
  if (args.json) {
    nlohmann::json j = {
        {"n", r.targets.size()},
        {"reached", r.reached},
        {"unreachable", unreachable},
        {"extrapolated", extrapolated},
        {"predicted_rms_mm", Number(r.predicted_rms_mm)},
        {"predicted_max_mm", Number(r.predicted_max_mm)},
        {"uncompensated_rms_mm", Number(r.uncompensated_rms_mm)},
        {"out", args.out},
        {"seconds", seconds}};
    if (!program_path.empty()) j["program"] = program_path;
    if (!args.obs.empty()) {
      j["replay"] = {{"rms_mm", Number(replay.stats.rms_mm)},
                     {"nominal_rms_mm", Number(replay_nominal_rms)}};
    }
    nlohmann::json per = nlohmann::json::array();
    for (const auto& t : r.targets) per.push_back(TargetJson(t));
    j["targets"] = per;
    AddWarnings(warnings, &j);
    PrintJson(j);
    return 0;
  }
  std::printf("kincal compensate: %d of %zu targets reached -> %s\n", r.reached,
              r.targets.size(), args.out.c_str());
  std::printf(
      "  predicted tip error after compensation: RMS %.4f mm, max %.4f mm\n",
      r.predicted_rms_mm, r.predicted_max_mm);
  std::printf("  the controller's own readings would miss by RMS %.4f mm\n",
              r.uncompensated_rms_mm);
  PrintTargetIssues(r);
  if (!args.obs.empty()) {
    std::printf(
        "  replay of %s: the model misses the measured tips by RMS %.4f mm "
        "(nominal %.4f mm)\n",
        args.obs.c_str(), replay.stats.rms_mm, replay_nominal_rms);
  }
  if (!program_path.empty()) std::printf("  wrote %s\n", program_path.c_str());
  return 0;
}

}  // namespace

void AddCompensateCommand(CLI::App& app, Runner* run) {
  auto args = std::make_shared<CompensateArgs>();
  CLI::App* sub = app.add_subcommand(
      "compensate",
      "Joint readings to command so that the calibrated robot (geometry and "
      "every extension) reaches the targets");
  AddRobotOptions(sub, &args->robot, &args->root, &args->tip,
                  "calibrated robot.yaml (its nominal: rows are the "
                  "controller's kinematics)")
      ->required();
  sub->add_option("--targets", args->targets,
                  "T.csv: target and x,y,z [rx,ry,rz deg] in the base frame, "
                  "optional seed joint columns and temp_c; or joint columns "
                  "only (a program for the nominal kinematics)");
  sub->add_option("--obs", args->obs,
                  "observations.csv instead of --targets: its measured tips, "
                  "registered into the base frame, seeded by its readings "
                  "(replay check)");
  sub->add_option("--frame", args->frame,
                  "frame of the targets' x,y,z and rx,ry,rz: base (the "
                  "robot's) or measuring (the instrument's, as registered "
                  "when the model was fitted)")
      ->check(CLI::IsMember({"base", "measuring"}))
      ->capture_default_str();
  sub->add_option("--series", args->options.series,
                  "with --frame measuring and a model fitted on several "
                  "series: the series whose instrument frame the targets "
                  "are in (default: the first, with a warning)");
  sub->add_option("--out", args->out,
                  "Q.csv to write: target and one column "
                  "per joint (the robot file's units)")
      ->required();
  sub->add_option("--program", args->program,
                  "also write a controller program: urscript, krl, rapid or "
                  "franka");
  sub->add_option("--program-out", args->program_out,
                  "the program's path (default: --out with the format's "
                  "extension)");
  sub->add_flag("--skip-unreachable", args->skip_unreachable,
                "write the reachable targets and list the others (default: "
                "exit 2 when any target is unreachable)");
  sub->add_option("--temp-c", args->options.temp_c,
                  "temperature for targets without temp_c (needed by a "
                  "thermal term), deg C");
  sub->add_option("--start", args->start,
                  "readings before the first target (approach directions for "
                  "backlash), comma separated")
      ->delimiter(',');
  sub->add_option("--max-correction", args->options.max_correction,
                  "largest change from the controller's readings, deg | mm; "
                  "more means another configuration (refused)")
      ->check(CLI::Range(1e-6, 180.0))
      ->capture_default_str();
  sub->add_flag("--json", args->json, "print one JSON object");
  sub->footer(HelpFooter(
      "Example: compensate a joint program planned for the nominal robot:\n"
      "  kincal compensate --robot extended.yaml --targets poses.csv "
      "--out compensated.csv --program urscript"));
  sub->callback(
      [run, args] { *run = [args] { return RunCompensate(*args); }; });
}

}  // namespace kincal::app
