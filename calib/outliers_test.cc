#include "calib/outliers.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <set>

#include "calib/calibrate.h"
#include "calib/evaluate.h"
#include "calib/holdout.h"
#include "data/robot.h"
#include "synth/simulate.h"
#include "tests/testing/paths.h"

namespace kincal {
namespace {

Robot RobotFile(const std::string& name) {
  return ReadRobotYaml(testing::SourceDir() + "/data/robots/" + name);
}

// The pose ids of the listed rows.
std::set<std::string> Poses(const std::vector<RowOutlier>& outliers) {
  std::set<std::string> out;
  for (const RowOutlier& o : outliers) out.insert(o.pose);
  return out;
}

TEST(OutliersTest, RobustAxisSigmaOfGaussianErrorsIsTheirSigma) {
  std::mt19937_64 rng(5);
  std::normal_distribution<double> n(0.0, 0.7);
  std::vector<double> norms;
  for (int i = 0; i < 20000; ++i) {
    const Eigen::Vector3d e(n(rng), n(rng), n(rng));
    norms.push_back(e.norm());
  }
  EXPECT_NEAR(RobustAxisSigmaMm(norms), 0.7, 0.7 * 0.02);
  // A tenth of the rows 100x larger barely moves it.
  for (size_t i = 0; i < norms.size(); i += 10) norms[i] *= 100;
  EXPECT_NEAR(RobustAxisSigmaMm(norms), 0.7, 0.7 * 0.15);
  EXPECT_EQ(RobustAxisSigmaMm({}), 0.0);
}

TEST(OutliersTest, CanExcludeKeepsThreeQuartersAndThreeRowsPerPoint) {
  std::vector<Measurement> ms(8);
  for (int i = 0; i < 8; ++i) {
    ms[i].kind = Measurement::kFixedPoint;
    ms[i].point = i < 4 ? 0 : 1;
  }
  EXPECT_TRUE(CanExclude(ms, {1, 0, 0, 0, 0, 0, 0, 0}));
  EXPECT_TRUE(CanExclude(ms, {1, 0, 0, 0, 1, 0, 0, 0}));
  EXPECT_FALSE(CanExclude(ms, {1, 1, 0, 0, 0, 0, 0, 0}));  // point 0 left 2
  EXPECT_FALSE(CanExclude(ms, {1, 0, 0, 0, 1, 1, 0, 0}));  // more than 1/4
}

// Measured points with gross errors of 1-20 mm in random directions on
// seeded random rows (a tracker's beam break): calibrate lists exactly those
// rows, fits as if they were not there, and without the screening the fit
// is spoiled. Two robots, two noise levels.
TEST(OutliersTest, CalibrateLeavesOutGrossMeasuredPoints) {
  struct Case {
    const char* robot;
    double noise_mm;
    uint64_t seed;
  };
  for (const Case& c :
       {Case{"ur10.yaml", 0.05, 3}, Case{"bh7.yaml", 0.02, 4}}) {
    SimulateOptions opt;
    opt.poses = 240;
    opt.noise_mm = c.noise_mm;
    opt.seed = c.seed;
    const SimulatedSession s = Simulate(RobotFile(c.robot), opt);
    Observations bad = s.observations;
    std::mt19937_64 rng(c.seed + 100);
    std::uniform_real_distribution<double> u(-1.0, 1.0), size(1.0, 20.0);
    std::set<std::string> corrupted;
    while (corrupted.size() < 8) {
      const size_t i = rng() % bad.rows.size();
      if (!corrupted.insert(bad.rows[i].pose).second) continue;
      Eigen::Vector3d d(u(rng), u(rng), u(rng));
      bad.rows[i].p_in_meas += size(rng) * d.normalized();
    }
    const CalibrateResult clean = Calibrate(s.nominal, s.observations, {});
    const CalibrateResult r = Calibrate(s.nominal, bad, {});
    CalibrateOptions keep_all;
    keep_all.outlier_sigmas = 0;
    const CalibrateResult spoiled = Calibrate(s.nominal, bad, keep_all);
    EXPECT_TRUE(clean.outliers.empty()) << c.robot;
    EXPECT_EQ(Poses(r.outliers), corrupted) << c.robot;
    for (const RowOutlier& o : r.outliers) EXPECT_TRUE(o.excluded);
    EXPECT_NEAR(r.train.rms_mm, clean.train.rms_mm, 0.05 * clean.train.rms_mm)
        << c.robot;
    EXPECT_LT(r.heldout.rms_mm, 1.2 * clean.heldout.rms_mm) << c.robot;
    EXPECT_GT(spoiled.train.rms_mm, 5 * clean.train.rms_mm) << c.robot;
    EXPECT_TRUE(spoiled.outliers.empty());
    // evaluate lists them too, and keeps the spec's figures over every row.
    const EvaluateResult e = Evaluate(s.truth, bad);
    EXPECT_EQ(Poses(e.outliers), corrupted) << c.robot;
    ASSERT_TRUE(e.has_robust);
    EXPECT_EQ(e.stats.n, static_cast<int>(bad.rows.size()));
    EXPECT_EQ(e.robust.stats.n, static_cast<int>(bad.rows.size()) - 8);
    EXPECT_LT(e.robust.stats.rms_mm, 2.0 * std::sqrt(3.0) * c.noise_mm);
    const EvaluateResult e0 = Evaluate(s.truth, bad, 0.0);
    EXPECT_TRUE(e0.outliers.empty());
    EXPECT_DOUBLE_EQ(e0.stats.rms_mm, e.stats.rms_mm);
  }
}

// Single-point data where rows of one fixed point were saved under the
// other's label (MUKCa panda_7 `left`): found, and the point they sit at is
// named.
TEST(OutliersTest, RowsSavedUnderAnotherFixedPointAreNamed) {
  SimulateOptions opt;
  opt.mode = SimulateOptions::kFixedPoint;
  opt.fixed_points = 2;
  opt.poses_per_point = 30;
  opt.measure_points = false;
  opt.noise_mm = 0.02;
  opt.seed = 8;
  const SimulatedSession s = Simulate(RobotFile("bh7.yaml"), opt);
  Observations bad = s.observations;
  std::string a, b;
  std::set<std::string> moved;
  for (Observation& o : bad.rows) {
    if (a.empty()) a = o.fixed_point;
    if (o.fixed_point != a && b.empty()) b = o.fixed_point;
  }
  ASSERT_FALSE(b.empty());
  for (Observation& o : bad.rows) {
    if (o.fixed_point == b && moved.size() < 4) {
      o.fixed_point = a;
      moved.insert(o.pose);
    }
  }
  CalibrateOptions opt_cal;
  opt_cal.holdout_fraction = 0;
  const CalibrateResult clean = Calibrate(s.nominal, s.observations, opt_cal);
  const CalibrateResult r = Calibrate(s.nominal, bad, opt_cal);
  EXPECT_TRUE(clean.outliers.empty());
  EXPECT_EQ(Poses(r.outliers), moved);
  for (const RowOutlier& o : r.outliers) {
    EXPECT_EQ(o.near_point, b) << o.pose;
    EXPECT_LT(o.near_point_mm, 0.2) << o.pose;
  }
  EXPECT_NEAR(r.epsilon.mean_mm, clean.epsilon.mean_mm,
              0.1 * clean.epsilon.mean_mm);
}

// Held-out rows beyond the threshold are left out of the held-out figures
// only while they are at most a quarter of them; more (a model predicting
// badly looks the same) stay in, listed as kept.
TEST(OutliersTest, HeldOutRowsLeftOutOnlyWhileFew) {
  SimulateOptions opt;
  opt.poses = 200;
  opt.noise_mm = 0.03;
  opt.seed = 11;
  const SimulatedSession s = Simulate(RobotFile("bh7.yaml"), opt);
  const CalibrateOptions defaults;
  ModelState state;
  const std::vector<Measurement> ms =
      MakeMeasurements(Chain::FromRobot(s.nominal), s.observations, &state);
  const std::vector<int> held =
      SplitHoldout(ms, defaults.holdout_fraction, defaults.seed).heldout;
  ASSERT_EQ(held.size(), 40u);
  for (const int corrupt : {5, 15}) {
    Observations bad = s.observations;
    for (int k = 0; k < corrupt; ++k)
      bad.rows[ms[held[k]].row].p_in_meas.x() += 5.0;
    const CalibrateResult r = Calibrate(s.nominal, bad, defaults);
    int listed = 0;
    for (const RowOutlier& o : r.outliers) {
      EXPECT_TRUE(o.heldout) << o.pose;
      EXPECT_EQ(o.excluded, corrupt == 5) << o.pose;
      ++listed;
    }
    EXPECT_EQ(listed, corrupt);
    EXPECT_EQ(r.outliers_too_many, corrupt == 15);
    EXPECT_EQ(r.heldout.n, corrupt == 5 ? 35 : 40);
    if (corrupt == 15) {
      EXPECT_GT(r.heldout.rms_mm, 2.0);
    } else {
      EXPECT_LT(r.heldout.rms_mm, 0.1);
    }
  }
}

// No false alarms on clean sessions: seeds x robots x noise.
TEST(OutliersTest, CleanSessionsListNoRow) {
  int sessions = 0;
  for (const char* robot : {"ur10.yaml", "bh7.yaml"}) {
    for (uint64_t seed = 20; seed < 26; ++seed) {
      SimulateOptions opt;
      opt.poses = 120;
      opt.noise_mm = seed % 2 ? 0.01 : 0.1;
      opt.seed = seed;
      const SimulatedSession s = Simulate(RobotFile(robot), opt);
      const CalibrateResult r = Calibrate(s.nominal, s.observations, {});
      EXPECT_TRUE(r.outliers.empty()) << robot << " seed " << seed;
      EXPECT_TRUE(Evaluate(s.truth, s.observations).outliers.empty())
          << robot << " seed " << seed;
      ++sessions;
    }
  }
  EXPECT_EQ(sessions, 12);
}

}  // namespace
}  // namespace kincal
