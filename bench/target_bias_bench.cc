// What error the views of a `kincal target` session share
// (tests/target_monte_carlo.h's sessions, seed by seed):
//  - the layout and the pivot tip refitted from the detected corners, from
//    the rendered truth, and from the detected corners less each tag
//    observation's mean shift or mean radial (scale) error: which part of
//    the corner error carries the tip's;
//  - each tag corner's error mapped into its tag's plane (through the
//    homography of the true corners), per (tag, corner) over the layout
//    session: the mean (what every view shares) against the scatter;
//  - --noise-free: the same render without sensor noise and JPEG, so that
//    only the detector's bias remains.
//
//   build/bin/target_bias_bench [--plain] [--noise-free] SEED...

#include <cstdio>
#include <map>
#include <opencv2/imgproc.hpp>
#include <string>

#include "tests/target_monte_carlo.h"

namespace kincal::testing {
namespace {

struct Detected {
  std::vector<LayoutFrame> frames;
  TruthCorners truth;
};

enum class Corners { kDetected, kTruth, kLessShift, kLessScale };

// The frames with every tag observation's corners replaced as `which` says.
std::vector<LayoutFrame> Replaced(const Detected& d, Corners which) {
  std::vector<LayoutFrame> frames = d.frames;
  for (size_t f = 0; f < frames.size(); ++f) {
    for (size_t c = 0; c < frames[f].detections.size(); ++c) {
      for (size_t j = 0; j < frames[f].detections[c].size(); ++j) {
        TagDetection& det = frames[f].detections[c][j];
        const auto& t = d.truth[f][c][j];
        if (std::isnan(t[0].x())) continue;
        const Eigen::Vector2d centre = (t[0] + t[1] + t[2] + t[3]) / 4;
        Eigen::Vector2d shift = Eigen::Vector2d::Zero();
        double radial = 0;
        int n = 0;
        for (int k = 0; k < 4; ++k) {
          if (!det.usable[k]) continue;
          const Eigen::Vector2d e = det.corners[k] - t[k];
          shift += e;
          radial += e.dot((t[k] - centre).normalized());
          ++n;
        }
        if (n == 0) continue;
        for (int k = 0; k < 4; ++k) {
          if (which == Corners::kTruth) det.corners[k] = t[k];
          if (which == Corners::kLessShift) det.corners[k] -= shift / n;
          if (which == Corners::kLessScale) {
            det.corners[k] -= radial / n * (t[k] - centre).normalized();
          }
        }
      }
    }
  }
  return frames;
}

// Per (tag, corner), the corner errors in the tag's plane (mm).
void PrintTagPlaneBias(const Detected& d, double size_mm) {
  std::map<std::pair<int, int>, std::vector<Eigen::Vector2d>> errors;
  for (size_t f = 0; f < d.frames.size(); ++f) {
    for (size_t c = 0; c < d.frames[f].detections.size(); ++c) {
      for (size_t j = 0; j < d.frames[f].detections[c].size(); ++j) {
        const TagDetection& det = d.frames[f].detections[c][j];
        const auto& t = d.truth[f][c][j];
        if (std::isnan(t[0].x())) continue;
        std::vector<cv::Point2f> image, plane;
        for (int k = 0; k < 4; ++k) {
          const Eigen::Vector3d p = TagCornerInTag(k, size_mm);
          image.emplace_back(t[k].x(), t[k].y());
          plane.emplace_back(p.x(), p.y());
        }
        const cv::Mat h = cv::getPerspectiveTransform(image, plane);
        for (int k = 0; k < 4; ++k) {
          if (!det.usable[k]) continue;
          std::vector<cv::Point2f> in{
              cv::Point2f(det.corners[k].x(), det.corners[k].y())},
              out;
          cv::perspectiveTransform(in, out, h);
          const Eigen::Vector3d p = TagCornerInTag(k, size_mm);
          errors[{det.id, k}].emplace_back(out[0].x - p.x(), out[0].y - p.y());
        }
      }
    }
  }
  double mean2 = 0, scatter2 = 0;
  for (const auto& [key, v] : errors) {
    Eigen::Vector2d mean = Eigen::Vector2d::Zero();
    for (const Eigen::Vector2d& e : v) mean += e;
    mean /= v.size();
    double s2 = 0;
    for (const Eigen::Vector2d& e : v) s2 += (e - mean).squaredNorm();
    mean2 += mean.squaredNorm();
    scatter2 += s2 / v.size();
  }
  std::printf(
      "  corner error in the tag plane over %zu (tag, corner): RMS of the "
      "means %.1f um, RMS scatter %.1f um\n",
      errors.size(), 1e3 * std::sqrt(mean2 / errors.size()),
      1e3 * std::sqrt(scatter2 / errors.size()));
}

void PrintFit(const char* name, const Rig& rig, const McSession& s,
              const std::vector<LayoutFrame>& views,
              const std::vector<LayoutFrame>& pivot) {
  TargetLayoutOptions options;
  options.family = s.truth.family;
  options.tag_size_mm = s.truth.tags[0].size_mm;
  const TargetLayoutResult layout = MeasureTargetLayout(rig, views, options);
  const PivotTipResult tip =
      MeasurePivotTip(rig, layout, pivot, PivotTipOptions());
  const Rigid3 ref_from_tool =
      s.truth.FindTag(layout.reference_tag_id)->tool_from_tag.Inverse();
  double max_t = 0, max_r = 0;
  for (const LayoutTag& tag : layout.tags) {
    const Rigid3 want = ref_from_tool * s.truth.FindTag(tag.id)->tool_from_tag;
    max_t = std::max(max_t, (tag.tool_from_tag.t - want.t).norm());
    max_r = std::max(max_r, RotationVectorFromMatrix(tag.tool_from_tag.R *
                                                     want.R.transpose())
                                    .norm() *
                                180 / M_PI);
  }
  const Eigen::Vector3d e =
      tip.pivot.tip_in_tool - ref_from_tool * s.truth.tip_in_tool;
  std::printf(
      "  %-34s tags %.4f mm %.4f deg  tip %.4f mm (sigma %.4f, shared part "
      "%.4f; offsets %.1f um)\n",
      name, max_t, max_r, e.norm(), tip.tip_sigma_mm.norm(),
      tip.systematic_sigma_mm.norm(), 1e3 * tip.corner_offset_sigma_mm);
}

void RunSeed(int seed, bool plain, bool noise_free) {
  std::mt19937_64 rng(1000 + seed);
  const Rig rig = ExampleStereoRig(640, 512);
  const McSession s = MakeSession(seed, plain, &rng, noise_free);
  const RenderOptions& e = s.effects;
  std::printf(
      "seed %d: %zu tags of %.1f mm; blur %.2f noise %.1f defocus %.2f motion "
      "%.2f px\n",
      seed, s.truth.tags.size(), s.truth.tags[0].size_mm, e.blur_sigma_px,
      e.noise_sigma, e.defocus_px, e.motion_px);
  CornerErrors errors;
  Detected views, pivot;
  views.frames =
      RenderAndDetect(rig, s.truth, s.views, e, &rng, &errors, &views.truth);
  pivot.frames =
      RenderAndDetect(rig, s.truth, s.pivot, e, &rng, &errors, &pivot.truth);
  PrintTagPlaneBias(views, s.truth.tags[0].size_mm);
  const std::pair<const char*, Corners> variants[] = {
      {"detected corners", Corners::kDetected},
      {"rendered truth", Corners::kTruth},
      {"less each observation's shift", Corners::kLessShift},
      {"less each observation's scale", Corners::kLessScale}};
  for (const auto& [name, which] : variants) {
    PrintFit(name, rig, s, Replaced(views, which), Replaced(pivot, which));
  }
  std::fflush(stdout);
}

}  // namespace
}  // namespace kincal::testing

int main(int argc, char** argv) {
  const kincal::testing::SeedArgs a =
      kincal::testing::ParseSeedArgs(argc, argv, "target_bias_bench");
  if (!a.ok) return 2;
  for (int seed : a.seeds) {
    kincal::testing::RunSeed(seed, a.plain, a.noise_free);
  }
  return 0;
}
