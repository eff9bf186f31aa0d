#ifndef KINCAL_TESTS_TARGET_MONTE_CARLO_H_
#define KINCAL_TESTS_TARGET_MONTE_CARLO_H_

// Monte Carlo of `kincal target`'s measurement (vision/target_layout.h) on
// rendered sessions of tools alone, shared by tests/target_cli_test.cc (a
// few seeds) and bench/target_bench.cc (the full run):
//  - a random holder per seed, not designed into the solver: 2-4 tags of
//    20-30 mm, the outer ones turned 15-35 deg outwards about the holder's
//    y axis (up to 70 deg between tags), +-10 deg about x, any
//    turn in their own plane; a hidden tip 90-140 mm from the tags;
//  - the renderer's widened effects drawn per seed (blur, noise, exposure,
//    defocus, motion blur, vignetting, light gradient, JPEG);
//  - 40 views tilted up to +-25 / +-30 deg, and a pivot session of 32
//    frames on two circles tilted +-25 and +-12 deg about the tip;
//  - the layout against the truth in the reference tag's frame, and the
//    pivot tip with its sigma (pivot and layout parts);
//  - `plain`: blur 0.5 px and noise 1.5 gray levels only, instead of the
//    widened effects.

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "synth/render.h"
#include "tests/testing/tilt.h"
#include "vision/apriltag_detector.h"
#include "vision/target_layout.h"

