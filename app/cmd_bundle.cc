// kincal bundle: one Ceres problem from the tag corners of a recorded
// session to the robot's parameters (../shared/spec/formats.md v2,
// docs/BUNDLE.md).

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <map>
#include <memory>
#include <optional>
#include <sstream>

#include "app/app_util.h"
#include "app/command.h"
#include "app/front_end.h"
#include "bundle/bundle.h"
#include "bundle/cross_validation.h"
#include "bundle/observe.h"
#include "calib/chain.h"
#include "calib/model_state.h"
#include "camcal/rig.h"
#include "data/atomic_file.h"
#include "data/error.h"
#include "data/observations.h"
#include "data/progress.h"
#include "data/provenance.h"
#include "data/robot.h"
#include "data/session.h"
#include "data/urdf.h"
#include "data/yaml_util.h"
#include "vision/target.h"
#include "vision/tool_pose.h"

namespace kincal::app {
namespace {

struct BundleArgs {
  std::string robot, rig, target, session, out, out_rig, out_obs;
  std::string extensions;  // comma-separated parameter names
  int folds = 0;           // k-fold cross-validation (0 = off)
  BundleOptions options;
  // Quality gate of --out-obs tips (as `track`).
  int min_tags = 2;
  double max_reproj_px = 0.5;
  // A finding must move the tool row's end by at least this much (RMS, mm).
  double min_effect_mm = 0.005;
  // Raw mosaic pattern of the images; empty: session.yaml's, else none
  // (ChooseBayerPattern).
  std::string bayer;
  // Corners' weights from their tags' contrast (ObserveOptions).
  double full_weight_contrast = ObserveOptions().full_weight_contrast;
  bool json = false, quiet = false;
};

std::vector<std::string> SplitNames(const std::string& text) {
  std::vector<std::string> out;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) {
    if (!item.empty()) out.push_back(item);
  }
  return out;
}

// The frame's tool pose from its bundle corners on `rig` (the refined rig).
ToolPoseResult RefitPose(const Rig& rig, const Target& target,
                         const BundleFrame& f) {
  std::vector<std::vector<TagDetection>> dets(rig.cameras.size());
  std::map<std::pair<int, int>, TagDetection> by_tag;
  std::map<std::pair<int, int>, int> count;
  for (const BundleCorner& c : f.corners) {
    TagDetection& d = by_tag[{c.camera, c.tag}];
    d.id = target.tags[c.tag].id;
    d.corners[c.corner] = c.px;
    d.detector_corners[c.corner] = c.px;
    ++count[{c.camera, c.tag}];
  }
  // Tags the per-corner check left with 3 corners are left out here.
  for (const auto& [key, d] : by_tag) {
    if (count[key] == 4) dets[key.first].push_back(d);
  }
  return EstimateToolPose(rig, target, dets);
}

// --extensions names: "j3.backlash" as given; a cause without a joint
// ("backlash") stands for that cause at every joint; "axis_tilt" for the
// Hayati beta of rows with parallel axes.
std::vector<std::string> ExpandExtensions(const Robot& robot,
                                          const std::string& text) {
  std::vector<std::string> out;
  for (const std::string& name : SplitNames(text)) {
    if (name.find('.') != std::string::npos) {
      out.push_back(name);
      continue;
    }
    if (name == "axis_tilt") {
      const Chain chain = Chain::FromRobot(robot);
      for (int row : ParallelAxisRows(chain)) {
        out.push_back(AxisTiltParam(chain, row).name);
      }
      continue;
    }
    for (const std::string& j : robot.JointNames()) {
      if (name == "cyclic") {
        out.push_back(j + ".cyclic_cos");
        out.push_back(j + ".cyclic_sin");
      } else {
        out.push_back(j + "." + name);
      }
    }
  }
  return out;
}

// --out-obs: the point the tool row ends at as the cameras saw it at each
// frame's joint readings (MeasuredPoint: the needle tip in the rig frame, or
// with the cameras on the flange the rig origin in the target frame; pose
// refitted on the refined rig when cameras were refined); empty where the
// pose misses the quality gate.
std::string TrackedTipsCsv(const BundleArgs& args, const Robot& robot,
                           const Target& target, const Session& session,
                           const SessionObservations& obs,
                           const BundleResult& r, int* points) {
  Observations out;
  out.source = session.frames_csv;
  out.joint_names = robot.JointNames();
  for (const BundleFrame& f : obs.frames) {
    Observation o;
    o.pose = std::to_string(f.frame);
    o.q = f.q_reading;
    o.t_s = f.t_s;
    ToolPoseResult p;
    if (args.options.refine_cameras && !f.corners.empty()) {
      p = RefitPose(r.rig, target, f);
    } else {
      p.found = f.tracked;
      p.rig_from_tool = f.rig_from_tool;
      p.rms_px = f.tracked_rms_px;
      p.tags_used = f.tracked_tags;
    }
    if (p.found && p.tags_used >= args.min_tags &&
        p.rms_px <= args.max_reproj_px &&
        SeenByEnoughCameras(f, static_cast<int>(r.rig.cameras.size()))) {
      o.has_point = true;
      o.p_in_meas = MeasuredPoint(r.mount, target, p.rig_from_tool);
      ++*points;
    }
    out.rows.push_back(o);
  }
  const std::string what =
      r.mount == RigMount::kFlange
          ? "rig origins (reference camera's optical centre) seen by the "
            "cameras on the flange (fixed target's frame, mm)"
          : "needle tips seen by the cameras (rig frame, mm)";
  return FormatObservationsCsv(
      out, {what +
            " at the session's joint readings; empty where only one camera "
            "of several saw the target, or its pose used fewer than " +
            std::to_string(args.min_tags) + " tags or fit worse than " +
            FormatDouble(args.max_reproj_px) + " px"});
}

// Each requested extension's estimate with its z = |value| / sigma and its
// effect on the tool row's end; significant when z > 4 and the effect is at
// least min_effect_mm (a 2 um move is no finding however small its sigma:
// the sigma assumes independent pixel errors, and rendering or detection
// biases shared by a frame's corners are not).
nlohmann::json ExtensionsJson(const BundleOptions& options,
                              const BundleResult& r, double min_effect_mm) {
  nlohmann::json extensions = nlohmann::json::array();
  for (const std::string& name : options.extensions) {
    for (const BundleParam& p : r.params) {
      if (p.name != name) continue;
      const double z = std::isfinite(p.sigma) && p.sigma > 0
                           ? std::abs(p.value) / p.sigma
                           : 0.0;
      const double effect = std::isfinite(p.effect_mm) ? p.effect_mm : 0.0;
      extensions.push_back(
          {{"name", p.name},
           {"value", p.value},
           {"sigma", p.sigma},
           {"z", z},
           {"effect_mm", effect},
           {"significant", z > 4.0 && effect >= min_effect_mm}});
    }
  }
  return extensions;
}

// Significant extensions, strongest first: what the images name.
nlohmann::json FindingsJson(const nlohmann::json& extensions) {
  nlohmann::json findings = nlohmann::json::array();
  std::vector<nlohmann::json> sig;
  for (const auto& e : extensions) {
    if (e["significant"].get<bool>()) sig.push_back(e);
  }
  std::sort(sig.begin(), sig.end(), [](const auto& a, const auto& b) {
    return a["z"].template get<double>() > b["z"].template get<double>();
  });
  for (const auto& e : sig) {
    const std::string name = e["name"];
    const size_t dot = name.find('.');
    findings.push_back(
        {{"cause", name.substr(dot + 1)},
         {"joint", name.substr(0, dot)},
         {"magnitude", e["value"]},
         {"sigma", e["sigma"]},
         {"effect_mm", e["effect_mm"]},
         {"ci95",
          {e["value"].get<double>() - 1.96 * e["sigma"].get<double>(),
           e["value"].get<double>() + 1.96 * e["sigma"].get<double>()}}});
  }
  return findings;
}

// The five frames the final model reprojects worst (per-frame RMS).
nlohmann::json WorstFramesJson(const BundleResult& r, const Target& target,
                               const std::vector<BundleFrame>& frames) {
  std::vector<std::pair<double, int>> frame_rms;
  for (size_t i = 0; i < frames.size(); ++i) {
    const BundleFrame& f = frames[i];
    if (f.corners.empty()) continue;
    const Rigid3 rt = ModelRigFromTool(r, static_cast<int>(i));
    double sum = 0;
    for (const BundleCorner& c : f.corners) {
      const Camera& cam = r.rig.cameras[c.camera];
      const Eigen::Vector2d px = Project(
          cam.intrinsics,
          cam.cam_from_rig * (rt * target.tags[c.tag].CornerInTool(c.corner)));
      sum += (px - c.px).squaredNorm();
    }
    frame_rms.push_back({std::sqrt(sum / f.corners.size()), f.frame});
  }
  std::sort(frame_rms.rbegin(), frame_rms.rend());
  nlohmann::json worst = nlohmann::json::array();
  for (size_t k = 0; k < frame_rms.size() && k < 5; ++k) {
    worst.push_back(
        {{"frame", frame_rms[k].second}, {"rms_px", frame_rms[k].first}});
  }
  return worst;
}

nlohmann::json PoseBlockJson(const std::array<double, 6>& b) {
  return nlohmann::json{
      {"rotation_vector_deg",
       {b[0] * 180 / M_PI, b[1] * 180 / M_PI, b[2] * 180 / M_PI}},
      {"t_mm", {b[3], b[4], b[5]}}};
}

// What one run computed, for the summary.
struct BundleRun {
  SessionObservations obs;
  BundleResult result;
  std::optional<BundleCrossValidation> cross_validation;
  int out_obs_points = 0;
  double seconds = 0.0;
};

// What the camera configuration itself cannot determine, beside the
// parameters the data leave unidentifiable (`unidentifiable`): {what, why}.
nlohmann::json NotDeterminedJson(const Rig& rig) {
  nlohmann::json out = nlohmann::json::array();
  if (rig.cameras.size() == 1) {
    out.push_back(
        {{"what", "scale"},
         {"why",
          "one camera sees directions only: every length (the robot's, "
          "the frames' translations) rests on target.yaml's tag sizes; a "
          "wrong tag size scales them all and no image can show it"}});
  } else {
    out.push_back(
        {{"what", "scale"},
         {"why",
          "lengths rest on the rig's baseline and target.yaml's tag sizes "
          "together; a disagreement between them shows as reprojection "
          "error, not as a scale"}});
  }
  if (rig.mount == RigMount::kFlange) {
    out.push_back(
        {{"what", "tool beyond the rig"},
         {"why",
          "the images place the cameras, not a tool: the tool row ends at the "
          "rig origin (the reference camera's optical centre)"}});
  } else {
    out.push_back(
        {{"what", "tool beyond the target"},
         {"why",
          "the images see the tags, not the tip: the tool row ends at "
          "target.yaml's tip_in_tool as measured by `kincal target`"}});
  }
  return out;
}

// The share of the session's observed corners on dim tags, weighed down
// (BundleCorner::weight < 1); 0 without corners.
double DimCornerShare(const std::vector<BundleFrame>& frames) {
  int dim = 0, all = 0;
  for (const BundleFrame& f : frames) {
    for (const BundleCorner& c : f.corners) {
      dim += c.weight < 1.0 ? 1 : 0;
      ++all;
    }
  }
  return all > 0 ? static_cast<double>(dim) / all : 0.0;
}

nlohmann::json SummaryJson(const BundleArgs& args, const Target& target,
                           const BundleRun& run, const Warnings& warnings) {
  const BundleResult& r = run.result;
  nlohmann::json params = nlohmann::json::array();
  for (const BundleParam& p : r.params) {
    params.push_back(
        {{"name", p.name},
         {"value", p.value},
         {"sigma", std::isfinite(p.sigma) ? nlohmann::json(p.sigma)
                                          : nlohmann::json(nullptr)}});
  }
  nlohmann::json j;
  j["frames"] = run.obs.session_frames;
  j["used_frames"] = r.used_frames;
  j["train_frames"] = r.train_frames;
  j["heldout_frames"] = r.heldout_frames;
  j["frames_without_joints"] = run.obs.without_joints;
  j["frames_without_tags"] = run.obs.without_tags;
  j["corners"] = r.corners;
  j["dropped_tags"] = r.dropped_tags;
  j["dropped_corners"] = r.dropped_corners;
  j["dim_corner_share"] = DimCornerShare(run.obs.frames);
  j["start_reproj_rms_px"] = r.start_reproj_rms_px;
  j["reproj_rms_px"] = r.reproj_rms_px;
  j["heldout_reproj_rms_px"] = r.heldout_reproj_rms_px;
  j["heldout_tip_rms_mm"] = r.heldout_tip_rms_mm;
  j["heldout_tips"] = r.heldout_tips;
  j["sigma0_px"] = r.sigma0_px;
  j["huber_px"] = r.huber_px;
  j["worst_frames"] = WorstFramesJson(r, target, run.obs.frames);
  j["identifiable"] = r.identifiable;
  j["unidentifiable"] = r.unidentifiable;
  j["params"] = params;
  j["cameras"] = r.rig.cameras.size();
  j["mount"] = RigMountName(r.rig.mount);
  j["not_determined"] = NotDeterminedJson(r.rig);
  if (!args.options.extensions.empty()) {
    const nlohmann::json extensions =
        ExtensionsJson(args.options, r, args.min_effect_mm);
    j["extensions"] = extensions;
    j["findings"] = FindingsJson(extensions);
  }
  if (r.mount == RigMount::kFlange) {
    j["flange_from_rig"] = PoseBlockJson(r.flange_from_rig);
    j["base_from_target"] = PoseBlockJson(r.base_from_target);
  } else {
    j["rig_from_base"] = PoseBlockJson(r.rig_from_base);
    j["flange_from_target"] = PoseBlockJson(r.flange_from_tool);
  }
  j["refine_cameras"] = args.options.refine_cameras;
  if (run.cross_validation) {
    const BundleCrossValidation& cv = *run.cross_validation;
    j["kfold"] = {{"folds", cv.folds},
                  {"heldout_reproj_rms_px", cv.heldout_reproj_rms_px},
                  {"heldout_tip_rms_mm", cv.heldout_tip_rms_mm},
                  {"heldout_tips", cv.heldout_tips}};
  }
  AddWarnings(warnings, &j);
  j["termination"] = r.termination;
  j["iterations"] = r.iterations;
  j["detect_seconds"] = run.obs.seconds;
  j["solve_seconds"] = r.seconds;
  j["seconds"] = run.seconds;
  j["out"] = args.out;
  if (!args.out_rig.empty()) j["out_rig"] = args.out_rig;
  if (!args.out_obs.empty()) {
    j["out_obs"] = args.out_obs;
    j["out_obs_points"] = run.out_obs_points;
  }
  return j;
}

void PrintSummary(const BundleArgs& args, const BundleRun& run) {
  const BundleResult& r = run.result;
  std::printf(
      "kincal bundle: %d frames, %d used (%d train, %d held out), %d "
      "corners\n",
      run.obs.session_frames, r.used_frames, r.train_frames, r.heldout_frames,
      r.corners);
  std::printf(
      "  reprojection RMS %.4f px (start %.3f px), held out %.4f px; "
      "held-out tip RMS %.4f mm (%d tips)\n",
      r.reproj_rms_px, r.start_reproj_rms_px, r.heldout_reproj_rms_px,
      r.heldout_tip_rms_mm, r.heldout_tips);
  std::printf("  %zu robot parameters fitted, %zu held at nominal\n",
              r.params.size(), r.unidentifiable.size());
  for (const BundleParam& p : r.params) {
    std::printf("    %-16s %12.5f +- %.5f\n", p.name.c_str(), p.value, p.sigma);
  }
  std::printf("  wrote %s (%.1f s: detection %.1f s, solve %.2f s)\n",
              args.out.c_str(), run.seconds, run.obs.seconds, r.seconds);
}

// Per camera of the rig, the target corners it sees in `obs`.
std::vector<int> CornersPerCamera(const Rig& rig,
                                  const SessionObservations& obs) {
  std::vector<int> corners(rig.cameras.size(), 0);
  for (const BundleFrame& f : obs.frames) {
    for (const auto& c : f.corners) {
      if (c.camera >= 0 && c.camera < static_cast<int>(corners.size())) {
        ++corners[c.camera];
      }
    }
  }
  return corners;
}

int RunBundleCommand(BundleArgs args) {
  const auto start = std::chrono::steady_clock::now();
  Progress progress("kincal bundle", args.json || args.quiet);
  progress.Stage("reading the session");
  const Robot robot = ReadRobot(args.robot);
  const Rig rig = ReadRigYaml(args.rig);
  const Target target = ReadTargetYaml(args.target);
  Warnings warnings = CommandWarnings();
  if (rig.mount == RigMount::kWorld && !target.has_tip) {
    warnings.Add("target_without_tip",
                 args.target + " has no tip_in_tool and " + args.rig +
                     " puts the cameras on a stand (mount: world): the "
                     "calibrated tool row ends at the target frame's origin. "
                     "Measure the tip (`kincal target --pivot`), or set "
                     "mount: flange if the cameras ride on the robot");
  }
  SessionReadOptions so;
  so.camera_names = rig.CameraNames();
  so.joint_names = robot.JointNames();
  so.require_joint_readings = true;
  const Session session = ReadSession(args.session, so);
  for (const std::string& name : ExpandExtensions(robot, args.extensions)) {
    args.options.extensions.push_back(name);
  }

  BundleRun run;
  ObserveOptions oo;
  oo.full_weight_contrast = args.full_weight_contrast;
  oo.bayer =
      ChooseBayerPattern(args.bayer, session.mosaics, args.session, &warnings);
  oo.progress = [&progress](int done, int total) {
    progress.Update(done, total, "frames (detecting tags)");
  };
  run.obs = ObserveSession(session, rig, target, oo);
  WarnDemosaiced(run.obs.looks_demosaiced, &warnings);
  WarnDoubtfulBayer(
      run.obs.bayer_doubtful,
      static_cast<int>(run.obs.frames.size() * rig.cameras.size()), oo.bayer,
      &warnings);
  // No camera with a tag at all: the start's own message (too few tracked
  // frames) says more than naming a camera.
  std::vector<std::string> folders;
  for (const std::string& f : session.folders) {
    folders.push_back(args.session + "/" + f);
  }
  RefuseBlindCameras(CornersPerCamera(rig, run.obs), rig.CameraNames(), folders,
                     args.rig,
                     "the " + std::to_string(run.obs.frames.size()) +
                         " frames with joint readings of " + args.session);
  progress.Stage("solving the bundle (" +
                 std::to_string(run.obs.frames.size()) + " frames)");
  run.result = RunBundle(robot, rig, target, run.obs.frames, args.options);
  if (args.folds >= 2) {
    run.cross_validation = CrossValidateBundle(
        robot, rig, target, run.obs.frames, args.options, args.folds,
        [&progress](int k, int folds) {
          progress.Update(k, folds, "cross-validation folds");
        });
  }

  // Outputs, all validated and computed before the first write.
  const BundleResult& r = run.result;
  const std::string robot_text = FormatRobotYaml(
      r.calibrated,
      {"calibrated by kincal bundle from the images of " + args.session,
       "reprojection RMS " + FormatDouble(r.reproj_rms_px) +
           " px (training), " + FormatDouble(r.heldout_reproj_rms_px) +
           " px (held out)"});
  const std::string obs_text =
      args.out_obs.empty() ? std::string()
                           : TrackedTipsCsv(args, robot, target, session,
                                            run.obs, r, &run.out_obs_points);
  progress.Done();
  WriteFileAtomic(args.out, robot_text);
  if (!args.out_rig.empty()) WriteRigYaml(args.out_rig, r.rig);
  if (!args.out_obs.empty()) WriteFileAtomic(args.out_obs, obs_text);
  run.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
          .count();
  if (args.json) {
    PrintJson(SummaryJson(args, target, run, warnings));
  } else {
    PrintSummary(args, run);
  }
  return 0;
}

}  // namespace

