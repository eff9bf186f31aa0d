// Figures of the diagnosis (quoted in docs/DIAGNOSE.md). Prints:
//   1. time of `diagnose model` (the full candidate sweep and selection) on
//      240 poses, median of repeated runs;
//   2. the smallest backlash in j3 found reliably at 0.03 mm noise, 240 poses;
//   3. the false-alarm rate of `diagnose model` on null data;
//   4. the seed's Section 4 clearance test: false-positive rate without
//      clearance and hit rate with clearance in j3.
//   5. (--only ur10) the UR10 series C timing at 240 and 2773 poses
//      (--repeat R runs each, median; default 3); (--only ur10-240: the 240
//      poses only); (--only ur10-abc) series A every 4th row, B and C
//      together, one measuring frame per series (7246 poses);
//   6. (--only cv) k-fold cross-validation of the selection on UR10 series
//      C (240 and 2773 poses): time and findings with the single held-out
//      split (--folds 0), 5 and 10 folds (linearised fold fits) and 5 folds
//      with full refits per fold, and how far the linearised
//      cross-validated RMS is from the refitted one; (--only cv-sim) naming
//      rates of marginal simulated effects and false alarms on null data,
//      single split against k folds (--runs N seeds each).
// Usage: diagnose_bench [--runs N] (N seeds per rate, default 40).

#include <malloc.h>

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

