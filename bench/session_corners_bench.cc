// Detected tag corners of a rendered session against its corners.csv (the
// render's truth): what the bundle would measure from those images. Per
// corner the error; per tag observation the mean outward error (along the
// direction from the tag's centre: a tag-scale bias, which trades against
// the stereo baseline), split by the corner's Bayer phase (x % 2, y % 2 of
// the nearest pixel), by the tag's contrast, and for the corners the pose
// fit keeps (what the bundle takes).
//
//   build/bin/session_corners_bench --session S/session --rig S/rig.yaml
//       --target S/target.yaml [--bayer RGGB] [--fit-demosaic 0] [--lens 0]
// (--bayer: the images are raw mosaics, balanced to gray as track and
// bundle --bayer do; --fit-demosaic 0: demosaiced images take the blur per
// phase, not the linear demosaic's model, AprilTagOptions::fit_demosaic;
// --lens 0: the sides' lines fitted in the distorted image, not in the
// rig camera's pinhole image, AprilTagOptions::lens.)

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "camcal/rig.h"
#include "data/session.h"
#include "vision/apriltag_detector.h"
#include "vision/stereo_images.h"
#include "vision/target.h"
#include "vision/tool_pose.h"

namespace kincal {
namespace {

struct Stat {
  double sq = 0, radial = 0, radial_sq = 0;
  int n = 0;
  std::vector<double> errors;
  void Add(const Eigen::Vector2d& e, double outward) {
    sq += e.squaredNorm();
    radial += outward;
    radial_sq += outward * outward;
    errors.push_back(e.norm());
    ++n;
  }
  void Print(const std::string& name) {
    if (n == 0) return;
    std::sort(errors.begin(), errors.end());
    std::printf(
        "  %-34s %5d  RMS %.4f  median %.4f  p99 %.3f  max %.3f  outward "
        "mean %+.4f RMS %.4f px\n",
        name.c_str(), n, std::sqrt(sq / n), errors[n / 2],
        errors[std::min(n - 1, n * 99 / 100)], errors.back(), radial / n,
        std::sqrt(radial_sq / n));
  }
};

using Key = std::tuple<int, int, int, int>;  // frame, camera, tag id, corner

std::map<Key, Eigen::Vector2d> ReadCorners(const std::string& path) {
  std::ifstream in(path);
  std::map<Key, Eigen::Vector2d> out;
  std::string line;
  bool header = false;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    if (!header) {
      header = true;
      continue;
    }
    std::replace(line.begin(), line.end(), ',', ' ');
    std::istringstream is(line);
    int f, c, t, k, visible;
    double u, v;
    if (is >> f >> c >> t >> k >> u >> v >> visible) {
      out[{f, c, t, k}] = {u, v};
    }
  }
  return out;
}

int Run(const std::string& session_dir, const std::string& rig_path,
        const std::string& target_path, BayerPattern bayer, bool fit_demosaic,
        bool lens) {
  const Rig rig = ReadRigYaml(rig_path);
  const Target target = ReadTargetYaml(target_path);
  SessionReadOptions ro;
  ro.camera_names = rig.CameraNames();
  const Session session = ReadSession(session_dir, ro);
  const auto truth = ReadCorners(session_dir + "/corners.csv");
  AprilTagOptions dopt;
  dopt.family = target.family;
  dopt.fit_demosaic = fit_demosaic;
  Rig lenses = rig;
  if (!lens) {
    for (Camera& c : lenses.cameras) c.intrinsics.distortion.clear();
  }
  const std::vector<std::unique_ptr<AprilTagDetector>> detectors =
      CameraDetectors(lenses, dopt);
  std::map<std::string, Stat> stats;
  std::vector<double> phase_ratios;
  for (const SessionFrame& sf : session.frames) {
    std::vector<std::vector<TagDetection>> dets(rig.cameras.size());
    for (size_t c = 0; c < rig.cameras.size(); ++c) {
      const cv::Mat image =
          ReadCameraImage(sf.images[c], rig.cameras[c].intrinsics, bayer);
      dets[c] = detectors[c]->Detect(image);
      if (!dets[c].empty()) {
        phase_ratios.push_back(PhaseSharpnessRatio(image, dets[c]));
      }
    }
    const ToolPoseResult pose = EstimateToolPose(rig, target, dets);
    for (size_t c = 0; c < dets.size(); ++c) {
      for (const TagDetection& d : dets[c]) {
        std::array<Eigen::Vector2d, 4> tc;
        bool all = true;
        for (int k = 0; k < 4; ++k) {
          auto it = truth.find({sf.frame, static_cast<int>(c), d.id, k});
          if (it == truth.end()) {
            all = false;
            break;
          }
          tc[k] = it->second;
        }
        if (!all) continue;
        const Eigen::Vector2d centre = (tc[0] + tc[1] + tc[2] + tc[3]) / 4;
        const TagObservationResult* used = nullptr;
        for (const auto& t : pose.tags) {
          if (t.camera == static_cast<int>(c) && t.tag_id == d.id && t.used) {
            used = &t;
          }
        }
        double contrast = 1e9;
        for (const auto& s : d.sides) contrast = std::min(contrast, s.contrast);
        const std::string band = contrast < 60    ? "contrast < 60"
                                 : contrast < 100 ? "contrast 60-100"
                                                  : "contrast >= 100";
        for (int k = 0; k < 4; ++k) {
          const Eigen::Vector2d e = d.corners[k] - tc[k];
          const double outward = e.dot((tc[k] - centre).normalized());
          stats["a libapriltag"].Add(d.detector_corners[k] - tc[k],
                                     (d.detector_corners[k] - tc[k])
                                         .dot((tc[k] - centre).normalized()));
          if (!d.usable[k]) continue;
          stats[d.refined[k] ? "b usable, refined" : "c usable, detector"].Add(
              e, outward);
          if (used == nullptr || !used->corner_used[k]) continue;
          stats["d pose-fit corners (bundle)"].Add(e, outward);
          const int px = static_cast<int>(std::lround(tc[k].x())) & 1;
          const int py = static_cast<int>(std::lround(tc[k].y())) & 1;
          stats["e phase x%2=" + std::to_string(px) +
                " y%2=" + std::to_string(py)]
              .Add(e, outward);
          stats["f " + band].Add(e, outward);
          const double ang =
              std::fmod(std::abs(std::atan2((tc[(k + 1) % 4] - tc[k]).y(),
                                            (tc[(k + 1) % 4] - tc[k]).x())) *
                            180 / M_PI,
                        90.0);
          const double off_axis = std::min(ang, 90 - ang);
          stats[off_axis < 10 ? "g side within 10 deg of axis"
                              : "g side > 10 deg off axis"]
              .Add(e, outward);
        }
      }
    }
  }
  std::printf("%s\n", session_dir.c_str());
  if (!phase_ratios.empty()) {
    std::sort(phase_ratios.begin(), phase_ratios.end());
    std::printf("  phase sharpness ratio: median %.2f, min %.2f, max %.2f\n",
                phase_ratios[phase_ratios.size() / 2], phase_ratios.front(),
                phase_ratios.back());
  }
  for (auto& [name, s] : stats) s.Print(name.substr(2));
  return 0;
}

}  // namespace
}  // namespace kincal

int main(int argc, char** argv) {
  std::string session, rig, target, bayer = "none";
  bool fit_demosaic = true, lens = true;
  for (int i = 1; i + 1 < argc; i += 2) {
    if (!std::strcmp(argv[i], "--session")) session = argv[i + 1];
    if (!std::strcmp(argv[i], "--rig")) rig = argv[i + 1];
    if (!std::strcmp(argv[i], "--target")) target = argv[i + 1];
    if (!std::strcmp(argv[i], "--bayer")) bayer = argv[i + 1];
    if (!std::strcmp(argv[i], "--fit-demosaic")) {
      fit_demosaic = std::strcmp(argv[i + 1], "0") != 0;
    }
    if (!std::strcmp(argv[i], "--lens")) lens = std::strcmp(argv[i + 1], "0");
  }
  if (session.empty() || rig.empty() || target.empty()) {
    std::fprintf(stderr,
                 "usage: session_corners_bench --session DIR --rig RIG.yaml "
                 "--target TARGET.yaml [--bayer RGGB] [--fit-demosaic 0] "
                 "[--lens 0]\n");
    return 2;
  }
  return kincal::Run(session, rig, target, kincal::ParseBayerPattern(bayer),
                     fit_demosaic, lens);
}
