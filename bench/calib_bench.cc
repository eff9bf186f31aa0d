// Calibration speed on a simulated BH-7 session (240 poses, 0.03 mm noise per
// axis), the target: < 50 ms per calibrate, held-out RMS <= 0.06 mm.
// Run: build/bin/calib_bench

#include <benchmark/benchmark.h>

#include <cstdio>

#include "calib/calibrate.h"
#include "synth/simulate.h"
#include "data/robot.h"

namespace kincal {
namespace {

const SimulatedSession& Session() {
  static const SimulatedSession s = [] {
    SimulateOptions opt;
    opt.poses = 240;
    opt.noise_mm = 0.03;
    opt.seed = 3;
    return Simulate(
        ReadRobotYaml(std::string(KINCAL_SOURCE_DIR) + "/data/robots/bh7.yaml"),
        opt);
  }();
  return s;
}

void BM_CalibrateBh7(benchmark::State& state) {
  const SimulatedSession& s = Session();
  CalibrateResult r;
  for (auto _ : state) {
    r = Calibrate(s.nominal, s.observations, CalibrateOptions{});
    benchmark::DoNotOptimize(r);
  }
  state.counters["heldout_rms_mm"] = r.heldout.rms_mm;
  state.counters["fit_ms"] = r.fit.seconds * 1e3;
}
BENCHMARK(BM_CalibrateBh7)->Unit(benchmark::kMillisecond);

void BM_FitOnly(benchmark::State& state) {
  const SimulatedSession& s = Session();
  const bool covariance = state.range(0) != 0;
  ModelState base;
  base.chain = Chain::FromRobot(s.nominal);
  const auto ms = MakeMeasurements(base.chain, s.observations, &base);
  InitializeFrameAndPoints(ms, &base);
  FitOptions opt;
  opt.free = FrameParams();
  for (const auto& p : GeometryParams(base.chain)) {
    if (p.name == "j2.a" || p.name == "j3.a" || p.name == "tool.d" ||
        p.name == "j5.theta" || p.name == "j4.alpha")
      opt.free.push_back(p);
  }
  opt.compute_covariance = covariance;
  for (auto _ : state) {
    ModelState m = base;
    FitSummary f = Fit(ms, opt, &m);
    benchmark::DoNotOptimize(f);
  }
}
BENCHMARK(BM_FitOnly)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace kincal

BENCHMARK_MAIN();
