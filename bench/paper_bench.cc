// The seed's eq. (9) (derivative-free direct search) vs the least-squares
// form (Ceres LM, one unknown point per label) on the same simulated
// single-point BH-7 data: time and eps side by side; and the UR10 real-data
// calibration time (series C). Figures are printed as benchmark counters:
//   eps_mm, eps_max_mm, eps_std_mm (Table 2's footer, training poses),
//   heldout_rms_mm, evaluations (objective evaluations / LM iterations).

#include <benchmark/benchmark.h>
#include <sys/stat.h>

#include <map>

#include "calib/calibrate.h"
#include "synth/simulate.h"
#include "data/import_ipa.h"
#include "data/robot.h"

namespace kincal {
namespace {

const SimulatedSession& SinglePoint(int points) {
  static std::map<int, SimulatedSession> cache;
  auto it = cache.find(points);
  if (it != cache.end()) return it->second;
  SimulateOptions opt;
  opt.mode = SimulateOptions::kFixedPoint;
  opt.fixed_points = points;
  opt.poses_per_point = 60;
  opt.measure_points = false;
  opt.noise_mm = 0.03;
  opt.seed = 5;
  return cache[points] = Simulate(ReadRobotYaml(std::string(KINCAL_SOURCE_DIR) +
                                                "/data/robots/bh7.yaml"),
                                  opt);
}

void Report(benchmark::State& state, const CalibrateResult& r) {
  state.counters["eps_mm"] = r.epsilon.mean_mm;
  state.counters["eps_max_mm"] = r.epsilon.max_mm;
  state.counters["eps_std_mm"] = r.epsilon.std_mm;
  state.counters["heldout_rms_mm"] = r.heldout.rms_mm;
  state.counters["evaluations"] = r.fit.iterations;
  state.counters["robot_params"] = static_cast<double>(
      r.identifiability.identifiable.size() - 3 * r.state.point_labels.size());
}

void BM_SinglePoint(benchmark::State& state, CalibrateOptions::Method method) {
  const SimulatedSession& s = SinglePoint(static_cast<int>(state.range(0)));
  CalibrateOptions opt;
  opt.method = method;
  CalibrateResult r;
  for (auto _ : state) {
    r = Calibrate(s.nominal, s.observations, opt);
    benchmark::DoNotOptimize(r);
  }
  Report(state, r);
}

void BM_PaperMethod(benchmark::State& state) {
  BM_SinglePoint(state, CalibrateOptions::kPaper);
}
void BM_LeastSquares(benchmark::State& state) {
  BM_SinglePoint(state, CalibrateOptions::kLeastSquares);
}
BENCHMARK(BM_PaperMethod)
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->Iterations(3);
BENCHMARK(BM_LeastSquares)
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->Iterations(3);

// UR10, 2773 real poses of series C, 20 % held out, 23 parameters.
void BM_Ur10CalibrateSeriesC(benchmark::State& state) {
  const std::string path =
      std::string(KINCAL_SHARED_DATA_DIR) +
      "/ipa-robot-accuracy/Series_C/measurements_random_poses.csv";
  struct stat st;
  if (::stat(path.c_str(), &st) != 0) {
    state.SkipWithError(
        "shared data absent: ../shared/data/ipa-robot-accuracy");
    return;
  }
  const Observations c = ReadIpaSeries(path).observations;
  const Robot ur10 =
      ReadRobotYaml(std::string(KINCAL_SOURCE_DIR) + "/data/robots/ur10.yaml");
  CalibrateResult r;
  for (auto _ : state) {
    r = Calibrate(ur10, c, {});
    benchmark::DoNotOptimize(r);
  }
  state.counters["heldout_rms_mm"] = r.heldout.rms_mm;
  state.counters["train_rms_mm"] = r.train.rms_mm;
  state.counters["fit_s"] = r.fit.seconds;
}
BENCHMARK(BM_Ur10CalibrateSeriesC)
    ->Unit(benchmark::kMillisecond)
    ->Iterations(2);

}  // namespace
}  // namespace kincal

BENCHMARK_MAIN();
