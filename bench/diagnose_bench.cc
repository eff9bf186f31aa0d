// Figures of the diagnosis (quoted in docs/DIAGNOSE.md). Prints:
//   1. time of `diagnose model` (the full candidate sweep and selection) on
//      240 poses, median of repeated runs;
//   2. the smallest backlash in j3 found reliably at 0.03 mm noise, 240 poses;
//   3. the false-alarm rate of `diagnose model` on null data;
//   4. the seed's Section 4 clearance test: false-positive rate without
//      clearance and hit rate with clearance in j3.
//   5. (--only ur10) the UR10 series C timing, reference vs free-parameter
//      refits, 240 and 2773 poses.
// Usage: diagnose_bench [--runs N] (N seeds per rate, default 40).

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <fstream>
#include <string>
#include <vector>

#include "calib/calibrate.h"
#include "data/import_ipa.h"
#include "data/robot.h"
#include "diagnose/clearance.h"
#include "diagnose/model_diagnosis.h"
#include "synth/simulate.h"

namespace kincal {
namespace {

Robot Bh7() {
  return ReadRobotYaml(std::string(KINCAL_SOURCE_DIR) +
                       "/data/robots/bh7.yaml");
}

SimulatedSession Sim(const Robot& robot,
                     const std::vector<std::string>& effects, uint64_t seed,
                     int poses, double noise) {
  SimulateOptions so;
  so.poses = poses;
  so.noise_mm = noise;
  so.seed = seed;
  for (const std::string& e : effects)
    so.effects.push_back(ParseEffect(e, robot));
  return Simulate(robot, so);
}

double Seconds(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
      .count();
}

void Timing(const Robot& bh7) {
  std::printf("== timing: diagnose model, BH-7, 240 poses, 0.03 mm noise\n");
  for (const std::string& effect :
       {std::string(""), std::string("backlash:j3:0.1")}) {
    std::vector<double> t;
    int candidates = 0, steps = 0;
    for (int run = 0; run < 5; ++run) {
      const SimulatedSession s =
          Sim(bh7,
              effect.empty() ? std::vector<std::string>{}
                             : std::vector<std::string>{effect},
              900 + run, 240, 0.03);
      const auto start = std::chrono::steady_clock::now();
      const DiagnosisResult r = DiagnoseModel(s.nominal, s.observations, {});
      t.push_back(Seconds(start));
      candidates = static_cast<int>(r.steps[0].size());
      steps = static_cast<int>(r.steps.size());
    }
    std::sort(t.begin(), t.end());
    std::printf(
        "  %-18s median %.3f s (min %.3f, max %.3f), %d candidates, %d steps\n",
        effect.empty() ? "null" : effect.c_str(), t[2], t[0], t[4], candidates,
        steps);
  }
}

// UR10 series C (../shared/data), if present: wall and CPU time of the full
// diagnosis at 2773 and at 240 poses, with the free-parameter refits and
// with the reference path (calib/fit.h Fit for every candidate), and with
// the catalogue of today (spec causes + harmonics) and the full one.
void Ur10Timing() {
  const std::string dir =
      std::string(KINCAL_SOURCE_DIR) + "/../shared/data/ipa-robot-accuracy/";
  const std::string file = dir + "Series_C/measurements_random_poses.csv";
  if (!std::ifstream(file)) {
    std::printf("== ur10: %s absent, skipped\n", file.c_str());
    return;
  }
  const Robot ur10 =
      ReadRobotYaml(std::string(KINCAL_SOURCE_DIR) + "/data/robots/ur10.yaml");
  const Observations all = ReadIpaSeries(file, ur10.JointNames()).observations;
  std::vector<int> first;
  for (int i = 0; i < 240; ++i) first.push_back(i * 11);
  const Observations small = Subset(all, first);
  const std::vector<std::string> today = {"backlash", "compliance", "cyclic",
                                          "gain",     "axis_tilt",  "drift"};
  std::printf("== ur10 series C: diagnose model, wall / CPU seconds\n");
  for (const Observations* obs : {&small, &all}) {
    for (int catalogue = 0; catalogue < 2; ++catalogue) {
      for (int fast = 0; fast < 2; ++fast) {
        DiagnoseOptions o;
        if (catalogue == 0) o.causes = today;
        o.free_parameter_fit = fast == 1;
        const auto start = std::chrono::steady_clock::now();
        const std::clock_t c0 = std::clock();
        const DiagnosisResult r = DiagnoseModel(ur10, *obs, o);
        const double cpu = double(std::clock() - c0) / CLOCKS_PER_SEC;
        std::printf(
            "  %4zu poses, %-8s catalogue, %-14s refits: %6.2f s wall, "
            "%6.2f s CPU, held-out %.4f -> %.4f mm\n",
            obs->rows.size(), catalogue == 0 ? "today's" : "full",
            fast ? "free-parameter" : "reference", Seconds(start), cpu,
            r.nominal_heldout_rms_mm, r.final_heldout_rms_mm);
      }
    }
  }
}

void SmallestBacklash(const Robot& bh7, int runs) {
  std::printf(
      "== smallest backlash in j3, 240 poses, 0.03 mm noise, %d seeds each\n",
      runs);
  for (double b : {0.01, 0.015, 0.02, 0.03, 0.05}) {
    int named = 0, within = 0;
    for (int run = 0; run < runs; ++run) {
      char effect[64];
      std::snprintf(effect, sizeof(effect), "backlash:j3:%g", b);
      const SimulatedSession s = Sim(bh7, {effect}, 2000 + run, 240, 0.03);
      const DiagnosisResult r = DiagnoseModel(s.nominal, s.observations, {});
      if (!r.findings.empty() && r.findings[0].cause == "backlash" &&
          r.findings[0].joint == "j3") {
        ++named;
        if (std::abs(r.findings[0].magnitude - b) <= 0.25 * b) ++within;
      }
    }
    std::printf("  b = %.3f deg: named %d/%d, magnitude within 25%% %d/%d\n", b,
                named, runs, within, runs);
  }
}

void FalseAlarms(const Robot& bh7, int runs) {
  std::printf(
      "== false alarms of diagnose model on null data (%d seeds each)\n", runs);
  for (int poses : {60, 240}) {
    for (double noise : {0.01, 0.05}) {
      int alarms = 0;
      for (int run = 0; run < runs; ++run) {
        const SimulatedSession s = Sim(bh7, {}, 3000 + run, poses, noise);
        const DiagnosisResult r = DiagnoseModel(s.nominal, s.observations, {});
        if (r.verdict != "no_significant_effect") ++alarms;
      }
      std::printf("  %3d poses, noise %.2f mm: %d/%d false alarms (%.1f %%)\n",
                  poses, noise, alarms, runs, 100.0 * alarms / runs);
    }
  }
}

// nominal_robot: give the test the nominal robot, else one calibrated on the
// same data; calibrate_first: the test's own default (calibrate the
// geometry first) instead of using the robot as given.
void Section4(const Robot& bh7, int runs, bool nominal_robot,
              bool calibrate_first) {
  std::printf(
      "== Section 4 clearance test (%s geometry, %s, 120 poses, 0.03 mm)\n",
      nominal_robot ? "nominal" : "calibrated",
      calibrate_first ? "default: calibrates first" : "--no-calibrate");
  for (double b : {0.0, 0.05, 0.1, 0.3, 1.0}) {
    int suspect_any = 0, suspect_j3 = 0;
    for (int run = 0; run < runs; ++run) {
      char effect[64];
      std::snprintf(effect, sizeof(effect), "backlash:j3:%g", b);
      const SimulatedSession s = Sim(
          bh7,
          b > 0 ? std::vector<std::string>{effect} : std::vector<std::string>{},
          4000 + run, 120, 0.03);
      CalibrateOptions co;
      co.holdout_fraction = 0.0;
      const Robot cal =
          nominal_robot ? s.nominal
                        : Calibrate(s.nominal, s.observations, co).calibrated;
      ClearanceOptions options;
      options.calibrate_geometry = calibrate_first;
      const ClearanceResult r = DiagnoseClearance(cal, s.observations, options);
      if (r.suspect >= 0) ++suspect_any;
      if (r.suspect == 2) ++suspect_j3;
    }
    if (b == 0) {
      std::printf(
          "  no clearance: a suspect named in %d/%d (false positives %.0f "
          "%%)\n",
          suspect_any, runs, 100.0 * suspect_any / runs);
    } else {
      std::printf(
          "  clearance %.2f deg in j3: j3 named %d/%d, any suspect %d/%d\n", b,
          suspect_j3, runs, suspect_any, runs);
    }
  }
}

}  // namespace
}  // namespace kincal

int main(int argc, char** argv) {
  int runs = 40;
  std::string only;
  for (int i = 1; i + 1 < argc; ++i) {
    if (std::strcmp(argv[i], "--runs") == 0) runs = std::atoi(argv[i + 1]);
    if (std::strcmp(argv[i], "--only") == 0) only = argv[i + 1];
  }
  const kincal::Robot bh7 = kincal::Bh7();
  if (only.empty() || only == "timing") kincal::Timing(bh7);
  if (only == "ur10") kincal::Ur10Timing();
  if (only.empty() || only == "backlash") kincal::SmallestBacklash(bh7, runs);
  if (only.empty() || only == "null") kincal::FalseAlarms(bh7, runs);
  if (only.empty() || only == "section4") {
    kincal::Section4(bh7, runs, false, false);
    kincal::Section4(bh7, runs, true, false);
    kincal::Section4(bh7, runs, true, true);
  }
  return 0;
}