void AddBundleCommand(CLI::App& app, Runner* run) {
  auto args = std::make_shared<BundleArgs>();
  CLI::App* sub = app.add_subcommand("bundle", kBundleDescription);
  sub->add_option("--robot", args->robot, "robot.yaml (nominal)")->required();
  sub->add_option("--rig", args->rig,
                  "rig.yaml (1..N cameras; mount: world or flange)")
      ->required();
  sub->add_option("--target", args->target, "target.yaml")->required();
  sub->add_option("--session", args->session,
                  "recorded session folder (left/, right/, frames.csv with "
                  "joint columns, session.yaml)")
      ->required();
  sub->add_option("--out", args->out, "calibrated robot.yaml to write")
      ->required();
  sub->add_option("--out-rig", args->out_rig,
                  "write the (refined) rig.yaml here");
  sub->add_option("--out-obs", args->out_obs,
                  "write observations.csv: joint readings + the needle tips "
                  "the cameras saw (for diagnose, clearance, sensitivity)");
  sub->add_option("--holdout", args->options.holdout_fraction,
                  "fraction of frames held out of the fit")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 0.5));
  sub->add_option("--seed", args->options.seed, "seed of the hold-out")
      ->capture_default_str();
  sub->add_option("--folds", args->folds,
                  "also k-fold cross-validation: K more fits, each frame "
                  "held out once; JSON kfold (pooled held-out RMS)")
      ->check(CLI::Range(2, 20));
  sub->add_option("--huber", args->options.huber_px,
                  "per-corner Huber scale, px; 0 = automatic (3 sigma of "
                  "the corners after a first fit, at least 0.05 px; JSON "
                  "huber_px)")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  sub->add_option("--outlier-sigmas", args->options.outlier_sigmas,
                  "drop single corners farther than this many sigma of the "
                  "corners' noise after a first fit (at least 0.2 px); 0 = "
                  "keep every corner of a kept tag (JSON dropped_corners)")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  sub->add_option("--weight-contrast", args->full_weight_contrast,
                  "corners of tags whose weakest side's contrast is below "
                  "this many gray levels weigh contrast / this (at least "
                  "0.1): a dim tag's corners err more; 0 = every corner "
                  "alike")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  sub->add_flag("--refine-cameras", args->options.refine_cameras,
                "also refine intrinsics and the right camera's pose, with "
                "priors at rig.yaml (see --prior-*)");
  sub->add_option("--prior-focal", args->options.prior_focal_px,
                  "prior sigma of fx, fy (px)")
      ->capture_default_str();
  sub->add_option("--prior-principal", args->options.prior_principal_px,
                  "prior sigma of cx, cy (px)")
      ->capture_default_str();
  sub->add_option("--prior-distortion", args->options.prior_distortion,
                  "prior sigma of distortion coefficients")
      ->capture_default_str();
  sub->add_option("--prior-rotation", args->options.prior_rotation_deg,
                  "prior sigma of the right camera's rotation (deg)")
      ->capture_default_str();
  sub->add_option("--prior-translation", args->options.prior_translation_mm,
                  "prior sigma of the right camera's translation (mm)")
      ->capture_default_str();
  sub->add_option(
      "--extensions", args->extensions,
      "extension parameters to fit with pixel residuals, "
      "comma-separated (e.g. j3.backlash,j2.gain; a cause alone, "
      "e.g. backlash, gain, compliance, cyclic, axis_tilt, means every "
      "joint); significant ones "
      "(|value| > 4 sigma and moving the tool by --min-effect) are listed "
      "under findings");
  sub->add_option("--min-effect", args->min_effect_mm,
                  "a significant extension must also move the tool row's end "
                  "(tip, or rig origin on the flange) by at least this RMS "
                  "over the frames, mm")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  sub->add_option("--threads", args->options.num_threads, "Ceres threads")
      ->capture_default_str()
      ->check(CLI::Range(1, 64));
  sub->add_option("--min-tags", args->min_tags,
                  "--out-obs: a tip needs a pose from at least this many tags")
      ->capture_default_str();
  sub->add_option("--max-reproj", args->max_reproj_px,
                  "--out-obs: a tip needs a pose fit within this RMS, px")
      ->capture_default_str();
  AddBayerOption(sub, &args->bayer);
  sub->add_flag("--quiet", args->quiet, "no progress on stderr");
  sub->add_flag("--json", args->json, "print one JSON object");
  sub->footer(HelpFooter(
      "Example (a rendered session with a hidden backlash, then the bundle):\n "
      " kincal simulate --robot data/robots/bh7.yaml --out sim --poses 160 "
      "--noise 0 --render --effect backlash:j3:0.05\n  kincal bundle --robot "
      "sim/robot.yaml --rig sim/rig.yaml --target sim/target.yaml --session "
      "sim/session --out cal.yaml --out-obs tips.csv --extensions backlash "
      "--json"));
  sub->callback(
      [run, args] { *run = [args] { return RunBundleCommand(*args); }; });
}

}  // namespace kincal::app
