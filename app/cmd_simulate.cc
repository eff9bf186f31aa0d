// kincal simulate: a seeded synthetic session for any robot file.

#include <algorithm>
#include <cstdio>
#include <iostream>
#include <memory>

#include "app/app_util.h"
#include "app/command.h"
#include "app/front_end.h"
#include "calib/model_state.h"
#include "data/atomic_file.h"
#include "data/error.h"
#include "data/provenance.h"
#include "data/rigid3.h"
#include "data/urdf.h"
#include "synth/recorded_session.h"
#include "synth/render.h"
#include "synth/rig_placement.h"
#include "synth/simulate.h"

namespace kincal::app {
namespace {

struct SimulateArgs {
  std::string robot, out, mode = "random", root, tip;
  std::vector<std::string> effects;
  SimulateOptions options;
  bool no_time = false, no_points = false, json = false;
  // --render: stereo images of the tool target at every pose.
  bool render = false;
  int render_width = 1280, render_height = 1024;
  int render_cameras = 2;  // 1, 2 or 3 (synth/rig_placement.h)
  RenderOptions render_options;
};

// The simulation options of the command line (mode, effects, columns).
SimulateOptions ResolveOptions(const SimulateArgs& args, const Robot& nominal) {
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
  return opt;
}

// Places the rig to see the tips of the simulated poses (its frame becomes
// the measuring frame, in `opt`) and scales the example tool so tags are at
// least ~40 px wide at that distance. Returns the rig's distance (mm).
double PlaceRigAndScaleTool(const Robot& nominal, const Rig& rig,
                            SimulateOptions* opt, Target* target) {
  double rig_distance = 0.0;
  // Same seed, so the same poses and truth; only the frame is placed.
  // 90 % of the tips in view: the rest leave the image, as on a real rig.
  const Rigid3 rig_from_base =
      PlaceRigFacingTips(Simulate(nominal, *opt).base_from_tip, rig,
                         TipFromTool(*target), 0.9, &rig_distance);
  opt->meas_from_base = PoseBlockFromRigid3(rig_from_base);
  const double tag_mm = 40.0 * rig_distance / rig.cameras.at(0).intrinsics.fx;
  const double scale = std::max(1.0, tag_mm / target->tags.at(0).size_mm);
  for (TargetTag& tag : target->tags) {
    tag.size_mm *= scale;
    tag.tool_from_tag.t *= scale;
  }
  target->tip_in_tool *= scale;
  return rig_distance;
}

nlohmann::json EffectsJson(const SimulatedSession& s) {
  nlohmann::json effects = nlohmann::json::array();
  for (size_t i = 0; i < s.effects.size(); ++i) {
    effects.push_back({{"cause", s.effects[i].cause},
                       {"joint", s.effects[i].joint.empty()
                                     ? nlohmann::json(nullptr)
                                     : nlohmann::json(s.effects[i].joint)},
                       {"magnitude", s.effects[i].magnitude},
                       {"note", s.effect_notes[i]}});
  }
  return effects;
}

// truth.json: the seed, effects, measuring frame and true parameters, for
// tests and for judging a diagnosis.
nlohmann::json TruthJson(const SimulatedSession& s, const SimulateOptions& opt,
                         const std::string& mode) {
  nlohmann::json truth;
  truth["command"] = CommandLine();
  truth["seed"] = opt.seed;
  truth["noise_mm"] = opt.noise_mm;
  truth["mode"] = mode;
  truth["poses"] = s.observations.rows.size();
  truth["effects"] = EffectsJson(s);
  truth["meas_from_base"] = {
      {"rotation_vector_deg",
       {s.meas_from_base[0] * 180 / M_PI, s.meas_from_base[1] * 180 / M_PI,
        s.meas_from_base[2] * 180 / M_PI}},
      {"t_mm",
       {s.meas_from_base[3], s.meas_from_base[4], s.meas_from_base[5]}}};
  ModelState truth_state;
  truth_state.chain = Chain::FromRobot(s.truth);
  nlohmann::json params;
  for (const ParamInfo& p : GeometryParams(truth_state.chain)) {
    params[p.name] = p.ToInterface(ParamValue(truth_state, p));
  }
  truth["parameters"] = params;
  return truth;
}

// Renders the simulated poses as a recorded session OUT/session (spec
// layout, joint columns) beside the rig and target it was seen with.
// Returns the frames rendered.
int WriteRenderedSession(const SimulateArgs& args, const Robot& nominal,
                         const SimulatedSession& s, const Rig& rig,
                         const Target& target) {
  const Rigid3 tip_from_tool = TipFromTool(target);
  const Rigid3 rig_from_base{
      RotationMatrixFromVector(Eigen::Vector3d(
          s.meas_from_base[0], s.meas_from_base[1], s.meas_from_base[2])),
      Eigen::Vector3d(s.meas_from_base[3], s.meas_from_base[4],
                      s.meas_from_base[5])};
  RecordedSessionInput in;
  for (const Eigen::Matrix4d& m : s.base_from_tip) {
    in.rig_from_tool.push_back(rig_from_base * Rigid3::FromMatrix(m) *
                               tip_from_tool);
  }
  in.joint_names = nominal.JointNames();
  for (const Observation& row : s.observations.rows) {
    in.joints.push_back(row.q);
    in.t_s.push_back(row.HasTime() ? row.t_s : 0.0);
  }
  if (!s.observations.AnyTime()) in.t_s.clear();
  int rendered = 0;
#ifndef KINCAL_FRONT_END
  rendered = RenderRecordedSession(rig, target, in, args.render_options,
                                   args.options.seed, args.out + "/session");
#endif
  WriteRigYaml(args.out + "/rig.yaml", rig);
  WriteTargetYaml(args.out + "/target.yaml", target);
  return rendered;
}

void PrintSummary(const SimulateArgs& args, const Robot& nominal,
                  const SimulatedSession& s, int rendered, double rig_distance,
                  const Target& target) {
  if (args.json) {
    nlohmann::json j = {
        {"out", args.out},
        {"poses", s.observations.rows.size()},
        {"effects", EffectsJson(s)},
        {"files",
         {"robot.yaml", "observations.csv", "truth.json", "truth_robot.yaml"}}};
    if (args.render) {
      j["render"] = {{"session", args.out + "/session"},
                     {"rig", args.out + "/rig.yaml"},
                     {"target", args.out + "/target.yaml"},
                     {"frames", rendered},
                     {"rig_distance_mm", rig_distance},
                     {"tag_size_mm", target.tags.at(0).size_mm}};
    }
    PrintJson(j);
    return;
  }
  std::cout << "simulated " << s.observations.rows.size() << " poses of "
            << nominal.name << " into " << args.out
            << "/ (robot.yaml, observations.csv, truth.json)\n";
  if (!args.render) return;
  std::cout << "rendered " << rendered << " stereo pairs into " << args.out
            << "/session/ (rig " << rig_distance
            << " mm from the workspace centre); calibrate from them with\n"
            << "  kincal bundle --robot " << args.out << "/robot.yaml --rig "
            << args.out << "/rig.yaml --target " << args.out
            << "/target.yaml --session " << args.out
            << "/session --out cal.yaml --out-obs tracked.csv\n"
            << "or track them with\n  kincal track --rig " << args.out
            << "/rig.yaml --target " << args.out << "/target.yaml --session "
            << args.out << "/session --robot " << args.out
            << "/robot.yaml --out points.csv --out-obs tracked.csv\n";
}

int RunSimulate(SimulateArgs args) {
  const Robot nominal = ReadRobot(args.robot, args.root, args.tip);
  SimulateOptions opt = ResolveOptions(args, nominal);
#ifdef KINCAL_FRONT_END
  // bin/kincal links no image code (app/front_end.h): kincal-vision renders.
  if (args.render) return ExecImageBinary();
  const Rig rig{};
  Target target{};
#else
  const Rig rig = ExampleStereoRig(args.render_width, args.render_height);
  Target target = ExampleTarget();
#endif
  double rig_distance = 0.0;
  if (args.render) {
    args.render_options.motion_angle_deg = 30.0;
#ifndef KINCAL_FRONT_END
    args.render_options.Check();
#endif
    rig_distance = PlaceRigAndScaleTool(nominal, rig, &opt, &target);
  }
  const Rig rendered_rig =
      args.render ? RigWithCameras(rig, args.render_cameras, rig_distance)
                  : rig;
  const SimulatedSession s = Simulate(nominal, opt);
  const nlohmann::json truth = TruthJson(s, opt, args.mode);

  const std::vector<std::string> comment = {
      "simulated session, seed " + std::to_string(opt.seed) +
      "; the true robot and injected effects are in truth.json"};
  const std::string robot_text =
      FormatRobotYaml(nominal, {"nominal robot of a simulated session"});
  const std::string truth_robot_text = FormatRobotYaml(
      s.truth, {"TRUE robot of a simulated session (for tests)"});
  const std::string obs_text = FormatObservationsCsv(s.observations, comment);
  MakeDirs(args.out);
  const int rendered =
      args.render ? WriteRenderedSession(args, nominal, s, rendered_rig, target)
                  : 0;
  WriteFileAtomic(args.out + "/robot.yaml", robot_text);
  WriteFileAtomic(args.out + "/truth_robot.yaml", truth_robot_text);
  WriteFileAtomic(args.out + "/observations.csv", obs_text);
  WriteFileAtomic(args.out + "/truth.json", truth.dump(2) + "\n");
  PrintSummary(args, nominal, s, rendered, rig_distance, target);
  return 0;
}

}  // namespace

void AddSimulateCommand(CLI::App& app, Runner* run) {
  auto args = std::make_shared<SimulateArgs>();
  CLI::App* sub = app.add_subcommand(
      "simulate",
      "Seeded synthetic session: true robot = nominal + random deviations, "
      "poses, measured tip points with noise, optional injected effects");
  AddRobotOptions(sub, &args->robot, &args->root, &args->tip,
                  "robot.yaml or .urdf (nominal)")
      ->required();
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
                  "compliance, cyclic, gain, axis_tilt, elastostatic deg, "
                  "thermal mm_per_h, transmission deg RMS) or drift:mm_per_h "
                  "or "
                  "mount_compliance:deg; repeatable");
  sub->add_option("--seed", args->options.seed, "random seed")
      ->capture_default_str();
  sub->add_flag("--no-time", args->no_time, "omit the t column");
  sub->add_flag("--no-points", args->no_points,
                "fixed-point mode: omit measured x,y,z (joint readings only)");
  sub->add_flag("--render", args->render,
                "also render stereo images of a tagged tool at every pose "
                "(the rig is placed to see the workspace; its frame is the "
                "measuring frame): a recorded session OUT/session (left/, "
                "right/, frames.csv with joint columns, session.yaml) and "
                "OUT/rig.yaml, OUT/target.yaml");
  sub->add_option("--render-width", args->render_width, "image width, px")
      ->capture_default_str();
  sub->add_option("--render-cameras", args->render_cameras,
                  "cameras of the rendered rig: 1 (the left camera alone), 2 "
                  "(left, right) or 3 (and 'top', 120 mm above left, turned "
                  "down to the workspace)")
      ->check(CLI::Range(1, 3))
      ->capture_default_str();
  sub->add_option("--render-height", args->render_height, "image height, px")
      ->capture_default_str();
  sub->add_option("--render-noise", args->render_options.noise_sigma,
                  "image noise, gray levels")
      ->capture_default_str();
  sub->add_option("--render-blur", args->render_options.blur_sigma_px,
                  "optical blur sigma, px")
      ->capture_default_str();
  sub->add_option("--render-exposure", args->render_options.exposure_jitter,
                  "exposure gain jitter (std of the gain)")
      ->capture_default_str();
  sub->add_flag("--render-needle", args->render_options.draw_needle,
                "draw the needle");
  sub->add_option("--render-defocus", args->render_options.defocus_px,
                  "defocus disk radius, px")
      ->capture_default_str();
  sub->add_option("--render-motion", args->render_options.motion_px,
                  "linear motion blur length, px (at 30 deg)")
      ->capture_default_str();
  sub->add_option("--render-vignetting", args->render_options.vignetting,
                  "vignetting: gain 1 - v (r / r_corner)^2")
      ->capture_default_str();
  sub->add_option("--render-jpeg", args->render_options.jpeg_quality,
                  "JPEG-compress the images at this quality (1..100; 0 = "
                  "lossless)")
      ->capture_default_str();
  sub->add_flag("--json", args->json, "print a JSON summary");
  sub->footer(HelpFooter(
      "Example: a BH-7 session with a hidden 0.15 deg backlash in j3, 240 "
      "random poses:\n  kincal simulate --robot data/robots/bh7.yaml --out sim "
      "--poses 240 --noise 0.03 --effect backlash:j3:0.15 --seed 7\n  -> "
      "sim/observations.csv, sim/robot.yaml, sim/truth.json"));
  sub->callback([run, args] { *run = [args] { return RunSimulate(*args); }; });
}

}  // namespace kincal::app
