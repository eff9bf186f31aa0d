// Vision figures on rendered 1280x1024 stereo frames of the example tool
// (vision/render.h): corner RMS per refinement, tip error against the stereo
// depth bound sigma_Z = Z^2 sigma_d / (f B), and stereo pairs per second with
// tracking against plain full-frame libapriltag (Google Benchmark).
//
//   build/bin/vision_bench [--frames N] [benchmark flags]

#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <random>
#include <thread>
#include <vector>

#include "synth/render.h"
#include "vision/tool_pose.h"
#include "vision/tracker.h"

namespace kincal {
namespace {

constexpr int kWidth = 1280, kHeight = 1024;

struct Scene {
  Rig rig = ExampleStereoRig(kWidth, kHeight);
  Target target = ExampleTarget();
};

const Scene& GetScene() {
  static const Scene scene;
  return scene;
}

RenderOptions Realistic() {
  RenderOptions o;
  o.blur_sigma_px = 0.8;
  o.noise_sigma = 2.0;
  o.exposure_jitter = 0.05;
  return o;
}

struct CornerStats {
  double sum_sq = 0;
  int n = 0, expected = 0, found = 0;
  double Rms() const { return n ? std::sqrt(sum_sq / n) : 0; }
};

void Accumulate(const std::vector<TagDetection>& dets,
                const std::vector<TagTruth>& truth, CornerStats* s) {
  for (const TagTruth& t : truth) {
    if (!t.visible) continue;
    ++s->expected;
    for (const TagDetection& d : dets) {
      if (d.id != t.id) continue;
      ++s->found;
      for (int k = 0; k < 4; ++k) {
        s->sum_sq += (d.corners[k] - t.corners[k]).squaredNorm();
        ++s->n;
      }
    }
  }
}

void AccuracyFigures(int frames) {
  const Scene& scene = GetScene();
  const char* names[3] = {"edges (kincal default)", "libapriltag corners",
                          "cv::cornerSubPix"};
  const CornerRefinement kinds[3] = {CornerRefinement::kEdges,
                                     CornerRefinement::kNone,
                                     CornerRefinement::kCornerSubPix};
  for (int noisy = 0; noisy < 2; ++noisy) {
    RenderOptions o = noisy ? Realistic() : RenderOptions();
    if (!noisy) o.blur_sigma_px = 0.5;
    StereoRenderer renderer(scene.rig, scene.target, o);
    std::mt19937_64 rng(1);
    CornerStats stats[3];
    std::vector<double> tip_err, tip_dz;
    double depth_sum = 0;
    for (int i = 0; i < frames; ++i) {
      const StereoFrameTruth f = renderer.Render(ExampleToolPose(i), &rng);
      std::vector<std::vector<TagDetection>> dets(2);
      for (int r = 0; r < 3; ++r) {
        AprilTagOptions d;
        d.refinement = kinds[r];
        AprilTagDetector detector(d);
        for (size_t c = 0; c < f.views.size(); ++c) {
          auto found = detector.Detect(f.views[c].image);
          Accumulate(found, f.views[c].tags, &stats[r]);
          if (r == 0) dets[c] = found;
        }
      }
      const ToolPoseResult pose =
          EstimateToolPose(scene.rig, scene.target, dets);
      if (!pose.found) continue;
      tip_err.push_back((pose.tip_in_rig - f.tip_in_rig).norm());
      tip_dz.push_back(pose.tip_in_rig.z() - f.tip_in_rig.z());
      depth_sum += f.tip_in_rig.z();
    }
    std::printf(
        "\n%s renders (1280x1024, blur %.1f px, noise %.1f, %d stereo "
        "frames):\n",
        noisy ? "Realistic" : "Clean", o.blur_sigma_px, o.noise_sigma, frames);
    for (int r = 0; r < 3; ++r) {
      std::printf("  corner RMS %-24s %.4f px  (%d/%d tags)\n", names[r],
                  stats[r].Rms(), stats[r].found, stats[r].expected);
    }
    if (tip_err.empty()) continue;
    double se = 0, sz = 0;
    for (size_t i = 0; i < tip_err.size(); ++i) {
      se += tip_err[i] * tip_err[i];
      sz += tip_dz[i] * tip_dz[i];
    }
    const double Z = depth_sum / tip_err.size();
    const double f_px = scene.rig.cameras[0].intrinsics.fx;
    const double B = scene.rig.BaselineMm();
    // Disparity sigma from the measured corners: per-coordinate sigma is
    // RMS / sqrt(2), the disparity (difference of two) sqrt(2) times that.
    const double sigma_d = stats[0].Rms();
    const double sigma_z = Z * Z * sigma_d / (f_px * B);
    std::printf(
        "  tip: RMS 3D %.4f mm, RMS depth %.4f mm; stereo bound "
        "sigma_Z = Z^2 sigma_d/(f B) = %.0f^2 * %.4f / (%.0f * %.1f) "
        "= %.4f mm; depth RMS / sigma_Z = %.2f\n",
        std::sqrt(se / tip_err.size()), std::sqrt(sz / tip_err.size()), Z,
        sigma_d, f_px, B, sigma_z, std::sqrt(sz / tip_err.size()) / sigma_z);
  }
  std::printf("\n");
}

// A smooth 40-frame sequence, rendered once.
struct Sequence {
  std::vector<std::array<cv::Mat, 2>> pairs;
  Sequence() {
    const Scene& scene = GetScene();
    StereoRenderer renderer(scene.rig, scene.target, Realistic());
    std::mt19937_64 rng(2);
    for (int i = 0; i < 40; ++i) {
      Rigid3 pose = ExampleToolPose(0);
      pose.t += Eigen::Vector3d(2.0 * std::sin(0.2 * i) * 10, 1.5 * i - 30,
                                5 * std::cos(0.1 * i));
      pose.R = pose.R * Eigen::AngleAxisd(0.01 * i, Eigen::Vector3d::UnitY())
                            .toRotationMatrix();
      const StereoFrameTruth f = renderer.Render(pose, &rng);
      pairs.push_back({f.views[0].image, f.views[1].image});
    }
  }
};
const Sequence& GetSequence() {
  static const Sequence s;
  return s;
}

// Both cameras in parallel (one thread each), then the tool pose.
void BM_TrackStereo(benchmark::State& state) {
  const Scene& scene = GetScene();
  const Sequence& seq = GetSequence();
  TrackerOptions o;
  o.enabled = state.range(0) != 0;
  TrackerOptions left_options = o, right_options = o;
  left_options.detector.lens = scene.rig.cameras[0].intrinsics;
  right_options.detector.lens = scene.rig.cameras[1].intrinsics;
  TagTracker left(left_options), right(right_options);
  size_t i = 0;
  int found = 0;
  for (auto _ : state) {
    const auto& pair = seq.pairs[i++ % seq.pairs.size()];
    std::vector<std::vector<TagDetection>> dets(2);
    std::thread t([&] { dets[1] = right.Track(pair[1]); });
    dets[0] = left.Track(pair[0]);
    t.join();
    const ToolPoseResult r = EstimateToolPose(scene.rig, scene.target, dets);
    found += r.found;
    benchmark::DoNotOptimize(r);
  }
  state.SetItemsProcessed(state.iterations());  // stereo pairs
  state.counters["found_ratio"] =
      static_cast<double>(found) / static_cast<double>(state.iterations());
  state.counters["full_searches"] = left.full_searches();
}
BENCHMARK(BM_TrackStereo)
    ->ArgName("tracking")
    ->Arg(1)
    ->Arg(0)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// Plain libapriltag on the full frames (its corners, no refinement, no pose),
// both cameras in parallel.
void BM_PlainLibapriltagStereo(benchmark::State& state) {
  const Sequence& seq = GetSequence();
  AprilTagOptions o;
  o.refinement = CornerRefinement::kNone;
  AprilTagDetector left(o), right(o);
  size_t i = 0;
  for (auto _ : state) {
    const auto& pair = seq.pairs[i++ % seq.pairs.size()];
    std::vector<TagDetection> a, b;
    std::thread t([&] { b = right.Detect(pair[1]); });
    a = left.Detect(pair[0]);
    t.join();
    benchmark::DoNotOptimize(a);
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_PlainLibapriltagStereo)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

void BM_RenderStereo640(benchmark::State& state) {
  const Rig rig = ExampleStereoRig(640, 512);
  StereoRenderer renderer(rig, ExampleTarget(), Realistic());
  std::mt19937_64 rng(3);
  int i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(renderer.Render(ExampleToolPose(i++), &rng));
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_RenderStereo640)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace kincal

int main(int argc, char** argv) {
  int frames = 20;
  std::vector<char*> rest;
  for (int i = 0; i < argc; ++i) {
    if (std::strcmp(argv[i], "--frames") == 0 && i + 1 < argc) {
      frames = std::atoi(argv[++i]);
    } else {
      rest.push_back(argv[i]);
    }
  }
  int n = static_cast<int>(rest.size());
  benchmark::Initialize(&n, rest.data());
  kincal::AccuracyFigures(frames);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
