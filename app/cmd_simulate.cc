// kincal simulate: a seeded synthetic session for any robot file.

#include <cstdio>
#include <iostream>
#include <memory>

#include "app/app_util.h"
#include "app/command.h"
#include "calib/model_state.h"
#include "calib/simulate.h"
#include "data/atomic_file.h"
#include "data/error.h"
#include "data/provenance.h"
#include "data/urdf.h"

namespace kincal::app {
namespace {

struct SimulateArgs {
  std::string robot, out, mode = "random", root, tip;
  std::vector<std::string> effects;
  SimulateOptions options;
  bool no_time = false, no_points = false, json = false;
};

int RunSimulate(const SimulateArgs& args) {
  const Robot nominal = ReadRobot(args.robot, args.root, args.tip);
  SimulateOptions opt = args.options;
  if (args.mode == "random") {
    opt.mode = SimulateOptions::kRandom;
  } else if (args.mode == "fixed-point") {
    opt.mode = SimulateOptions::kFixedPoint;
  } else {
    throw InputError("--mode: expected 'random' or 'fixed-point', got '" +
                     args.mode + "'");
  }
  for (const std::string& e : args.effects) {
    opt.effects.push_back(ParseEffect(e, nominal));
  }
  if (args.no_time) opt.seconds_per_pose = 0;
  opt.measure_points = !args.no_points;
  const SimulatedSession s = Simulate(nominal, opt);

  // Truth, for tests and for judging a diagnosis.
  nlohmann::json truth;
  truth["command"] = CommandLine();
  truth["seed"] = opt.seed;
  truth["noise_mm"] = opt.noise_mm;
  truth["mode"] = args.mode;
  truth["poses"] = s.observations.rows.size();
  nlohmann::json effects = nlohmann::json::array();
  for (size_t i = 0; i < s.effects.size(); ++i) {
    effects.push_back({{"cause", s.effects[i].cause},
                       {"joint", s.effects[i].joint.empty()
                                     ? nlohmann::json(nullptr)
                                     : nlohmann::json(s.effects[i].joint)},
                       {"magnitude", s.effects[i].magnitude},
                       {"note", s.effect_notes[i]}});
  }
  truth["effects"] = effects;
  truth["meas_from_base"] = {
      {"rotation_vector_deg",
       {s.meas_from_base[0] * 180 / M_PI, s.meas_from_base[1] * 180 / M_PI,
        s.meas_from_base[2] * 180 / M_PI}},
      {"t_mm", {s.meas_from_base[3], s.meas_from_base[4], s.meas_from_base[5]}}};
  ModelState truth_state;
  truth_state.chain = Chain::FromRobot(s.truth);
  nlohmann::json params;
  for (const ParamInfo& p : GeometryParams(truth_state.chain)) {
    params[p.name] = p.ToInterface(ParamValue(truth_state, p));
  }
  truth["parameters"] = params;

  const std::vector<std::string> comment = {
      "simulated session, seed " + std::to_string(opt.seed) +
      "; the true robot and injected effects are in truth.json"};
  const std::string robot_text = FormatRobotYaml(nominal, {"nominal robot of a simulated session"});
  const std::string truth_robot_text = FormatRobotYaml(s.truth, {"TRUE robot of a simulated session (for tests)"});
  const std::string obs_text = FormatObservationsCsv(s.observations, comment);
  MakeDirs(args.out);
  WriteFileAtomic(args.out + "/robot.yaml", robot_text);
  WriteFileAtomic(args.out + "/truth_robot.yaml", truth_robot_text);
  WriteFileAtomic(args.out + "/observations.csv", obs_text);
  WriteFileAtomic(args.out + "/truth.json", truth.dump(2) + "\n");

  if (args.json) {
    PrintJson({{"out", args.out},
               {"poses", s.observations.rows.size()},
               {"effects", effects},
               {"files",
                {"robot.yaml", "observations.csv", "truth.json",
                 "truth_robot.yaml"}}});
  } else {
    std::cout << "simulated " << s.observations.rows.size() << " poses of "
              << nominal.name << " into " << args.out
              << "/ (robot.yaml, observations.csv, truth.json)\n";
  }
  return 0;
}

}  // namespace

void AddSimulateCommand(CLI::App& app, Runner* run) {
  auto args = std::make_shared<SimulateArgs>();
  CLI::App* sub = app.add_subcommand(
      "simulate",
      "Seeded synthetic session: true robot = nominal + random deviations, "
      "poses, measured tip points with noise, optional injected effects");
  sub->add_option("--robot", args->robot, "robot.yaml or .urdf (nominal)")
      ->required();
  sub->add_option("--root", args->root, "URDF root link");
  sub->add_option("--tip", args->tip, "URDF tip link");
  sub->add_option("--out", args->out, "output folder")->required();
  sub->add_option("--mode", args->mode, "random | fixed-point")
      ->capture_default_str();
  sub->add_option("--poses", args->options.poses, "poses (random mode)")
      ->capture_default_str();
  sub->add_option("--fixed-points", args->options.fixed_points,
                  "fixed points (fixed-point mode)")
      ->capture_default_str();
  sub->add_option("--poses-per-point", args->options.poses_per_point,
                  "poses per fixed point")
      ->capture_default_str();
  sub->add_option("--noise", args->options.noise_mm,
                  "measurement noise per axis, mm")
      ->capture_default_str();
  sub->add_option("--sigma-length", args->options.sigma_length_mm,
                  "std of true length deviations, mm")
      ->capture_default_str();
  sub->add_option("--sigma-angle", args->options.sigma_angle_deg,
                  "std of true angle deviations, deg")
      ->capture_default_str();
  sub->add_option("--seconds-per-pose", args->options.seconds_per_pose,
                  "time between poses for the t column, s")
      ->capture_default_str();
  sub->add_option("--effect", args->effects,
                  "injected effect cause:joint:magnitude (backlash, "
                  "compliance, cyclic, gain, axis_tilt) or drift:mm_per_h; "
                  "repeatable");
  sub->add_option("--seed", args->options.seed, "random seed")
      ->capture_default_str();
  sub->add_flag("--no-time", args->no_time, "omit the t column");
  sub->add_flag("--no-points", args->no_points,
                "fixed-point mode: omit measured x,y,z (joint readings only)");
  sub->add_flag("--json", args->json, "print a JSON summary");
  sub->callback([run, args] { *run = [args] { return RunSimulate(*args); }; });
}

}  // namespace kincal::app