namespace kincal::testing {

inline Eigen::Matrix3d McRot(const Eigen::Vector3d& axis, double deg) {
  return Eigen::AngleAxisd(deg * M_PI / 180, axis.normalized())
      .toRotationMatrix();
}

inline Target RandomHolder(int tags, std::mt19937_64* rng) {
  std::uniform_real_distribution<double> u(0, 1);
  const auto range = [&](double lo, double hi) {
    return lo + (hi - lo) * u(*rng);
  };
  Target t;
  t.family = "tag36h11";
  const double size = range(20, 30);
  const double pitch = 1.45 * size;
  for (int i = 0; i < tags; ++i) {
    // Row of 2-3 tags along x, or a 2 x 2 grid; outer columns turned
    // opposite ways about y.
    const int columns = tags == 4 ? 2 : tags;
    const int col = i % columns, row = i / columns;
    const double x = pitch * (col - (columns - 1) / 2.0);
    const double y = tags == 4 ? pitch * (row - 0.5) : range(-3, 3);
    // A convex holder: the outer tags face outwards and sit further back
    // (as on a folded sheet), so that no tag hides another.
    double about_y = range(-10, 10);
    if (col == 0) about_y = range(15, 35);
    if (col == columns - 1) about_y = -range(15, 35);
    TargetTag tag;
    tag.id = 3 * i + static_cast<int>(range(0, 3));
    tag.size_mm = size;
    tag.tool_from_tag.R = McRot(Eigen::Vector3d::UnitY(), about_y) *
                          McRot(Eigen::Vector3d::UnitX(), range(-10, 10)) *
                          McRot(Eigen::Vector3d::UnitZ(), range(-180, 180));
    tag.tool_from_tag.t = Eigen::Vector3d(
        x, y, std::abs(x) * std::sin(std::abs(about_y) * M_PI / 180));
    t.tags.push_back(tag);
  }
  t.tip_in_tool = Eigen::Vector3d(range(-15, 15), range(90, 140), range(0, 20));
  return t;
}

inline RenderOptions WidenedEffects(std::mt19937_64* rng) {
  std::uniform_real_distribution<double> u(0, 1);
  const auto range = [&](double lo, double hi) {
    return lo + (hi - lo) * u(*rng);
  };
  RenderOptions o;
  o.blur_sigma_px = range(0.4, 0.9);
  o.noise_sigma = range(1.0, 2.5);
  o.exposure_jitter = 0.05;
  if (u(*rng) < 0.5) o.defocus_px = range(0.5, 1.5);
  if (u(*rng) < 0.5) {
    o.motion_px = range(0.5, 2.5);
    o.motion_angle_deg = range(0, 180);
  }
  o.vignetting = range(0, 0.5);
  o.light_gradient = range(0, 0.3);
  if (u(*rng) < 0.5) o.jpeg_quality = static_cast<int>(range(70, 95));
  return o;
}

struct McTrial {
  int tags = 0, views = 0, pivot_views = 0;
  // error / sigma per component: tag translation and rotation (non-reference
  // tags), tip (total sigma); errors in the measured tool frame.
  std::vector<double> z_t, z_r, z_tip;
  double max_t_mm = 0, max_r_deg = 0, tip_mm = 0;
  double tip_sigma_mm = 0, tip_layout_sigma_mm = 0, tip_pivot_sigma_mm = 0;
  // The corner offsets shared by every view: their sigma (mm, per axis in
  // the tag plane) and their part of the tip's sigma.
  double corner_offset_sigma_mm = 0, tip_systematic_sigma_mm = 0;
  double seconds = 0;
  // Detected corners against the rendered truth: RMS (px) and the largest
  // mean offset of one tag observation's four corners (px).
  double corner_rms_px = 0, max_tag_offset_px = 0;
  RenderOptions effects;
};

struct CornerErrors {
  double sum_sq = 0, max_offset = 0;
  int n = 0;
};

// The rendered truth of every detection, [frame][camera][detection] as
// LayoutFrame::detections (NaN corners for a detection without a truth).
using TruthCorners =
    std::vector<std::vector<std::vector<std::array<Eigen::Vector2d, 4>>>>;

inline std::vector<LayoutFrame> RenderAndDetect(
    const Rig& rig, const Target& target, const std::vector<Rigid3>& poses,
    const RenderOptions& options, std::mt19937_64* rng, CornerErrors* errors,
    TruthCorners* truth_corners = nullptr) {
  const StereoRenderer renderer(rig, target, options);
  AprilTagOptions detector_options;
  detector_options.family = target.family;
  const std::vector<std::unique_ptr<AprilTagDetector>> detectors =
      CameraDetectors(rig, detector_options);
  std::vector<LayoutFrame> frames;
  for (size_t i = 0; i < poses.size(); ++i) {
    const StereoFrameTruth truth = renderer.Render(poses[i], rng);
    LayoutFrame f;
    f.frame = static_cast<int>(i);
    if (truth_corners) truth_corners->emplace_back();
    for (const ViewTruth& view : truth.views) {
      f.detections.push_back(
          detectors[f.detections.size()]->Detect(view.image));
      if (truth_corners) truth_corners->back().emplace_back();
      for (const TagDetection& d : f.detections.back()) {
        std::array<Eigen::Vector2d, 4> nan;
        for (Eigen::Vector2d& c : nan) c.setConstant(NAN);
        if (truth_corners) truth_corners->back().back().push_back(nan);
        for (const TagTruth& t : view.tags) {
          if (t.id != d.id) continue;
          if (truth_corners) truth_corners->back().back().back() = t.corners;
          // The corners the detector trusts (those the fits use).
          Eigen::Vector2d mean = Eigen::Vector2d::Zero();
          int n = 0;
          for (int k = 0; k < 4; ++k) {
            if (!d.usable[k]) continue;
            errors->sum_sq += (d.corners[k] - t.corners[k]).squaredNorm();
            mean += d.corners[k] - t.corners[k];
            ++n;
          }
          errors->n += n;
          if (n > 0) {
            errors->max_offset = std::max(errors->max_offset, mean.norm() / n);
          }
        }
      }
    }
    frames.push_back(std::move(f));
  }
  return frames;
}

// One Monte Carlo session: the holder, the rendering effects and the tool
// poses of the layout session (40 views) and of the pivot session (32).
struct McSession {
  Target truth;
  RenderOptions effects;
  std::vector<Rigid3> views, pivot;
};

// `noise_free`: without sensor noise and JPEG (only the detector's bias
// remains; the benches' --noise-free).
inline McSession MakeSession(int seed, bool plain, std::mt19937_64* rng,
                             bool noise_free = false) {
  std::uniform_real_distribution<double> u(0, 2 * M_PI);
  McSession s;
  s.truth = RandomHolder(2 + seed % 3, rng);
  s.effects = WidenedEffects(rng);
  if (plain) {
    s.effects = RenderOptions();
    s.effects.blur_sigma_px = 0.5;
    s.effects.noise_sigma = 1.5;
  }
  if (noise_free) {
    s.effects.noise_sigma = 0;
    s.effects.jpeg_quality = 0;
  }
  const double phase_a = u(*rng), phase_b = u(*rng);
  for (int i = 0; i < 40; ++i) {
    s.views.push_back(TiltedAbout(
        ExampleToolPose(i + 7 * seed), 25 * std::sin(0.9 * i + phase_a),
        30 * std::cos(0.6 * i + phase_b), Eigen::Vector3d::Zero()));
  }
  const Rigid3 mid = ExampleToolPose(seed);
  for (int i = 0; i < 32; ++i) {
    // Two circles about the tip, +-25 and +-12 deg.
    const double a = 2 * M_PI * i / 16 + phase_a, tilt = i < 16 ? 25 : 12;
    s.pivot.push_back(TiltedAbout(mid, tilt * std::sin(a), tilt * std::cos(a),
                                  s.truth.tip_in_tool));
  }
  return s;
}

inline McTrial RunTargetTrial(
    int seed, LayoutCovariance model = LayoutCovariance::kTagObservations,
    bool plain = false) {
  const auto start = std::chrono::steady_clock::now();
  std::mt19937_64 rng(1000 + seed);
  const Rig rig = ExampleStereoRig(640, 512);
  const McSession session = MakeSession(seed, plain, &rng);
  const Target& truth = session.truth;
  const RenderOptions& effects = session.effects;
  const std::vector<Rigid3>& views = session.views;
  const std::vector<Rigid3>& pivot = session.pivot;
  CornerErrors corner_errors;
  const std::vector<LayoutFrame> view_frames =
      RenderAndDetect(rig, truth, views, effects, &rng, &corner_errors);
  const std::vector<LayoutFrame> pivot_frames =
      RenderAndDetect(rig, truth, pivot, effects, &rng, &corner_errors);

  TargetLayoutOptions options;
  options.family = truth.family;
  options.tag_size_mm = truth.tags[0].size_mm;
  options.covariance = model;
  const TargetLayoutResult layout =
      MeasureTargetLayout(rig, view_frames, options);
  const PivotTipResult tip =
      MeasurePivotTip(rig, layout, pivot_frames, PivotTipOptions());

  McTrial trial;
  trial.tags = static_cast<int>(truth.tags.size());
  trial.views = layout.views_used;
  trial.pivot_views = tip.views;
  const TargetTag* true_ref = truth.FindTag(layout.reference_tag_id);
  const Rigid3 ref_from_tool = true_ref->tool_from_tag.Inverse();
  for (const LayoutTag& tag : layout.tags) {
    if (tag.id == layout.reference_tag_id) continue;
    const Rigid3 want = ref_from_tool * truth.FindTag(tag.id)->tool_from_tag;
    const Eigen::Vector3d dt = tag.tool_from_tag.t - want.t;
    const Eigen::Vector3d dr =
        RotationVectorFromMatrix(tag.tool_from_tag.R * want.R.transpose()) *
        180 / M_PI;
    trial.max_t_mm = std::max(trial.max_t_mm, dt.norm());
    trial.max_r_deg = std::max(trial.max_r_deg, dr.norm());
    for (int k = 0; k < 3; ++k) {
      trial.z_t.push_back(dt(k) / tag.sigma_t_mm(k));
      trial.z_r.push_back(dr(k) / tag.sigma_r_deg(k));
    }
  }
  const Eigen::Vector3d tip_error =
      tip.pivot.tip_in_tool - ref_from_tool * truth.tip_in_tool;
  trial.tip_mm = tip_error.norm();
  for (int k = 0; k < 3; ++k) {
    trial.z_tip.push_back(tip_error(k) / tip.tip_sigma_mm(k));
  }
  trial.tip_sigma_mm = tip.tip_sigma_mm.norm();
  trial.tip_layout_sigma_mm = tip.layout_sigma_mm.norm();
  trial.tip_pivot_sigma_mm = tip.pivot.tip_sigma_mm.norm();
  trial.corner_offset_sigma_mm = tip.corner_offset_sigma_mm;
  trial.tip_systematic_sigma_mm = tip.systematic_sigma_mm.norm();
  trial.effects = effects;
  trial.corner_rms_px = std::sqrt(corner_errors.sum_sq / corner_errors.n);
  trial.max_tag_offset_px = corner_errors.max_offset;
  trial.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
          .count();
  return trial;
}

// The arguments of the per-seed benches: [--plain] [--noise-free] SEED...
struct SeedArgs {
  bool ok = true;  // false: a usage message went to stderr
  bool plain = false, noise_free = false;
  std::vector<int> seeds;
};

inline SeedArgs ParseSeedArgs(int argc, char** argv, const std::string& name) {
  SeedArgs a;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--plain")) {
      a.plain = true;
    } else if (!std::strcmp(argv[i], "--noise-free")) {
      a.noise_free = true;
    } else if (std::atoi(argv[i]) > 0) {
      a.seeds.push_back(std::atoi(argv[i]));
    } else {
      std::fprintf(stderr, "usage: %s [--plain] [--noise-free] SEED...\n",
                   name.c_str());
      a.ok = false;
      return a;
    }
  }
  return a;
}

inline double RmsOf(const std::vector<double>& v) {
  double sum = 0;
  for (double x : v) sum += x * x;
  return v.empty() ? 0 : std::sqrt(sum / v.size());
}

}  // namespace kincal::testing

#endif  // KINCAL_TESTS_TARGET_MONTE_CARLO_H_
