// kincal target: measure a tool target (../shared/spec/formats.md, version
// 3): the tag poses on the tool from a recorded session of the tool
// (vision/target_layout.h), and with --pivot the needle tip by pivot
// calibration from a second session (vision/pivot.h). Writes target.yaml
// with a sigma for every tag pose and the tip, and made_by.

#include <chrono>
#include <cstdio>
#include <memory>

#include "app/app_util.h"
#include "app/command.h"
#include "app/front_end.h"
#include "camcal/rig.h"
#include "data/error.h"
#include "data/progress.h"
#include "data/provenance.h"
#include "data/session.h"
#include "data/warnings.h"
#include "vision/pivot.h"
#include "vision/target.h"
#include "vision/target_layout.h"
#include "vision/tool_pose.h"

namespace kincal::app {
namespace {

struct TargetArgs {
  std::string rig, session, family = "tag36h11", pivot, out;
  double size_mm = 0;
  // The pivot session must tilt the tool at least this much in its second
  // direction (vision/pivot.h, PivotResult::tilt_range_deg).
  double min_tilt_deg = 15.0;
  int min_views = 10;
  bool json = false;
  bool quiet = false;
  // Raw mosaic pattern of the images; empty: session.yaml's, else none.
  std::string bayer;
};

std::vector<LayoutFrame> Detect(const std::string& dir, const Rig& rig,
                                const TargetArgs& args, Progress* progress,
                                Warnings* warnings) {
  SessionReadOptions so;
  so.camera_names = rig.CameraNames();
  const Session session = ReadSession(dir, so);
  if (session.frames.empty()) {
    throw InputError(dir + ": the session has no complete frame");
  }
  AprilTagOptions detector;
  detector.family = args.family;
  const BayerPattern bayer =
      ChooseBayerPattern(args.bayer, session.mosaics, dir, warnings);
  return DetectSessionTags(session, rig, detector, bayer,
                           [&](int done, int total) {
                             progress->Update(done, total, "frames of " + dir);
                           });
}

// The tip by pivot calibration with the measured layout; a refusal names
// the pivot session.
PivotTipResult MeasureTip(const std::vector<LayoutFrame>& frames,
                          const Rig& rig, const TargetLayoutResult& layout,
                          const TargetArgs& args) {
  PivotTipOptions options;
  options.min_views = args.min_views;
  options.min_tilt_deg = args.min_tilt_deg;
  try {
    return MeasurePivotTip(rig, layout, frames, options);
  } catch (const InputError& e) {
    throw InputError(args.pivot + ": " + e.what());
  }
}

// Views with two or more tags that a layout should rest on; fewer (or
// fewer than half the frames) are warned about: the bundle still runs, but
// its sigmas rest on few views and one-tag frames carry no layout.
constexpr int kWellDeterminedViews = 30;

void WarnAboutLayoutViews(const TargetLayoutResult& layout,
                          Warnings* warnings) {
  if (layout.multi_tag_views >= kWellDeterminedViews &&
      2 * layout.multi_tag_views >= layout.frames) {
    return;
  }
  warnings->Add(
      "few_layout_views",
      "only " + std::to_string(layout.multi_tag_views) + " of " +
          std::to_string(layout.frames) +
          " frames show two or more tags together; the layout rests on "
          "those alone (frames with one tag say nothing about where the tags "
          "sit on the tool), so it may be off by more than its sigma: record "
          "a session of the tool turned so that pairs of neighbouring tags "
          "are seen together, at least " +
          std::to_string(kWellDeterminedViews) +
          " such views (e.g. the tool alone, hand-held and tilted +-25 deg)");
}

nlohmann::json Vec3(const Eigen::Vector3d& v) {
  return {Number(v.x()), Number(v.y()), Number(v.z())};
}

void Print(const TargetArgs& args, const TargetLayoutResult& layout,
           const Target& target, const PivotTipResult* pivot,
           const Warnings& warnings, double seconds) {
  if (args.json) {
    nlohmann::json j;
    j["out"] = args.out;
    j["views_used"] = layout.views_used;
    j["frames"] = layout.frames;
    j["reference_tag"] = layout.reference_tag_id;
    j["reproj_rms_px"] = Number(layout.rms_px);
    j["corners_used"] = layout.corners_used;
    j["corners_rejected"] = layout.corners_rejected;
    j["tags"] = nlohmann::json::array();
    for (const LayoutTag& t : layout.tags) {
      j["tags"].push_back({{"id", t.id},
                           {"views", t.views},
                           {"sigma_t_mm", Vec3(t.sigma_t_mm)},
                           {"sigma_r_deg", Vec3(t.sigma_r_deg)}});
    }
    j["corner_offset_sigma_mm"] = Number(layout.corner_offset_sigma_mm);
    j["tip_in_tool"] = nullptr;
    j["tip_sigma_mm"] = nullptr;
    if (pivot) {
      j["tip_in_tool"] = Vec3(target.tip_in_tool);
      j["tip_sigma_mm"] = Vec3(target.tip_sigma_mm);
      j["pivot_rms_mm"] = Number(pivot->pivot.rms_mm);
      j["pivot_views"] = pivot->views;
      j["pivot_tilt_deg"] = Number(pivot->pivot.tilt_range_deg);
      j["pivot_in_rig"] = Vec3(pivot->pivot.pivot_in_rig);
      j["tip_layout_sigma_mm"] = Vec3(pivot->layout_sigma_mm);
      j["tip_shared_sigma_mm"] = Vec3(pivot->systematic_sigma_mm);
      j["corner_offset_sigma_mm"] = Number(pivot->corner_offset_sigma_mm);
      j["pivot_frames_rejected"] = pivot->frames_rejected;
    }
    j["seconds"] = seconds;
    AddWarnings(warnings, &j);
    PrintJson(j);
    return;
  }
  std::printf(
      "kincal target: %zu tags from %d views (tool frame = tag %d), "
      "reprojection RMS %.3f px (%.1f s)\n",
      layout.tags.size(), layout.views_used, layout.reference_tag_id,
      layout.rms_px, seconds);
  for (const LayoutTag& t : layout.tags) {
    std::printf("  tag %d: sigma %.4f mm, %.4f deg (largest axis)\n", t.id,
                t.sigma_t_mm.maxCoeff(), t.sigma_r_deg.maxCoeff());
  }
  if (pivot) {
    std::printf(
        "  tip (%.3f, %.3f, %.3f) mm, sigma up to %.3f mm, pivot RMS %.3f mm "
        "over %d views (%zu off the pivot left out)\n",
        target.tip_in_tool.x(), target.tip_in_tool.y(), target.tip_in_tool.z(),
        target.tip_sigma_mm.maxCoeff(), pivot->pivot.rms_mm, pivot->views,
        pivot->frames_rejected.size());
  }
  std::printf("  wrote %s\n", args.out.c_str());
}

int RunTarget(const TargetArgs& args) {
  const auto start = std::chrono::steady_clock::now();
  const Rig rig = ReadRigYaml(args.rig);
  TargetLayoutOptions options;
  options.family = args.family;
  options.tag_size_mm = args.size_mm;
  options.min_views = args.min_views;
  options.Check();
  Progress progress("kincal target", args.quiet || args.json);
  Warnings warnings = CommandWarnings();
  const std::vector<LayoutFrame> frames =
      Detect(args.session, rig, args, &progress, &warnings);
  std::vector<LayoutFrame> pivot_frames;
  if (!args.pivot.empty()) {
    pivot_frames = Detect(args.pivot, rig, args, &progress, &warnings);
  }
  progress.Stage("bundle over every tag corner");
  const TargetLayoutResult layout = MeasureTargetLayout(rig, frames, options);
  Target target = layout.target;
  target.made_by = CommandLine();
  std::unique_ptr<PivotTipResult> pivot;
  if (!args.pivot.empty()) {
    progress.Stage("pivot calibration");
    pivot = std::make_unique<PivotTipResult>(
        MeasureTip(pivot_frames, rig, layout, args));
    target.has_tip = true;
    target.tip_in_tool = pivot->pivot.tip_in_tool;
    target.has_tip_sigma = true;
    target.tip_sigma_mm = pivot->tip_sigma_mm;
  }
  progress.Done();
  WarnAboutLayoutViews(layout, &warnings);
  WriteTargetYaml(args.out, target);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
          .count();
  Print(args, layout, target, pivot.get(), warnings, seconds);
  return 0;
}

}  // namespace

void AddTargetCommand(CLI::App& app, Runner* run) {
  auto args = std::make_shared<TargetArgs>();
  CLI::App* sub = app.add_subcommand("target", kTargetDescription);
  sub->add_option("--rig", args->rig, "rig.yaml (2 cameras)")->required();
  sub->add_option("--session", args->session,
                  "recorded session of the tool (10+ views, neighbouring tags "
                  "seen together)")
      ->required();
  sub->add_option("--family", args->family, "tag family")
      ->capture_default_str();
  sub->add_option("--size", args->size_mm, "edge of the tags' black square, mm")
      ->required();
  sub->add_option("--pivot", args->pivot,
                  "second session: the tip resting in a divot while the tool "
                  "tilts (at least +-15 deg in two directions)");
  sub->add_option("--out", args->out, "target.yaml to write")->required();
  sub->add_option("--min-views", args->min_views,
                  "views needed (with two or more tags; pivot: with the tool)")
      ->capture_default_str()
      ->check(CLI::Range(3, 100000));
  sub->add_option("--min-tilt", args->min_tilt_deg,
                  "pivot: tilt range needed in the second direction, deg")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 90.0));
  sub->add_flag("--quiet", args->quiet, "no progress bar on stderr");
  AddBayerOption(sub, &args->bayer);
  sub->add_flag("--json", args->json, "print one JSON object");
  sub->footer(HelpFooter(
      "Example:\n  kincal target --rig rig.yaml --session tool_session "
      "--family tag36h11 --size 25 --pivot pivot_session --out target.yaml\n"
      "The tool frame is the frame of the tag seen most (JSON "
      "reference_tag)."));
  sub->callback([run, args] { *run = [args] { return RunTarget(*args); }; });
}

}  // namespace kincal::app
