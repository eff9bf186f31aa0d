// Where the refined corners err under a blur that is not one Gaussian
// (tests/target_monte_carlo.h's sessions, views and pivot frames, seed by
// seed), against the rendered truth:
//  - the usable corners' RMS, split into refined and fallen back to
//    libapriltag's (and what the fallen-back ones would have been as
//    refined), and by their sides' line scatter;
//  - each side's edge error (the mean, over its two corners, of the corner
//    error along the side's outward normal; + = outwards), binned by the
//    motion blur's length projected on the side's normal and by the cell
//    size over the side's fitted blur (TagSideQuality::blur_px);
//  - the twelve worst corners with their sides' cells, blur and scatter.
//
//   build/bin/blur_sides_bench [--plain] [--noise-free] SEED...

#include <algorithm>
#include <cstdio>
#include <map>
#include <string>

#include "tests/target_monte_carlo.h"

namespace kincal::testing {
namespace {

struct Bin {
  double sum = 0, sum_sq = 0;
  int n = 0;
  void Add(double e) {
    sum += e;
    sum_sq += e * e;
    ++n;
  }
};

void PrintBins(const char* what, const std::map<int, Bin>& bins, double width) {
  std::printf("  side edge error by %s:\n", what);
  for (const auto& [i, b] : bins) {
    std::printf("    [%5.2f, %5.2f): %4d sides, mean %+.3f px, RMS %.3f px\n",
                i * width, (i + 1) * width, b.n, b.sum / b.n,
                std::sqrt(b.sum_sq / b.n));
  }
}

void RunSeed(int seed, bool plain, bool noise_free) {
  std::mt19937_64 rng(1000 + seed);
  const Rig rig = ExampleStereoRig(640, 512);
  const McSession s = MakeSession(seed, plain, &rng, noise_free);
  const RenderOptions& e = s.effects;
  std::printf(
      "seed %d: blur %.2f defocus %.2f motion %.2f px at %.0f deg, noise "
      "%.1f\n",
      seed, e.blur_sigma_px, e.defocus_px, e.motion_px, e.motion_angle_deg,
      e.noise_sigma);
  std::vector<Rigid3> poses = s.views;
  poses.insert(poses.end(), s.pivot.begin(), s.pivot.end());
  // As RenderAndDetect, keeping the images: each fallen-back corner's
  // refined (model) corner is measured too.
  const StereoRenderer renderer(rig, s.truth, e);
  AprilTagDetector tags;
  std::vector<LayoutFrame> frames;
  TruthCorners truth;
  Bin model_of_fallen;
  for (size_t i = 0; i < poses.size(); ++i) {
    const StereoFrameTruth rendered = renderer.Render(poses[i], &rng);
    LayoutFrame f;
    truth.emplace_back();
    for (const ViewTruth& view : rendered.views) {
      f.detections.push_back(tags.Detect(view.image));
      truth.back().emplace_back();
      for (const TagDetection& d : f.detections.back()) {
        std::array<Eigen::Vector2d, 4> corners;
        for (Eigen::Vector2d& c : corners) c.setConstant(NAN);
        for (const TagTruth& t : view.tags) {
          if (t.id == d.id) corners = t.corners;
        }
        truth.back().back().push_back(corners);
        if (std::isnan(corners[0].x())) continue;
        std::vector<NeighbourTag> others;
        for (const TagDetection& o : f.detections.back()) {
          if (&o != &d) others.push_back({o.detector_corners});
        }
        TagDetection raw = d;
        raw.corners = d.detector_corners;
        if (!RefineCornersByEdges(view.image, TagImage("tag36h11", d.id), 8,
                                  &raw, others)) {
          continue;
        }
        for (int k = 0; k < 4; ++k) {
          if (!d.refined[k] && d.usable[k]) {
            model_of_fallen.Add((raw.corners[k] - corners[k]).norm());
          }
        }
      }
    }
    frames.push_back(std::move(f));
  }
  const Eigen::Vector2d motion(std::cos(e.motion_angle_deg * M_PI / 180),
                               std::sin(e.motion_angle_deg * M_PI / 180));
  std::map<int, Bin> by_motion, by_cell;
  Bin refined, detector, all_sides, kept, fell_back;
  std::map<int, Bin> by_scatter;
  struct Worst {
    double error;
    std::string text;
  };
  std::vector<Worst> worst_corners;  // corner error by its sides' line scatter
  int unusable = 0, corners = 0, worse = 0;
  double worst = 0;
  for (size_t f = 0; f < frames.size(); ++f) {
    for (size_t c = 0; c < frames[f].detections.size(); ++c) {
      for (size_t j = 0; j < frames[f].detections[c].size(); ++j) {
        const TagDetection& d = frames[f].detections[c][j];
        const auto& t = truth[f][c][j];
        if (std::isnan(t[0].x())) continue;
        const Eigen::Vector2d centre = (t[0] + t[1] + t[2] + t[3]) / 4;
        for (int k = 0; k < 4; ++k) {
          ++corners;
          const double de = (d.detector_corners[k] - t[k]).norm();
          detector.Add(de);
          if (!d.usable[k]) {
            ++unusable;
            continue;
          }
          const double ce = (d.corners[k] - t[k]).norm();
          refined.Add(ce);
          (d.refined[k] ? kept : fell_back).Add(ce);
          {
            const int prev = (k + 3) % 4;
            char text[400];
            std::snprintf(
                text, sizeof text,
                "frame %zu cam %zu tag %d corner %d: %.3f px (%s; "
                "libapriltag %.3f) sides %d/%d: cells %.2f/%.2f px, blur "
                "%.2f/%.2f, scatter %.3f/%.3f, points %d/%d, near %d/%d",
                f, c, d.id, k, ce, d.refined[k] ? "refined" : "libapriltag", de,
                prev, k, (t[k] - t[prev]).norm() / 8,
                (t[(k + 1) % 4] - t[k]).norm() / 8, d.sides[prev].blur_px,
                d.sides[k].blur_px, d.sides[prev].line_rms_px,
                d.sides[k].line_rms_px, d.sides[prev].points, d.sides[k].points,
                d.sides[prev].near_other_tag, d.sides[k].near_other_tag);
            worst_corners.push_back({ce, text});
          }
          const double scatter = std::max(d.sides[k].line_rms_px,
                                          d.sides[(k + 3) % 4].line_rms_px);
          by_scatter[static_cast<int>(scatter / 0.05)].Add(ce);
          worst = std::max(worst, ce);
          worse += ce > de + 0.1 ? 1 : 0;
          const int next = (k + 1) % 4;
          if (!d.usable[next] || !d.refined[k] || !d.refined[next]) continue;
          const Eigen::Vector2d dir = (t[next] - t[k]).normalized();
          Eigen::Vector2d n(-dir.y(), dir.x());
          if (n.dot((t[k] + t[next]) / 2 - centre) < 0) n = -n;
          const double err = 0.5 * (n.dot(d.corners[k] - t[k]) +
                                    n.dot(d.corners[next] - t[next]));
          const double cell = (t[next] - t[k]).norm() / 8;
          const double projected = e.motion_px * std::abs(n.dot(motion));
          all_sides.Add(err);
          by_motion[static_cast<int>(projected / 0.5)].Add(err);
          if (d.sides[k].blur_px > 0) {
            by_cell[static_cast<int>(cell / d.sides[k].blur_px)].Add(err);
          }
        }
      }
    }
  }
  std::printf(
      "  %d corners: usable RMS %.4f px (max %.2f), libapriltag %.4f px; "
      "unusable %d, worse than libapriltag by 0.1 px: %d\n",
      corners, std::sqrt(refined.sum_sq / refined.n), worst,
      std::sqrt(detector.sum_sq / detector.n), unusable, worse);
  std::printf(
      "  refined %d corners, RMS %.4f px; fallen back to libapriltag's %d, "
      "RMS %.4f px\n",
      kept.n, std::sqrt(kept.sum_sq / std::max(1, kept.n)), fell_back.n,
      std::sqrt(fell_back.sum_sq / std::max(1, fell_back.n)));
  PrintBins("corner error (not side) by its sides' line scatter (px)",
            by_scatter, 0.05);
  std::printf(
      "  the fallen-back corners as refined: RMS %.4f px\n",
      std::sqrt(model_of_fallen.sum_sq / std::max(1, model_of_fallen.n)));
  std::printf("  sides: %d, mean %+.4f px, RMS %.4f px\n", all_sides.n,
              all_sides.sum / all_sides.n,
              std::sqrt(all_sides.sum_sq / all_sides.n));
  std::sort(worst_corners.begin(), worst_corners.end(),
            [](const Worst& a, const Worst& b) { return a.error > b.error; });
  for (size_t i = 0; i < std::min<size_t>(worst_corners.size(), 12); ++i) {
    std::printf("  %s\n", worst_corners[i].text.c_str());
  }
  PrintBins("projected motion (px)", by_motion, 0.5);
  PrintBins("cell / fitted blur", by_cell, 1.0);
  std::fflush(stdout);
}

}  // namespace
}  // namespace kincal::testing

int main(int argc, char** argv) {
  const kincal::testing::SeedArgs a =
      kincal::testing::ParseSeedArgs(argc, argv, "blur_sides_bench");
  if (!a.ok) return 2;
  for (int seed : a.seeds) {
    kincal::testing::RunSeed(seed, a.plain, a.noise_free);
  }
  return 0;
}
