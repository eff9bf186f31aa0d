// Tag corners against the rendered truth, one rendering effect at a time
// (and the widened mix of target_bench), on the random holders of the
// target Monte Carlo (tests/target_monte_carlo.h): 640x512, 2-4 tags of
// 20-30 mm up to 70 deg apart, 40 tilted views per holder.
//
// Per scene and corner source (libapriltag's corners; the previous area-rule
// refinement, bench/previous_refinement.h; the pattern-model refinement
// before its checks; the detector's final corners): the corner RMS, and the
// RMS and maximum of a tag observation's mean corner offset (the shift its
// four corners share, which a pose fit cannot average out). The final
// corners (those the detector marks usable) are also split by what the
// detector kept (refined, or fallen back to libapriltag's), and compared
// corner by corner with libapriltag's: the share worse by more than 0.1 px
// and the RMS of the excess. For the corners not refined (fallen back, or
// left out as unusable), the model's corner and libapriltag's are compared.
//
//   build/bin/corner_bench [--holders N] [--scene NAME]

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <random>
#include <string>
#include <vector>

#include "bench/previous_refinement.h"
#include "synth/render.h"
#include "tests/target_monte_carlo.h"
#include "vision/apriltag_detector.h"

namespace kincal {
namespace {

struct Stat {
  double sum_sq = 0, off_sq = 0, off_max = 0;
  double radial_sum = 0, scale_sq = 0;  // along the tag centre's direction
  int n = 0, tags = 0;
  void AddCorner(const Eigen::Vector2d& e) {
    sum_sq += e.squaredNorm();
    ++n;
  }
  void AddTag(const Eigen::Vector2d& mean, double radial) {
    off_sq += mean.squaredNorm();
    off_max = std::max(off_max, mean.norm());
    radial_sum += radial;
    scale_sq += radial * radial;
    ++tags;
  }
  double Rms() const { return n ? std::sqrt(sum_sq / n) : 0; }
  double OffRms() const { return tags ? std::sqrt(off_sq / tags) : 0; }
  double RadialMean() const { return tags ? radial_sum / tags : 0; }
  double ScaleRms() const { return tags ? std::sqrt(scale_sq / tags) : 0; }
};

struct Scene {
  std::string name;
  RenderOptions options;  // ignored when `widened`
  bool widened = false;
};

std::vector<Scene> Scenes() {
  const auto base = [] {
    RenderOptions o;
    o.blur_sigma_px = 0.5;
    o.noise_sigma = 1.5;
    return o;
  };
  std::vector<Scene> s;
  s.push_back({"plain (blur 0.5, noise 1.5)", base()});
  RenderOptions o = base();
  o.blur_sigma_px = 0.9;
  s.push_back({"blur 0.9", o});
  o = base();
  o.defocus_px = 1.5;
  s.push_back({"defocus 1.5", o});
  o = base();
  o.motion_px = 2.5;
  o.motion_angle_deg = 30;
  s.push_back({"motion 2.5 px at 30 deg", o});
  o = base();
  o.vignetting = 0.5;
  s.push_back({"vignetting 0.5", o});
  o = base();
  o.light_gradient = 0.3;
  s.push_back({"light gradient 0.3", o});
  o = base();
  o.jpeg_quality = 70;
  s.push_back({"jpeg 70", o});
  o = base();
  o.bayer = true;
  s.push_back({"bayer (RGGB, gains 0.55 1 0.75)", o});
  o.noise_sigma = 0;
  s.push_back({"bayer without noise", o});
  o = base();
  o.noise_sigma = 0;
  s.push_back({"plain without noise", o});
  s.push_back({"widened (target_bench's draw)", base(), true});
  return s;
}

// The other detections (the refinement keeps its samples clear of them).
std::vector<NeighbourTag> Others(const std::vector<TagDetection>& dets,
                                 const TagDetection& self) {
  std::vector<NeighbourTag> out;
  for (const TagDetection& d : dets) {
    if (&d != &self) {
      out.push_back({d.detector_corners});
    }
  }
  return out;
}

// The corners' errors; with `usable`, only the corners it marks (the tag
// shift then over those).
void Accumulate(const TagTruth& t,
                const std::array<Eigen::Vector2d, 4>& corners, Stat* s,
                const std::array<bool, 4>& usable = {true, true, true, true}) {
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  const Eigen::Vector2d centre =
      (t.corners[0] + t.corners[1] + t.corners[2] + t.corners[3]) / 4.0;
  double radial = 0;
  int n = 0;
  for (int k = 0; k < 4; ++k) {
    if (!usable[k]) continue;
    s->AddCorner(corners[k] - t.corners[k]);
    mean += corners[k] - t.corners[k];
    radial +=
        (corners[k] - t.corners[k]).dot((t.corners[k] - centre).normalized());
    ++n;
  }
  if (n > 0) s->AddTag(mean / n, radial / n);
}

void RunScene(const Scene& scene, int holders) {
  std::map<std::string, Stat> stats;
  std::map<std::string, Stat> diag_model, diag_det;  // by what was kept
  int fallback = 0, left_out = 0, total = 0, failed = 0, worse = 0;
  double excess_sq = 0;
  for (int seed = 1; seed <= holders; ++seed) {
    std::mt19937_64 rng(1000 + seed);
    std::uniform_real_distribution<double> u(0, 2 * M_PI);
    const Rig rig = ExampleStereoRig(640, 512);
    const Target target = testing::RandomHolder(2 + seed % 3, &rng);
    RenderOptions options = testing::WidenedEffects(&rng);
    if (!scene.widened) options = scene.options;
    const double phase_a = u(rng), phase_b = u(rng);
    const StereoRenderer renderer(rig, target, options);
    AprilTagOptions det_options;
    AprilTagDetector detector(det_options);
    for (int i = 0; i < 40; ++i) {
      const Rigid3 pose = testing::TiltedAbout(
          ExampleToolPose(i + 7 * seed), 25 * std::sin(0.9 * i + phase_a),
          30 * std::cos(0.6 * i + phase_b), Eigen::Vector3d::Zero());
      const StereoFrameTruth truth = renderer.Render(pose, &rng);
      for (const ViewTruth& view : truth.views) {
        const std::vector<TagDetection> dets = detector.Detect(view.image);
        for (const TagDetection& d : dets) {
          const TagTruth* t = nullptr;
          for (const TagTruth& c : view.tags) {
            if (c.id == d.id) t = &c;
          }
          if (t == nullptr) continue;
          Accumulate(*t, d.detector_corners, &stats["a libapriltag"]);
          Accumulate(*t, d.corners, &stats["d final (usable corners)"],
                     d.usable);
          TagDetection raw = d;
          raw.corners = d.detector_corners;
          if (RefineCornersByEdges(view.image, TagImage("tag36h11", d.id), 8,
                                   &raw, Others(dets, d))) {
            Accumulate(*t, raw.corners, &stats["c model, no checks"]);
            // Corners not refined: the model's corner against libapriltag's.
            for (int k = 0; k < 4; ++k) {
              if (d.refined[k]) continue;
              const char* key = d.usable[k] ? "fallen back" : "left out";
              diag_model[key].AddCorner(raw.corners[k] - t->corners[k]);
              diag_det[key].AddCorner(d.detector_corners[k] - t->corners[k]);
            }
          } else {
            ++failed;
          }
          for (int k = 0; k < 4; ++k) {
            ++total;
            if (!d.usable[k]) {
              ++left_out;
              continue;
            }
            if (!d.refined[k]) ++fallback;
            Stat& s = stats[d.refined[k] ? "e final, refined corners"
                                         : "f final, fallen back"];
            s.AddCorner(d.corners[k] - t->corners[k]);
            const double excess =
                (d.corners[k] - t->corners[k]).norm() -
                (d.detector_corners[k] - t->corners[k]).norm();
            excess_sq += excess > 0 ? excess * excess : 0;
            worse += excess > 0.1 ? 1 : 0;
          }
        }
        for (const TagDetection& d : previous::Refine(view.image, dets)) {
          for (const TagTruth& c : view.tags) {
            if (c.id == d.id) {
              Accumulate(c, d.corners, &stats["b previous area rule"]);
            }
          }
        }
      }
    }
  }
  std::printf(
      "%s: %d corners, %.1f %% fallen back, %.1f %% left out, %d tags not "
      "refined; final vs libapriltag per corner: %.2f %% worse by > 0.1 px, "
      "RMS excess %.4f px\n",
      scene.name.c_str(), total, 100.0 * fallback / std::max(1, total),
      100.0 * left_out / std::max(1, total), failed,
      100.0 * worse / std::max(1, total),
      std::sqrt(excess_sq / std::max(1, total)));
  for (const auto& [name, s] : stats) {
    std::printf("  %-26s corner RMS %.4f px", name.c_str() + 2, s.Rms());
    if (s.tags > 0) {
      std::printf("  tag shift RMS %.4f max %.3f px", s.OffRms(), s.off_max);
      std::printf("  outward mean %+.4f RMS %.4f px", s.RadialMean(),
                  s.ScaleRms());
    }
    std::printf("\n");
  }
  for (const auto& [name, s] : diag_model) {
    std::printf(
        "  not refined, %-12s %4d corners: model's corner RMS %.4f px, "
        "libapriltag's %.4f px\n",
        name.c_str(), s.n, s.Rms(), diag_det[name].Rms());
  }
  std::fflush(stdout);
}

}  // namespace
}  // namespace kincal

int main(int argc, char** argv) {
  int holders = 6;
  std::string only;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--holders") && i + 1 < argc) {
      holders = std::atoi(argv[++i]);
    } else if (!std::strcmp(argv[i], "--scene") && i + 1 < argc) {
      only = argv[++i];
    } else {
      std::fprintf(stderr,
                   "usage: corner_bench [--holders N] [--scene NAME]\n");
      return 2;
    }
  }
  for (const kincal::Scene& s : kincal::Scenes()) {
    if (!only.empty() && s.name.find(only) == std::string::npos) continue;
    kincal::RunScene(s, holders);
  }
  return 0;
}
