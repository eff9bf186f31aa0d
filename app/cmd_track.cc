// kincal track: the needle tip in the rig frame for every frame of 1..N
// cameras, from the AprilTags of the tool target (../shared/spec/formats.md).

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <sstream>

#include "app/app_util.h"
#include "app/command.h"
#include "app/front_end.h"
#include "camcal/rig.h"
#include "data/atomic_file.h"
#include "data/csv.h"
#include "data/error.h"
#include "data/glob.h"
#include "data/observations.h"
#include "data/progress.h"
#include "data/provenance.h"
#include "data/session.h"
#include "data/urdf.h"
#include "data/yaml_util.h"
#include "vision/camera_order.h"
#include "vision/pose_uncertainty.h"
#include "vision/stereo_images.h"
#include "vision/target.h"
#include "vision/tool_pose.h"
#include "vision/tracker.h"

namespace kincal::app {
namespace {

struct TrackArgs {
  std::string rig, target, left, right, out;
  std::vector<std::string> cameras;  // --camera NAME=GLOB
  // A recorded session folder instead of --left/--right (data/session.h).
  std::string session;
  // Optional: joint readings of the same frames (one row per frame pair, in
  // order) to merge with the tracked tips into observations for calibrate.
  std::string obs, robot, out_obs;
  // Quality gate for the merge: a tip is merged only when the tool pose used
  // at least min_tags tags and fits them within max_reproj_px (one small tag
  // leaves the rotation, and so the tip at the end of its lever, ambiguous).
  // With two or more cameras the tags must also be seen by two of them.
  int min_tags = 2;
  double max_reproj_px = 0.5;
  bool json = false;
  bool no_tracking = false;
  double decimate = 2.0;
  bool quiet = false;
  // Raw mosaic pattern of the images; empty: session.yaml's, else none
  // (ChooseBayerPattern).
  std::string bayer;
};

std::string PosesPath(const std::string& out) {
  const std::string ext = ".csv";
  if (out.size() > ext.size() &&
      out.compare(out.size() - ext.size(), ext.size(), ext) == 0) {
    return out.substr(0, out.size() - ext.size()) + ".poses.csv";
  }
  return out + ".poses.csv";
}

// The frames to track, from a session folder or one glob per camera.
struct FrameSets {
  std::vector<std::string> option;               // per camera, for messages
  std::vector<std::vector<std::string>> images;  // [camera][frame]
  Session session;                               // when --session
  size_t size() const { return images.empty() ? 0 : images[0].size(); }
};

FrameSets ListFrameSets(const TrackArgs& args, const Rig& rig) {
  FrameSets sets;
  const std::vector<CameraGlob> globs =
      CameraGlobs(args.cameras, args.left, args.right);
  if (!args.session.empty()) {
    if (!globs.empty()) {
      throw InputError(
          "--session replaces --camera and --left/--right; give one or the "
          "other");
    }
    SessionReadOptions so;
    so.camera_names = rig.CameraNames();
    if (!args.robot.empty() && args.obs.empty()) {
      so.joint_names = ReadRobot(args.robot).JointNames();
      so.require_joint_readings = !args.out_obs.empty();
    }
    sets.session = ReadSession(args.session, so);
    sets.images.resize(rig.cameras.size());
    for (size_t c = 0; c < rig.cameras.size(); ++c) {
      sets.option.push_back(args.session + "/" + sets.session.folders[c]);
    }
    for (const SessionFrame& f : sets.session.frames) {
      for (size_t c = 0; c < f.images.size(); ++c) {
        sets.images[c].push_back(f.images[c]);
      }
    }
    if (sets.size() == 0) {
      throw InputError(args.session + ": the session has no complete frame");
    }
    return sets;
  }
  if (globs.empty()) {
    throw InputError(
        "give --camera NAME='GLOB' for every camera of the rig (or --left and "
        "--right for a stereo rig), or --session");
  }
  for (const CameraGlob& g : InRigOrder(globs, rig.CameraNames(), args.rig)) {
    sets.option.push_back(g.option);
    sets.images.push_back(GlobSortedOrThrow(g.glob, g.option));
  }
  for (size_t c = 1; c < sets.images.size(); ++c) {
    if (sets.images[c].size() != sets.images[0].size()) {
      throw InputError(
          sets.option[0] + " matches " + std::to_string(sets.images[0].size()) +
          " images but " + sets.option[c] + " matches " +
          std::to_string(sets.images[c].size()) + "; frames pair in order");
    }
  }
  return sets;
}

// The joint readings the tracked tips are merged into (--out-obs).
struct Merge {
  Observations merged;
  // merged row of each frame pair, -1 = none (session frames without joint
  // readings).
  std::vector<int> merged_row;
};

// Validates the merge inputs before any work, so bad input writes nothing.
Merge PrepareMerge(const TrackArgs& args, const FrameSets& pairs) {
  Merge merge;
  Observations& merged = merge.merged;
  merge.merged_row.assign(pairs.size(), -1);
  if (!args.session.empty() && args.obs.empty() &&
      (!args.robot.empty() || !args.out_obs.empty())) {
    if (args.robot.empty() || args.out_obs.empty()) {
      throw InputError(
          "--robot and --out-obs go together (with --session: merge tracked "
          "tips into the session's joint readings)");
    }
    merged.source = pairs.session.frames_csv;
    merged.joint_names = ReadRobot(args.robot).JointNames();
    for (size_t f = 0; f < pairs.session.frames.size(); ++f) {
      const SessionFrame& sf = pairs.session.frames[f];
      if (!sf.HasJoints()) continue;
      Observation o;
      o.pose = std::to_string(sf.frame);
      o.q = sf.q;
      o.t_s = sf.t[0];
      o.line = sf.line;
      merge.merged_row[f] = static_cast<int>(merged.rows.size());
      merged.rows.push_back(o);
    }
  } else if (!args.obs.empty() || !args.out_obs.empty()) {
    if (args.obs.empty() || args.robot.empty() || args.out_obs.empty()) {
      throw InputError(
          "--obs, --robot and --out-obs go together (merge tracked tips "
          "into the joint readings of the same frames)");
    }
    merged = ReadObservationsCsv(args.obs, ReadRobot(args.robot).JointNames());
    if (merged.rows.size() != pairs.size()) {
      throw InputError(args.obs + ": " + std::to_string(merged.rows.size()) +
                       " observation rows but " + std::to_string(pairs.size()) +
                       " frames; rows must match frames in order");
    }
    for (size_t f = 0; f < pairs.size(); ++f) {
      merge.merged_row[f] = static_cast<int>(f);
    }
  }
  return merge;
}

// What tracking every frame produced: the two CSV texts and the counts.
struct Tracked {
  std::string points, poses;
  int found = 0, merged_count = 0;
  std::vector<int> failed_gate;  // found, but not good
  std::vector<double> rms_values;
  std::vector<double> depths_mm;  // distance of the tool from the rig, found
  // 1-sigma of the tip along the reference camera's line of sight, found
  // frames (vision/pose_uncertainty.h).
  std::vector<double> depth_sigmas_mm;
  int frames_tags_in_all = 0;      // frames with a target tag in every camera
  std::vector<int> tag_frames;     // per camera: frames with a target tag
  std::vector<int> full_searches;  // per camera
  std::map<std::string, int> left_out;  // tag observations left out, by why
  int bayer_doubtful = 0;  // images whose Bayer balance is doubtful
  int looks_raw = 0;       // cameras whose first image looks like a mosaic
};

std::string PosesHeader(const std::string& header,
                        const std::string& image_columns) {
  return header + "# rig_from_tool: R row-major, t in mm; tip in rig, mm\n" +
         "# good = 1: the tip passes the quality gate (>= --min-tags tag "
         "observations, reprojection RMS <= --max-reproj px, and with two "
         "or more cameras tags seen by two); a found tip with good = 0 is "
         "the tracker's best guess, not a measurement. depth_sigma_mm: "
         "1-sigma of the tip along the first camera's line of sight\n" +
         "# tags_used: tag@camera of the fit; tags_left_out: "
         "tag@camera:reason (contrast, corners or residual)\n" +
         "frame,found,r00,r01,r02,r10,r11,r12,r20,r21,r22,tx,ty,tz,"
         "reproj_px,tags,depth_sigma_mm,good," +
         image_columns + ",tags_used,tags_left_out\n";
}

// The tag observations of a pose, used or left out with the reason, as
// space-separated tag@camera[:reason] (CSV-safe).
std::string TagList(const Rig& rig, const ToolPoseResult& r, bool used) {
  std::string out;
  for (const TagObservationResult& t : r.tags) {
    if (t.used != used) continue;
    if (!out.empty()) out += " ";
    out +=
        std::to_string(t.tag_id) + "@" + rig.cameras[t.camera].intrinsics.name;
    if (!used) out += ":" + t.left_out;
  }
  return out;
}

// The quality gate with the command's --min-tags and --max-reproj
// (vision/tool_pose.h PassesTrackGate).
bool PassesGate(const TrackArgs& args, size_t num_cameras,
                const ToolPoseResult& r) {
  return PassesTrackGate(r, num_cameras, args.min_tags, args.max_reproj_px);
}

bool SeesTargetTag(const Target& target,
                   const std::vector<TagDetection>& dets) {
  for (const TagDetection& d : dets) {
    for (const TargetTag& t : target.tags) {
      if (t.id == d.id) return true;
    }
  }
  return false;
}

// Per-camera image columns of poses.csv: image_<camera name>.
std::string ImageColumns(const Rig& rig) {
  std::string h;
  for (const std::string& n : rig.CameraNames()) {
    h += (h.empty() ? "" : ",") + CsvQuote("image_" + n);
  }
  return h;
}

// One pose row's values after `frame,found` (empty cells when not found).
void AppendPoseCells(const ToolPoseResult& r, const TipUncertainty& u,
                     std::ostringstream* poses) {
  if (!r.found) {
    *poses << ",,,,,,,,,,,,,,0,";
    return;
  }
  for (int i = 0; i < 9; ++i) {
    *poses << "," << FormatDouble(r.rig_from_tool.R(i / 3, i % 3));
  }
  for (int i = 0; i < 3; ++i) {
    *poses << "," << FormatDouble(r.rig_from_tool.t(i));
  }
  *poses << "," << FormatDouble(r.rms_px) << "," << r.tags_used << ",";
  if (u.ok) *poses << FormatDouble(u.depth_sigma_mm);
}

// The point a frame measures: the needle tip in the rig frame, or with the
// cameras on the flange (rig.yaml mount: flange) the rig origin (the
// reference camera's optical centre) in the fixed target's frame, the point
// the calibrated robot's tool row ends at (spec v3).
Eigen::Vector3d TrackedPoint(const Rig& rig, const ToolPoseResult& r) {
  return rig.mount == RigMount::kFlange ? r.rig_from_tool.Inverse().t
                                        : r.tip_in_rig;
}

// The header comment saying what x,y,z are.
std::string PointsMeaning(const Rig& rig) {
  return rig.mount == RigMount::kFlange
             ? "x,y,z = rig origin (reference camera's optical centre) in the "
               "fixed target's frame, mm (rig.yaml mount: flange)"
             : "x,y,z = needle tip tracked in the rig frame, mm";
}

Tracked TrackFrames(const TrackArgs& args, const Rig& rig, const Target& target,
                    const FrameSets& pairs, Merge* merge) {
  TrackerOptions topt;
  topt.detector.family = target.family;
  topt.detector.quad_decimate = args.decimate;
  topt.enabled = !args.no_tracking;
  topt.Check();
  const int nc = static_cast<int>(rig.cameras.size());
  const BayerPattern bayer = ParseBayerPattern(args.bayer);
  std::vector<std::unique_ptr<TagTracker>> trackers;
  for (int c = 0; c < nc; ++c) {
    TrackerOptions camera_options = topt;
    camera_options.detector.lens = rig.cameras[c].intrinsics;
    trackers.push_back(std::make_unique<TagTracker>(camera_options));
  }

  const size_t n = pairs.size();
  Tracked out;
  out.tag_frames.assign(nc, 0);
  std::ostringstream points, poses;
  const std::string header =
      "# written by " + ToolVersion() + ": " + CommandLine() + "\n";
  points << header << "# " << PointsMeaning(rig) << "\n"
         << "frame,x,y,z,reproj_px,tags\n";
  poses << PosesHeader(header, ImageColumns(rig));
  // On a terminal only; silent with --json, --quiet or when piped.
  Progress progress("kincal track", args.json || args.quiet);
  for (size_t f = 0; f < n; ++f) {
    std::vector<std::vector<TagDetection>> dets(nc);
    std::vector<BayerBalance> balance(nc);
    std::vector<int> looks_raw(nc, 0);
    ForEachCamera(nc, [&](int c) {
      const cv::Mat image = ReadCameraImage(
          pairs.images[c][f], rig.cameras[c].intrinsics, bayer, &balance[c]);
      if (f == 0 && bayer == BayerPattern::kNone) {
        looks_raw[c] = LooksLikeRawMosaic(image);
      }
      dets[c] = trackers[c]->Track(image);
    });
    for (int raw : looks_raw) out.looks_raw += raw;
    for (const BayerBalance& b : balance) out.bayer_doubtful += b.doubtful;
    const ToolPoseResult r = EstimateToolPose(rig, target, dets);
    int cameras_with_tags = 0;
    for (int c = 0; c < nc; ++c) {
      const bool seen = SeesTargetTag(target, dets[c]);
      out.tag_frames[c] += seen ? 1 : 0;
      cameras_with_tags += seen ? 1 : 0;
    }
    if (cameras_with_tags == nc) ++out.frames_tags_in_all;
    points << f;
    poses << f << "," << (r.found ? 1 : 0);
    const bool good = PassesGate(args, rig.cameras.size(), r);
    if (merge->merged_row[f] >= 0) {
      Observation& row = merge->merged.rows[merge->merged_row[f]];
      row.has_point = good;
      if (good) row.p_in_meas = TrackedPoint(rig, r);
      out.merged_count += good ? 1 : 0;
    }
    // The corner sigma per coordinate: the fit's RMS (a norm over x and y)
    // over sqrt(2), at least 0.05 px (a perfect fit still has noise).
    const TipUncertainty u = TipUncertaintyOf(
        rig, target, r, std::max(0.05, r.rms_px / std::sqrt(2.0)));
    if (r.found) {
      ++out.found;
      out.rms_values.push_back(r.rms_px);
      out.depths_mm.push_back(r.rig_from_tool.t.norm());
      if (u.ok) out.depth_sigmas_mm.push_back(u.depth_sigma_mm);
      const Eigen::Vector3d point = TrackedPoint(rig, r);
      for (int i = 0; i < 3; ++i) points << "," << FormatDouble(point(i));
      if (!good) out.failed_gate.push_back(static_cast<int>(f));
      points << "," << FormatDouble(r.rms_px) << "," << r.tags_used << "\n";
    } else {
      points << ",,,,,0\n";
    }
    AppendPoseCells(r, u, &poses);
    poses << "," << (good ? 1 : 0);
    for (int c = 0; c < nc; ++c) poses << "," << CsvQuote(pairs.images[c][f]);
    poses << "," << CsvQuote(TagList(rig, r, true)) << ","
          << CsvQuote(TagList(rig, r, false)) << "\n";
    for (const TagObservationResult& t : r.tags) {
      if (!t.used) ++out.left_out[t.left_out];
    }
    progress.Update(static_cast<long>(f + 1), static_cast<long>(n),
                    "frames (" + std::to_string(out.found) + " with a tip)");
  }
  out.points = points.str();
  out.poses = poses.str();
  for (int c = 0; c < nc; ++c) {
    out.full_searches.push_back(trackers[c]->full_searches());
  }
  return out;
}

void WriteMergedObservations(const TrackArgs& args, const Rig& rig,
                             const Observations& merged) {
  WriteFileAtomic(
      args.out_obs,
      FormatObservationsCsv(
          merged,
          {"joint readings from " + merged.source + "; " + PointsMeaning(rig) +
           " (empty where the tool was not found, "
           "seen by one camera of a multi-camera rig, "
           "or with fewer than " +
           std::to_string(args.min_tags) + " tags or a reprojection RMS over " +
           FormatDouble(args.max_reproj_px) + " px)"}));
}

double MedianOf(std::vector<double> values) {
  if (values.empty()) return 0;
  std::nth_element(values.begin(), values.begin() + values.size() / 2,
                   values.end());
  return values[values.size() / 2];
}

std::string JoinInts(const std::vector<int>& v) {
  std::string s;
  for (int x : v) s += (s.empty() ? "" : "/") + std::to_string(x);
  return s;
}

void PrintTrack(const TrackArgs& args, size_t n, const Tracked& t, bool merged,
                const std::string& poses_path, double seconds,
                const Warnings& warnings) {
  const double median_rms = MedianOf(t.rms_values);
  const double depth_sigma = MedianOf(t.depth_sigmas_mm);
  if (args.json) {
    nlohmann::json j;
    j["frames"] = n;
    j["found"] = t.found;
    j["good"] = t.found - static_cast<int>(t.failed_gate.size());
    j["failed_gate"] = t.failed_gate;
    j["tags_left_out"] = t.left_out;
    j["seconds"] = seconds;
    j["out"] = args.out;
    j["poses"] = poses_path;
    j["median_reproj_px"] = median_rms;
    j["cameras"] = t.tag_frames.size();
    j["median_depth_sigma_mm"] =
        Number(t.depth_sigmas_mm.empty() ? NAN : depth_sigma);
    j["full_searches"] = t.full_searches;
    if (merged) {
      j["out_obs"] = args.out_obs;
      j["merged"] = t.merged_count;
    }
    AddWarnings(warnings, &j);
    PrintJson(j);
    return;
  }
  std::printf(
      "kincal track: %zu frames of %zu camera(s), tip found in %d "
      "(%.1f s)\n",
      n, t.tag_frames.size(), t.found, seconds);
  std::printf("  median reprojection RMS %.3f px; full-frame searches %s\n",
              median_rms, JoinInts(t.full_searches).c_str());
  if (!t.depth_sigmas_mm.empty()) {
    std::printf(
        "  median depth sigma %.3f mm (along the first camera's line "
        "of sight)\n",
        depth_sigma);
  }
  if (!t.left_out.empty()) {
    std::printf(
        "  tag observations left out of their frame's fit (the frame kept "
        "its other tags; tags_left_out in %s):",
        poses_path.c_str());
    for (const auto& [why, count] : t.left_out) {
      std::printf(" %s %d", why.c_str(), count);
    }
    std::printf("\n");
  }
  if (!t.failed_gate.empty()) {
    std::printf(
        "  %zu found tips fail the quality gate (< %d tags, > %.2f px or "
        "one camera of several; "
        "good = 0 in %s): frames",
        t.failed_gate.size(), args.min_tags, args.max_reproj_px,
        poses_path.c_str());
    for (size_t k = 0; k < t.failed_gate.size() && k < 20; ++k) {
      std::printf(" %d", t.failed_gate[k]);
    }
    std::printf(t.failed_gate.size() > 20 ? " ...\n" : "\n");
  }
  std::printf("  wrote %s and %s\n", args.out.c_str(), poses_path.c_str());
}

// When fewer than half the frames give a tip that passes the gate, a
// sample of pairs is tried with the two images exchanged
// (vision/camera_order.h); if that explains the data, the images were given
// in the wrong order: bad input, nothing written.
void RefuseSwappedCameras(const TrackArgs& args, const Rig& rig,
                          const Target& target, const FrameSets& pairs,
                          const Tracked& tracked) {
  const int good = tracked.found - static_cast<int>(tracked.failed_gate.size());
  if (pairs.images.size() != 2 || pairs.size() == 0 ||
      2 * good >= static_cast<int>(pairs.size())) {
    return;
  }
  AprilTagOptions detector;
  detector.family = target.family;
  detector.quad_decimate = args.decimate;
  const CameraOrderCheck check = CheckCameraOrder(
      rig, target, pairs.images[0], pairs.images[1],
      [&](const ToolPoseResult& r) { return PassesGate(args, 2, r); }, detector,
      6, ParseBayerPattern(args.bayer));
  if (!check.LooksSwapped()) return;
  throw InputError(
      "the images of " + pairs.option[0] + " and " + pairs.option[1] +
      " look swapped: of " + std::to_string(check.sampled) +
      " sampled frame pairs, " + std::to_string(check.pass_as_given) +
      " give a tool pose passing the quality gate as given and " +
      std::to_string(check.pass_swapped) +
      " with the two images exchanged. --left takes the images of the rig's "
      "first camera (" +
      args.rig +
      "): exchange --left and --right (or the --camera globs), or "
      "check which camera recorded which folder");
}

// A tool found closer to the cameras than any lens focuses (the median over
// the frames below 20 mm) means the rig and target.yaml disagree on units:
// typically a rig from camcal with the board given in metres (a baseline in
// metres read as mm). Bad input, nothing written.
void RefuseImpossibleDepth(const TrackArgs& args, const Rig& rig,
                           const Tracked& tracked) {
  constexpr double kMinDepthMm = 20.0;
  const std::string units =
      " disagree on units. camcal's --target lengths and target.yaml's are "
      "millimetres: a board given in metres gives a rig 1000 times too small "
      "(recalibrate with the board in mm)";
  const double baseline =
      rig.cameras.size() > 1 ? rig.cameras[1].cam_from_rig.t.norm() : 0.0;
  const std::string pair = args.rig + " (baseline " + FormatDouble(baseline) +
                           " mm) and " + args.target;
  // Tags in every camera, yet no tool pose fits any frame.
  if (tracked.found == 0 && rig.cameras.size() > 1 &&
      tracked.frames_tags_in_all >= 3) {
    throw InputError("tags of the target are seen by every camera in " +
                     std::to_string(tracked.frames_tags_in_all) +
                     " frames, but no tool pose fits them in any: " + pair +
                     " do not describe the same set-up; most likely they" +
                     units);
  }
  if (tracked.depths_mm.empty()) return;
  const double depth = MedianOf(tracked.depths_mm);
  if (depth >= kMinDepthMm) return;
  throw InputError("the tool would be " + FormatDouble(depth) +
                   " mm from the cameras (median over " +
                   std::to_string(tracked.depths_mm.size()) +
                   " frames), closer than any lens focuses: " + pair + units);
}

int RunTrack(const TrackArgs& given) {
  const auto start = std::chrono::steady_clock::now();
  const Rig rig = ReadRigYaml(given.rig);
  const Target target = ReadTargetYaml(given.target);
  const FrameSets pairs = ListFrameSets(given, rig);
  Warnings warnings = CommandWarnings();
  TrackArgs args = given;
  args.bayer = BayerPatternName(ChooseBayerPattern(
      given.bayer, pairs.session.mosaics, given.session, &warnings));
  Merge merge = PrepareMerge(args, pairs);
  const Tracked tracked = TrackFrames(args, rig, target, pairs, &merge);
  // Images without any tag in every camera are read as they are (the tool
  // was not there: found = 0).
  RefuseBlindCameras(tracked.tag_frames, rig.CameraNames(), pairs.option,
                     args.rig,
                     "the " + std::to_string(pairs.size()) + " frames");
  RefuseSwappedCameras(args, rig, target, pairs, tracked);
  RefuseImpossibleDepth(args, rig, tracked);
  WriteFileAtomic(args.out, tracked.points);
  const std::string poses_path = PosesPath(args.out);
  WriteFileAtomic(poses_path, tracked.poses);
  const bool merged = !merge.merged.rows.empty();
  WarnDoubtfulBayer(tracked.bayer_doubtful,
                    static_cast<int>(pairs.size() * rig.cameras.size()),
                    ParseBayerPattern(args.bayer), &warnings);
  WarnRawMosaic(tracked.looks_raw, &warnings);
  if (merged) {
    WriteMergedObservations(args, rig, merge.merged);
    WarnPoseCoverage(ReadRobot(args.robot), merge.merged, &warnings);
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
          .count();
  PrintTrack(args, pairs.size(), tracked, merged, poses_path, seconds,
             warnings);
  return 0;
}

}  // namespace

void AddTrackCommand(CLI::App& app, Runner* run) {
  auto args = std::make_shared<TrackArgs>();
  CLI::App* sub = app.add_subcommand("track", kTrackDescription);
  sub->add_option("--rig", args->rig, "rig.yaml (1..N cameras)")->required();
  sub->add_option("--target", args->target, "target.yaml")->required();
  AddCameraOption(sub, &args->cameras,
                  "NAME='GLOB': the images of the rig's camera NAME (repeat "
                  "for every camera; frames pair in sorted order)");
  sub->add_option("--left", args->left,
                  "images of the rig's first camera, a glob (quote it); the "
                  "two-camera spelling of --camera");
  sub->add_option("--right", args->right,
                  "images of the rig's second camera, a glob (quote it)");
  sub->add_option("--session", args->session,
                  "a recorded session folder (one image folder per camera, "
                  "frames.csv, session.yaml) instead of --camera; with "
                  "--robot and --out-obs its joint columns are merged with "
                  "the tips");
  sub->add_option("--out", args->out, "points.csv to write")->required();
  sub->add_option("--decimate", args->decimate,
                  "libapriltag quad_decimate (default 2)")
      ->check(CLI::Range(1.0, 8.0));
  sub->add_flag("--no-tracking", args->no_tracking,
                "search every full frame (no region prediction)");
  sub->add_flag("--quiet", args->quiet, "no progress bar on stderr");
  AddBayerOption(sub, &args->bayer);
  sub->add_option("--obs", args->obs,
                  "observations.csv with the joint readings of the same "
                  "frames (one row per pair, in order)");
  sub->add_option("--robot", args->robot,
                  "robot.yaml naming the joints of --obs");
  sub->add_option("--out-obs", args->out_obs,
                  "write --obs with x,y,z replaced by the tracked tips");
  sub->add_option("--min-tags", args->min_tags,
                  "merge a tip only if its pose used at least this many tags")
      ->capture_default_str();
  sub->add_option("--max-reproj", args->max_reproj_px,
                  "merge a tip only if its pose fits within this RMS, px")
      ->capture_default_str();
  sub->add_flag("--json", args->json, "print one JSON object");
  sub->footer(
      HelpFooter("Example:\n  kincal track --rig rig.yaml --target target.yaml "
                 "--left 'session/left/*.png' --right 'session/right/*.png' "
                 "--out session/points.csv\n  kincal report --rig rig.yaml "
                 "--session session --out tracking.html"));
  sub->callback([run, args] { *run = [args] { return RunTrack(*args); }; });
}

}  // namespace kincal::app
