// kincal simulate: a seeded synthetic session for any robot file.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <limits>
#include <memory>
#include <random>

#include "app/app_util.h"
#include "app/command.h"
#include "app/front_end.h"
#include "calib/model_state.h"
#include "data/atomic_file.h"
#include "data/error.h"
#include "data/provenance.h"
#include "data/rigid3.h"
#include "data/urdf.h"
#include "synth/flange_scene.h"
#include "synth/recorded_session.h"
#include "synth/render.h"
#include "synth/rig_placement.h"
#include "synth/simulate.h"

namespace kincal::app {
namespace {

// Cameras on the flange: the distance from the rig to the board.
constexpr double kFlangeWorkingDistanceMm = 450.0;

struct SimulateArgs {
  std::string robot, out, mode = "random", root, tip;
  std::vector<std::string> effects;
  SimulateOptions options;
  bool no_time = false, no_points = false, json = false;
  // --render: stereo images of the tool target at every pose.
  bool render = false;
  int render_width = 1280, render_height = 1024;
  int render_cameras = 2;  // 1, 2 or 3 (synth/rig_placement.h)
  // world: the rig on a stand, the tool target on the flange; flange: the
  // rig on the flange, a fixed board in the world (FlangeScene).
  std::string render_mount = "world";
  RenderOptions render_options;
  // --render-light: a distant light at this angle from the reference
  // camera's axis (turned about its y axis); NaN = even light.
  double render_light_deg = std::numeric_limits<double>::quiet_NaN();
  std::string render_demosaic = "bilinear";  // with --render-bayer
};

// Cameras on the flange: where the rig sits on the tool and the board in
// the base, both hidden from the bundle (truth.json has them).
struct FlangeScene {
  bool on = false;
  Rigid3 tip_from_rig;  // the rig origin at the true tool row's end
  Rigid3 base_from_board;
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

#ifndef KINCAL_FRONT_END
// (bin/kincal renders nothing: it execs kincal-vision, app/front_end.h.)

// The rig's hidden mounting on the flange, drawn from the seed: its origin
// at the tool row's end (the tip frame's origin, so the true robot's tool
// row ends at the rig origin, as the spec has the calibrated one end), its
// optical axis tilted 0..20 deg from the tip frame's z, any roll.
Rigid3 DrawFlangeMounting(uint64_t seed) {
  std::mt19937_64 rng(seed ^ 0x5eedf1a9e5ull);
  std::normal_distribution<double> n(0.0, 1.0);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const Eigen::Vector3d axis =
      Eigen::Vector3d(n(rng), n(rng), 0.0).normalized();
  const double tilt = 20.0 * u(rng) * M_PI / 180.0;
  const double roll = 2.0 * M_PI * u(rng);
  Rigid3 r;
  r.R = (Eigen::AngleAxisd(tilt, axis) *
         Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitZ()))
            .toRotationMatrix();
  return r;
}

// Too few random poses see the board (a six-axis arm's wrist seldom points
// at one spot): more from small joint moves (N(0, 8) deg or mm per joint,
// within the robot's limits) of poses that do, until `wanted`; then the
// visiting order is shuffled so the approach directions stay random.
void GrowSeenPoses(const Robot& nominal, SimulateOptions candidates,
                   const Rig& rig, const Rigid3& tip_from_rig,
                   const Target& board, const Rigid3& base_from_board,
                   double distance_mm, int min_tags, size_t wanted,
                   std::vector<std::vector<double>>* seen) {
  if (seen->size() >= wanted || seen->empty()) return;
  std::mt19937_64 rng(candidates.seed * 7919 + 11);
  std::normal_distribution<double> step(0.0, 8.0);
  for (int round = 0; round < 20 && seen->size() < wanted; ++round) {
    candidates.readings.clear();
    for (size_t k = 0; k < 4 * wanted; ++k) {
      std::vector<double> q = (*seen)[rng() % seen->size()];
      for (size_t j = 0; j < q.size(); ++j) {
        q[j] += step(rng);
        const RobotRow& row = nominal.joints[j];
        if (row.HasLimits()) q[j] = std::clamp(q[j], row.lower, row.upper);
      }
      candidates.readings.push_back(q);
    }
    const SimulatedSession more = Simulate(nominal, candidates);
    for (int i : PosesSeeingBoard(more.base_from_tip, rig, tip_from_rig, board,
                                  base_from_board, distance_mm, min_tags)) {
      seen->push_back(candidates.readings[i]);
    }
  }
  std::shuffle(seen->begin(), seen->end(), rng);
}

// Cameras on the flange: a 5 x 4 AprilGrid board (tags ~50 px wide at the
// working distance) placed where the reference camera sees it on most of
// 80x --poses random poses of the seed (same truth), turned about its
// normal by a seeded angle; the session's poses are those that see it (near,
// within 60 deg of its normal, half its tags; GrowSeenPoses when too few),
// and its measuring frame is the board's (observations.csv then holds the
// rig origins in the board frame, what `track` measures).
FlangeScene PlaceFlangeBoard(const Robot& nominal, const Rig& rig,
                             double distance_mm, SimulateOptions* opt,
                             Target* board) {
  AprilGrid grid;
  grid.cols = 5;
  grid.rows = 4;
  grid.tag_size_mm = 50.0 * distance_mm / rig.cameras.at(0).intrinsics.fx;
  *board = grid.AsTarget();
  board->has_tip = false;
  const int min_tags = static_cast<int>(board->tags.size()) / 2;
  FlangeScene scene;
  scene.on = true;
  scene.tip_from_rig = DrawFlangeMounting(opt->seed);
  SimulateOptions candidates = *opt;
  candidates.effects.clear();
  candidates.poses = 80 * opt->poses;
  const SimulatedSession all = Simulate(nominal, candidates);
  const FlangeBoardPlacement place =
      PlaceBoardForFlangeRig(all.base_from_tip, rig, scene.tip_from_rig, *board,
                             distance_mm, min_tags);
  // Turn the board about its normal through its centre.
  const double turn = (opt->seed % 360) * M_PI / 180.0;
  const Eigen::Vector3d centre(
      0.5 * grid.cols * grid.tag_size_mm * (1 + grid.spacing_ratio),
      0.5 * grid.rows * grid.tag_size_mm * (1 + grid.spacing_ratio), 0.0);
  Rigid3 spin;
  spin.R = Eigen::AngleAxisd(turn, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  spin.t = centre - spin.R * centre;
  scene.base_from_board = place.base_from_board * spin;
  std::vector<std::vector<double>> seen;
  for (int i :
       PosesSeeingBoard(all.base_from_tip, rig, scene.tip_from_rig, *board,
                        scene.base_from_board, distance_mm, min_tags)) {
    seen.push_back(all.observations.rows[i].q);
  }
  const size_t wanted = static_cast<size_t>(opt->poses);
  GrowSeenPoses(nominal, candidates, rig, scene.tip_from_rig, *board,
                scene.base_from_board, distance_mm, min_tags, wanted, &seen);
  if (seen.size() < wanted) {
    throw InputError("--render-mount flange: only " +
                     std::to_string(seen.size()) +
                     " poses found that see the board; ask for fewer --poses");
  }
  seen.resize(wanted);
  opt->readings = seen;
  opt->meas_from_base = PoseBlockFromRigid3(scene.base_from_board.Inverse());
  return scene;
}
#endif  // KINCAL_FRONT_END

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

nlohmann::json PoseJson(const Rigid3& r) {
  const Eigen::Vector3d w = RotationVectorFromMatrix(r.R) * 180 / M_PI;
  return {{"rotation_vector_deg", {w.x(), w.y(), w.z()}},
          {"t_mm", {r.t.x(), r.t.y(), r.t.z()}}};
}

// truth.json: the seed, effects, measuring frame and true parameters, for
// tests and for judging a diagnosis; with the cameras on the flange also
// the true flange_from_rig and base_from_target.
nlohmann::json TruthJson(const SimulatedSession& s, const SimulateOptions& opt,
                         const std::string& mode, const FlangeScene& scene) {
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
  if (scene.on) {
    const Chain chain = Chain::FromRobot(s.truth);
    const ChainRow& tool = chain.rows[chain.tool_row()];
    const Rigid3 flange_from_tip = Rigid3::FromMatrix(
        RowTransform<double>(chain.convention, tool, tool.p.data(), 0.0));
    truth["mount"] = "flange";
    truth["flange_from_rig"] = PoseJson(flange_from_tip * scene.tip_from_rig);
    truth["base_from_target"] = PoseJson(scene.base_from_board);
  }
  return truth;
}

// Renders the simulated poses as a recorded session OUT/session (spec
// layout, joint columns) beside the rig and target it was seen with.
// Returns the frames rendered.
int WriteRenderedSession(const SimulateArgs& args, const Robot& nominal,
                         const SimulatedSession& s, const Rig& rig,
                         const Target& target, const FlangeScene& scene) {
  RecordedSessionInput in;
  for (const Eigen::Matrix4d& m : s.base_from_tip) {
    const Rigid3 base_from_tip = Rigid3::FromMatrix(m);
    if (scene.on) {  // rig_from_board
      in.rig_from_tool.push_back(
          (base_from_tip * scene.tip_from_rig).Inverse() *
          scene.base_from_board);
    } else {  // rig_from_base * base_from_tip * tip_from_tool
      in.rig_from_tool.push_back(Rigid3FromPoseBlock(s.meas_from_base.data()) *
                                 base_from_tip * TipFromTool(target));
    }
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
  FlangeScene scene;
  Rig rendered_rig = rig;
  if (args.render) {
    args.render_options.motion_angle_deg = 30.0;
    if (std::isfinite(args.render_light_deg)) {
      const double a = args.render_light_deg * M_PI / 180.0;
      args.render_options.light_in_rig =
          Eigen::Vector3d(std::sin(a), 0.0, std::cos(a));
    }
    if (args.render_options.bayer_raw) args.render_options.bayer = true;
    args.render_options.demosaic =
        args.render_demosaic == "vng"  ? RenderOptions::Demosaic::kVng
        : args.render_demosaic == "ea" ? RenderOptions::Demosaic::kEdgeAware
                                       : RenderOptions::Demosaic::kBilinear;
    if (args.render_options.shadow_tag >= 0) {
      args.render_options.shadow_angle_deg = 30.0;
      args.render_options.shadow_offset = 0.1;
    }
#ifndef KINCAL_FRONT_END
    args.render_options.Check();
#endif
    if (args.render_mount == "flange") {
      rig_distance = kFlangeWorkingDistanceMm;
      rendered_rig = RigWithCameras(rig, args.render_cameras, rig_distance);
      rendered_rig.mount = RigMount::kFlange;
#ifndef KINCAL_FRONT_END
      scene =
          PlaceFlangeBoard(nominal, rendered_rig, rig_distance, &opt, &target);
#endif
    } else {
      rig_distance = PlaceRigAndScaleTool(nominal, rig, &opt, &target);
      rendered_rig = RigWithCameras(rig, args.render_cameras, rig_distance);
    }
#ifndef KINCAL_FRONT_END
    if (args.render_options.shadow_tag >=
        static_cast<int>(target.tags.size())) {
      throw InputError(
          "--render-shadow " + std::to_string(args.render_options.shadow_tag) +
          ": the rendered target has " + std::to_string(target.tags.size()) +
          " tags; give an index 0.." + std::to_string(target.tags.size() - 1) +
          " (or -1 for no shadow)");
    }
#endif
  }
  const SimulatedSession s = Simulate(nominal, opt);
  const nlohmann::json truth = TruthJson(s, opt, args.mode, scene);

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
      args.render
          ? WriteRenderedSession(args, nominal, s, rendered_rig, target, scene)
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
  sub->add_option("--render-mount", args->render_mount,
                  "where the rendered cameras are: world (on a stand, the "
                  "tool target on the flange) or flange (on the flange at a "
                  "hidden mounting, 450 mm from a fixed AprilGrid board at a "
                  "hidden pose; observations.csv then holds the rig origins "
                  "in the board frame)")
      ->check(CLI::IsMember({"world", "flange"}))
      ->capture_default_str();
  sub->add_option("--render-height", args->render_height, "image height, px")
      ->capture_default_str();
  sub->add_option("--render-noise", args->render_options.noise_sigma,
                  "image noise, gray levels")
      ->capture_default_str();
  sub->add_option("--render-blur", args->render_options.blur_sigma_px,
                  "optical blur sigma, px")
      ->capture_default_str();
  sub->add_flag(
      "!--render-blur-on-pixels", args->render_options.fine_optics,
      "blur the pixel-integrated image instead of the light before the "
      "pixels integrate it (the renderer before the optics were fine; for "
      "comparisons)");
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
  sub->add_option("--render-light", args->render_light_deg,
                  "light the tags by a distant light travelling at this "
                  "angle (deg) from the reference camera's axis, turned "
                  "about its y axis: each tag's paper gets ambient + (1 - "
                  "ambient) cos (Lambert), so tags turned away are dim "
                  "(default: even light)")
      ->check(CLI::Range(-89.0, 89.0));
  sub->add_option("--render-ambient", args->render_options.ambient,
                  "with --render-light: the share of the light every tag "
                  "gets whatever its angle")
      ->capture_default_str();
  sub->add_option("--render-shadow", args->render_options.shadow_tag,
                  "a shadow edge (gain 0.35, at 30 deg) across this tag of "
                  "the target (index in target.yaml; -1 = none)")
      ->capture_default_str();
  sub->add_flag("--render-bayer", args->render_options.bayer,
                "a colour sensor: RGGB photosites with their own gains and "
                "noise, demosaiced to gray by OpenCV");
  sub->add_option("--render-demosaic", args->render_demosaic,
                  "with --render-bayer: the driver's demosaic, OpenCV's "
                  "bilinear Bayer to gray, or its VNG or edge-aware (ea) "
                  "demosaic to colour, then to gray")
      ->check(CLI::IsMember({"bilinear", "vng", "ea"}))
      ->capture_default_str();
  sub->add_flag("--render-bayer-raw", args->render_options.bayer_raw,
                "a colour sensor's raw mosaic (as --render-bayer, not "
                "demosaiced: one photosite per pixel; read it with track/"
                "bundle --bayer RGGB)");
  sub->add_flag("--json", args->json, "print a JSON summary");
  sub->footer(HelpFooter(
      "Example: a BH-7 session with a hidden 0.15 deg backlash in j3, 240 "
      "random poses:\n  kincal simulate --robot data/robots/bh7.yaml --out sim "
      "--poses 240 --noise 0.03 --effect backlash:j3:0.15 --seed 7\n  -> "
      "sim/observations.csv, sim/robot.yaml, sim/truth.json"));
  sub->callback([run, args] { *run = [args] { return RunSimulate(*args); }; });
}

}  // namespace kincal::app