double CpuSeconds() {
  timespec ts;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

// One diagnosis timed: wall and process CPU seconds.
DiagnosisResult Timed(const Robot& robot, const Observations& obs,
                      const DiagnoseOptions& o, double* wall, double* cpu) {
  const auto start = std::chrono::steady_clock::now();
  const double c0 = CpuSeconds();
  DiagnosisResult r = DiagnoseModel(robot, obs, o);
  *cpu = CpuSeconds() - c0;
  *wall = Seconds(start);
  return r;
}

// `runs` diagnoses timed: the last one's result, the median wall and CPU
// seconds.
struct MedianTiming {
  DiagnosisResult result;
  double wall = 0, cpu = 0;
};
MedianTiming TimedMedian(const Robot& robot, const Observations& obs,
                         const DiagnoseOptions& o, int runs) {
  MedianTiming out;
  std::vector<double> walls, cpus;
  for (int run = 0; run < runs; ++run) {
    double wall = 0, cpu = 0;
    out.result = Timed(robot, obs, o, &wall, &cpu);
    walls.push_back(wall);
    cpus.push_back(cpu);
  }
  std::sort(walls.begin(), walls.end());
  std::sort(cpus.begin(), cpus.end());
  out.wall = walls[runs / 2];
  out.cpu = cpus[runs / 2];
  return out;
}

// UR10 series C from ../shared/data and its every 11th pose (240); false
// (with a line saying so) when the data are absent.
bool LoadUr10SeriesC(const char* tag, Robot* ur10, Observations* all,
                     Observations* small) {
  const std::string file = std::string(KINCAL_SOURCE_DIR) +
                           "/../shared/data/ipa-robot-accuracy/Series_C/"
                           "measurements_random_poses.csv";
  if (!std::ifstream(file)) {
    std::printf("== %s: %s absent, skipped\n", tag, file.c_str());
    return false;
  }
  *ur10 =
      ReadRobotYaml(std::string(KINCAL_SOURCE_DIR) + "/data/robots/ur10.yaml");
  *all = ReadIpaSeries(file, ur10->JointNames()).observations;
  std::vector<int> first;
  for (int i = 0; i < 240; ++i) first.push_back(i * 11);
  *small = Subset(*all, first);
  return true;
}

// UR10 series C (../shared/data), if present: wall and CPU seconds of the
// full diagnosis (default options, full catalogue) at 240 and 2773 poses,
// medians of `repeat` runs.
void Ur10Timing(int repeat, bool small_only) {
  Robot ur10;
  Observations all, small;
  if (!LoadUr10SeriesC("ur10", &ur10, &all, &small)) return;
  std::printf(
      "== ur10 series C: diagnose model (default options), median of %d, "
      "wall / process CPU seconds (2 threads)\n",
      repeat);
  for (const Observations* obs : {&small, &all}) {
    if (small_only && obs == &all) break;
    const MedianTiming t = TimedMedian(ur10, *obs, DiagnoseOptions{}, repeat);
    std::printf(
        "  %4zu poses: %6.2f s wall, %6.2f s CPU, held-out %.4f -> %.4f mm\n",
        obs->rows.size(), t.wall, t.cpu, t.result.nominal_heldout_rms_mm,
        t.result.final_heldout_rms_mm);
  }
}

// UR10 series A (every 4th row), B and C (../shared/data), each row
// labelled with its series (one measuring frame each), as `kincal import
// ipa-ur10 --every 4 --series A` etc. concatenate them: wall and CPU
// seconds of the full diagnosis, median of `repeat` runs.
void Ur10AbcTiming(int repeat) {
  const std::string dir =
      std::string(KINCAL_SOURCE_DIR) + "/../shared/data/ipa-robot-accuracy/";
  const std::vector<std::pair<std::string, std::string>> files = {
      {"A", "Series_A/measurements_grid.csv"},
      {"B", "Series_B/measurements_joint_configurations.csv"},
      {"C", "Series_C/measurements_random_poses.csv"}};
  const Robot ur10 =
      ReadRobotYaml(std::string(KINCAL_SOURCE_DIR) + "/data/robots/ur10.yaml");
  Observations abc;
  for (const auto& [name, file] : files) {
    if (!std::ifstream(dir + file)) {
      std::printf("== ur10-abc: %s absent, skipped\n", (dir + file).c_str());
      return;
    }
    const Observations one =
        ReadIpaSeries(dir + file, ur10.JointNames()).observations;
    if (abc.rows.empty()) {
      abc = one;
      abc.rows.clear();
    }
    const int every = name == "A" ? 4 : 1;
    for (size_t i = 0; i < one.rows.size(); i += every) {
      Observation o = one.rows[i];
      o.series = name;
      o.pose = name + "-" + o.pose;
      abc.rows.push_back(o);
    }
  }
  const MedianTiming t = TimedMedian(ur10, abc, DiagnoseOptions{}, repeat);
  std::printf(
      "== ur10 series A every 4th + B + C (a frame per series): diagnose "
      "model (default options), median of %d\n  %4zu poses: %6.2f s wall, "
      "%6.2f s CPU, held-out %.4f -> %.4f mm\n",
      repeat, abc.rows.size(), t.wall, t.cpu, t.result.nominal_heldout_rms_mm,
      t.result.final_heldout_rms_mm);
}

std::string FindingsLabel(const DiagnosisResult& r) {
  std::string s;
  for (const Finding& f : r.findings) {
    if (!s.empty()) s += ", ";
    s += f.cause + (f.joint.empty() ? "" : " " + f.joint);
  }
  return s.empty() ? "none" : s;
}

// Largest relative difference of the candidates' cross-validated RMS
// between two diagnoses of the same data (same steps and candidates).
double CvDifference(const DiagnosisResult& a, const DiagnosisResult& b) {
  double worst =
      std::abs(a.nominal_cv_rms_mm - b.nominal_cv_rms_mm) / b.nominal_cv_rms_mm;
  for (size_t s = 0; s < std::min(a.steps.size(), b.steps.size()); ++s) {
    for (size_t c = 0; c < std::min(a.steps[s].size(), b.steps[s].size());
         ++c) {
      const double x = a.steps[s][c].cv_rms_mm, y = b.steps[s][c].cv_rms_mm;
      if (std::isfinite(x) && std::isfinite(y))
        worst = std::max(worst, std::abs(x - y) / y);
    }
  }
  return worst;
}

void CvUr10(int repeat) {
  Robot ur10;
  Observations all, small;
  if (!LoadUr10SeriesC("cv", &ur10, &all, &small)) return;
  std::printf(
      "== cv: UR10 series C, diagnose model, median of %d, wall / process "
      "CPU seconds (2 threads)\n",
      repeat);
  struct Mode {
    const char* name;
    int folds;
    bool refit;
  };
  const Mode modes[] = {{"single split (--folds 0)", 0, false},
                        {"5 folds, linearised", 5, false},
                        {"10 folds, linearised", 10, false},
                        {"5 folds, refit per fold", 5, true}};
  for (const Observations* obs : {&small, &all}) {
    DiagnosisResult lin5, refit5;
    for (const Mode& m : modes) {
      DiagnoseOptions o;
      o.folds = m.folds;
      o.cv_refit = m.refit;
      const int runs = m.refit && obs == &all ? 1 : repeat;
      const MedianTiming t = TimedMedian(ur10, *obs, o, runs);
      const DiagnosisResult& r = t.result;
      std::printf(
          "  %4zu poses, %-26s: %6.2f s wall, %6.2f s CPU, cv %.4f -> %.4f, "
          "held-out %.4f -> %.4f mm: %s\n",
          obs->rows.size(), m.name, t.wall, t.cpu, r.nominal_cv_rms_mm,
          r.final_cv_rms_mm, r.nominal_heldout_rms_mm, r.final_heldout_rms_mm,
          FindingsLabel(r).c_str());
      if (m.folds == 5 && !m.refit) lin5 = r;
      if (m.folds == 5 && m.refit) refit5 = r;
    }
    std::printf(
        "  %4zu poses: linearised vs refit cross-validated RMS, largest "
        "relative difference over all candidates %.1e; findings %s\n",
        obs->rows.size(), CvDifference(lin5, refit5),
        FindingsLabel(lin5) == FindingsLabel(refit5) ? "same" : "DIFFER");
  }
}

// Naming rates, single split against k folds, on marginal simulated effects
// (near the detection limit, where one split decides) and on null data.
void CvSimulated(int runs) {
  const Robot bh7 = Bh7();
  const Robot ur10 =
      ReadRobotYaml(std::string(KINCAL_SOURCE_DIR) + "/data/robots/ur10.yaml");
  struct Case {
    const Robot* robot;
    std::string effect, cause, joint;
    double magnitude;
    int poses;
    double noise;
  };
  const std::vector<Case> cases = {
      {&bh7, "backlash:j3:0.012", "backlash", "j3", 0.012, 240, 0.03},
      {&bh7, "backlash:j3:0.03", "backlash", "j3", 0.03, 120, 0.03},
      {&bh7, "cyclic:j2:0.01", "cyclic", "j2", 0.01, 120, 0.03},
      {&bh7, "compliance:j5:0.03", "compliance", "j5", 0.03, 120, 0.03},
      {&bh7, "compliance:j5:0.2", "compliance", "j5", 0.2, 180, 0.02},
      {&bh7, "cyclic:j5:0.1", "cyclic", "j5", 0.1, 180, 0.02},
      {&ur10, "elastostatic:shoulder_lift_joint:0.01", "elastostatic",
       "shoulder_lift_joint", 0.01, 150, 0.03},
      {&ur10, "gain:elbow_joint:0.0005", "gain", "elbow_joint", 0.0005, 150,
       0.03},
      {&bh7, "", "", "", 0, 60, 0.03},
      {&bh7, "", "", "", 0, 120, 0.03},
      {&bh7, "", "", "", 0, 240, 0.03},
      {&ur10, "", "", "", 0, 150, 0.03},
  };
  std::printf(
      "== cv-sim: %d seeds per case; named = first finding has the cause "
      "and joint (magnitude within 25 %%); null: false alarms\n",
      runs);
  std::printf("  %-44s %6s  %-22s %-22s %-22s\n", "case", "poses",
              "single split", "5 folds, lowest cv", "5 folds (default)");
  for (const Case& c : cases) {
    std::string cells[3];
    double seconds[3] = {0, 0, 0};
    const int folds[3] = {0, 5, 5};
    // single split; 5 folds where the cross-validated RMS must only drop and
    // the lowest wins; 5 folds with the defaults (paired z gate, ties).
    const DiagnoseOptions defaults;
    const double tie_z[3] = {0.0, 0.0, defaults.cv_tie_z};
    const double min_z[3] = {0.0, 0.0, defaults.cv_min_z};
    int hits[3] = {0, 0, 0}, within[3] = {0, 0, 0}, alarms[3] = {0, 0, 0};
    for (int run = 0; run < runs; ++run) {
      const SimulatedSession s =
          Sim(*c.robot,
              c.effect.empty() ? std::vector<std::string>{}
                               : std::vector<std::string>{c.effect},
              5000 + run, c.poses, c.noise);
      for (int m = 0; m < 3; ++m) {
        DiagnoseOptions o;
        o.folds = folds[m];
        o.folds_given = true;
        o.cv_tie_z = tie_z[m];
        o.cv_min_z = min_z[m];
        const auto start = std::chrono::steady_clock::now();
        const DiagnosisResult r = DiagnoseModel(s.nominal, s.observations, o);
        seconds[m] += Seconds(start);
        if (c.effect.empty()) {
          alarms[m] += r.verdict != "no_significant_effect";
          continue;
        }
        if (!r.findings.empty() && r.findings[0].cause == c.cause &&
            r.findings[0].joint == c.joint) {
          ++hits[m];
          if (std::abs(std::abs(r.findings[0].magnitude) - c.magnitude) <=
              0.25 * c.magnitude)
            ++within[m];
        }
        // Any further finding of a named cause counts as a false alarm.
        for (size_t i = 1; i < r.findings.size(); ++i)
          alarms[m] += r.findings[i].cause != "unexplained";
      }
    }
    for (int m = 0; m < 3; ++m) {
      char cell[64];
      if (c.effect.empty()) {
        std::snprintf(cell, sizeof(cell), "alarms %d/%d %.2fs", alarms[m], runs,
                      seconds[m] / runs);
      } else {
        std::snprintf(cell, sizeof(cell), "%d/%d (%d) +%d %.2fs", hits[m], runs,
                      within[m], alarms[m], seconds[m] / runs);
      }
      cells[m] = cell;
    }
    std::printf("  %-44s %6d  %-22s %-22s %-22s\n",
                (c.robot->name + " " +
                 (c.effect.empty() ? std::string("null") : c.effect))
                    .c_str(),
                c.poses, cells[0].c_str(), cells[1].c_str(), cells[2].c_str());
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
  // As the kincal executable does (app/main.cc): large Jacobians from the
  // heap, freed memory kept, so that the figures are the command's.
  mallopt(M_MMAP_THRESHOLD, 32 << 20);
  mallopt(M_TRIM_THRESHOLD, 1 << 30);
  int runs = 40, repeat = 3;
  std::string only;
  for (int i = 1; i + 1 < argc; ++i) {
    if (std::strcmp(argv[i], "--runs") == 0) runs = std::atoi(argv[i + 1]);
    if (std::strcmp(argv[i], "--only") == 0) only = argv[i + 1];
    if (std::strcmp(argv[i], "--repeat") == 0) repeat = std::atoi(argv[i + 1]);
  }
  const kincal::Robot bh7 = kincal::Bh7();
  if (only.empty() || only == "timing") kincal::Timing(bh7);
  if (only == "ur10") kincal::Ur10Timing(repeat, false);
  if (only == "ur10-240") kincal::Ur10Timing(repeat, true);
  if (only == "ur10-abc") kincal::Ur10AbcTiming(repeat);
  if (only == "cv") kincal::CvUr10(repeat);
  if (only == "cv-sim") kincal::CvSimulated(runs);
  if (only.empty() || only == "backlash") kincal::SmallestBacklash(bh7, runs);
  if (only.empty() || only == "null") kincal::FalseAlarms(bh7, runs);
  if (only.empty() || only == "section4") {
    kincal::Section4(bh7, runs, false, false);
    kincal::Section4(bh7, runs, true, false);
    kincal::Section4(bh7, runs, true, true);
  }
  return 0;
}
