// Bundle time vs frames: BH-7, the three-tag holder seen by both cameras of
// the example rig (1280x1024), 0.1 px corner noise, every tag in view (3 tags
// x 2 cameras x 4 corners = 24 corners per frame). The time is RunBundle's:
// hand-eye start, identifiability on the pixel Jacobian, the fits with the
// outlier pass, covariance and held-out statistics (tag detection is not
// included: it is vision_bench's). Target: 500 frames <= 3 s, ~linear.
// Run: build/bin/bundle_bench

#include <benchmark/benchmark.h>

#include <cstdio>
#include <map>
#include <utility>

#include "bundle/bundle.h"
#include "bundle/testing/synthetic.h"
#include "data/robot.h"

namespace kincal {
namespace {

const SyntheticBundle& Data(int frames, int cameras = 2) {
  static std::map<std::pair<int, int>, SyntheticBundle> cache;
  auto it = cache.find({frames, cameras});
  if (it == cache.end()) {
    SyntheticBundleOptions o;
    o.frames = frames;
    o.cameras = cameras;
    o.noise_px = 0.1;
    o.seed = 42;
    it = cache
             .emplace(std::make_pair(frames, cameras),
                      MakeSyntheticBundle(
                          ReadRobotYaml(std::string(KINCAL_SOURCE_DIR) +
                                        "/data/robots/bh7.yaml"),
                          o))
             .first;
  }
  return it->second;
}

// Times RunBundle on `s` and reports the problem's size and fit.
void TimeBundle(benchmark::State& state, const SyntheticBundle& s,
                const BundleOptions& o) {
  BundleResult r;
  for (auto _ : state) {
    r = RunBundle(s.nominal, s.rig, s.target, s.frames, o);
    benchmark::DoNotOptimize(r);
  }
  int corners = 0;
  for (const BundleFrame& f : s.frames) {
    corners += static_cast<int>(f.corners.size());
  }
  state.counters["frames"] = static_cast<double>(s.frames.size());
  state.counters["cameras"] = static_cast<double>(s.rig.cameras.size());
  state.counters["corners"] = corners;
  state.counters["reproj_px"] = r.reproj_rms_px;
  state.counters["iterations"] = r.iterations;
}

void BM_Bundle(benchmark::State& state) {
  BundleOptions o;
  o.refine_cameras = state.range(1) != 0;
  TimeBundle(state, Data(static_cast<int>(state.range(0))), o);
}
BENCHMARK(BM_Bundle)
    ->Args({125, 0})
    ->Args({250, 0})
    ->Args({500, 0})
    ->Args({1000, 0})
    ->Args({500, 1})
    ->Unit(benchmark::kMillisecond)
    ->Iterations(2);

// The same with one and three cameras on the stand (format v3; three:
// the stereo pair and "top", synth/rig_placement.h). Target: 500 frames x 3
// cameras <= 3 s, linear in frames.
void BM_BundleCameras(benchmark::State& state) {
  TimeBundle(
      state,
      Data(static_cast<int>(state.range(0)), static_cast<int>(state.range(1))),
      BundleOptions());
}
BENCHMARK(BM_BundleCameras)
    ->Args({250, 1})
    ->Args({500, 1})
    ->Args({250, 3})
    ->Args({500, 3})
    ->Args({1000, 3})
    ->Unit(benchmark::kMillisecond)
    ->Iterations(2);

}  // namespace
}  // namespace kincal

BENCHMARK_MAIN();
