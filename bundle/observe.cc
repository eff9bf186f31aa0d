#include "bundle/observe.h"

#include <algorithm>
#include <chrono>
#include <memory>

#include "data/error.h"
#include "vision/stereo_images.h"

namespace kincal {

double CornerWeight(double contrast, const ObserveOptions& options) {
  if (options.full_weight_contrast <= 0) return 1.0;
  return std::clamp(contrast / options.full_weight_contrast,
                    options.min_corner_weight, 1.0);
}

SessionObservations ObserveSession(const Session& session, const Rig& rig,
                                   const Target& target,
                                   const ObserveOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  const int nc = static_cast<int>(rig.cameras.size());
  if (session.cameras.size() != rig.cameras.size()) {
    throw InputError(session.dir + ": the session has " +
                     std::to_string(session.cameras.size()) +
                     " cameras, the rig " + std::to_string(nc) +
                     " (read the session with the rig's camera names)");
  }
  SessionObservations out;
  out.session_frames = static_cast<int>(session.frames.size());
  AprilTagOptions dopt = options.detector;
  dopt.family = target.family;
  dopt.Check();
  const std::vector<std::unique_ptr<AprilTagDetector>> detectors =
      CameraDetectors(rig, dopt);
  int done = 0;
  const int total = session.CountWithJoints();
  // Per camera: its first image with tags checked for a camera's demosaic.
  std::vector<char> phase_checked(nc, 0), looks_demosaiced(nc, 0);
  for (const SessionFrame& sf : session.frames) {
    if (!sf.HasJoints()) {
      ++out.without_joints;
      continue;
    }
    std::vector<std::vector<TagDetection>> dets(nc);
    std::vector<BayerBalance> balance(nc);
    std::vector<int> looks_raw(nc, 0);
    ForEachCamera(nc, [&](int c) {
      const cv::Mat image = ReadCameraImage(
          sf.images[c], rig.cameras[c].intrinsics, options.bayer, &balance[c]);
      if (done == 0 && options.bayer == BayerPattern::kNone) {
        looks_raw[c] = LooksLikeRawMosaic(image);
      }
      dets[c] = detectors[c]->Detect(image);
      if (options.bayer == BayerPattern::kNone && !phase_checked[c] &&
          !dets[c].empty()) {
        phase_checked[c] = true;
        looks_demosaiced[c] =
            PhaseSharpnessRatio(image, dets[c]) > dopt.demosaiced_ratio;
      }
    });
    for (int raw : looks_raw) out.looks_raw += raw;
    for (const BayerBalance& b : balance) out.bayer_doubtful += b.doubtful;
    BundleFrame f;
    f.frame = sf.frame;
    f.q_reading = sf.q;
    f.t_s = sf.t[0];
    const ToolPoseResult r = EstimateToolPose(rig, target, dets, options.pose);
    if (r.found) {
      f.tracked = true;
      f.rig_from_tool = r.rig_from_tool;
      f.tracked_rms_px = r.rms_px;
      f.tracked_tags = r.tags_used;
      for (const TagObservationResult& t : r.tags) {
        if (!t.used) continue;
        int tag_index = -1;
        for (size_t k = 0; k < target.tags.size(); ++k) {
          if (target.tags[k].id == t.tag_id) tag_index = static_cast<int>(k);
        }
        if (tag_index < 0) continue;
        const double w = CornerWeight(t.contrast, options);
        for (int k = 0; k < 4; ++k) {
          if (t.corner_used[k]) {
            f.corners.push_back({t.camera, tag_index, k, t.corners_px[k], w});
          }
        }
      }
    }
    if (f.corners.empty()) ++out.without_tags;
    out.frames.push_back(std::move(f));
    ++done;
    if (options.progress) options.progress(done, total);
  }
  for (char d : looks_demosaiced) out.looks_demosaiced += d;
  out.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
          .count();
  return out;
}

}  // namespace kincal
