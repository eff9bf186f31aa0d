#include "calib/calibrate.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>

#include "calib/evaluate.h"
#include "data/error.h"
#include "data/import_ipa.h"
#include "data/rigid3.h"
#include "data/robot.h"
#include "data/urdf.h"
#include "synth/simulate.h"
#include "tests/testing/paths.h"

namespace kincal {
namespace {

Robot Bh7() {
  return ReadRobotYaml(testing::SourceDir() + "/data/robots/bh7.yaml");
}

SimulatedSession Session(uint64_t seed, int poses = 240, double noise = 0.03) {
  SimulateOptions opt;
  opt.poses = poses;
  opt.noise_mm = noise;
  opt.seed = seed;
  return Simulate(Bh7(), opt);
}

// Held-out prediction error at the noise floor: the model explains
// everything but the noise (3D RMS of noise = sqrt(3) * sigma).
TEST(CalibrateTest, HeldOutRmsAtNoiseFloorOnSimulatedBh7) {
  const SimulatedSession s = Session(3);
  const CalibrateResult r = Calibrate(s.nominal, s.observations, {});
  const double floor_mm = std::sqrt(3.0) * 0.03;
  EXPECT_EQ(r.heldout.n, 48);
  EXPECT_EQ(r.train.n, 192);
  EXPECT_LT(r.heldout.rms_mm, 1.10 * floor_mm);
  EXPECT_GT(r.heldout.rms_mm, 0.80 * floor_mm);  // not fitting the noise away
  EXPECT_TRUE(r.fit.converged) << r.fit.termination;
  // The nominal model is far off (random deviations of 0.5 mm / 0.2 deg).
  const EvaluateResult nominal = Evaluate(s.nominal, s.observations);
  EXPECT_GT(nominal.stats.rms_mm, 10 * r.heldout.rms_mm);
}

// BH-7 from 3D points: 6 frame + 12 robot parameters; the rest is redundant
// with the frame (base offsets: j1..j4 axes are parallel) or invisible in a
// point (tool orientation).
TEST(CalibrateTest, IdentifiabilityOfBh7From3dPoints) {
  const SimulatedSession s = Session(4);
  const CalibrateResult r = Calibrate(s.nominal, s.observations, {});
  const auto id = r.identifiability.IdentifiableNames();
  const auto un = r.identifiability.UnidentifiableNames();
  EXPECT_EQ(id.size(), 18u);
  EXPECT_EQ(un.size(), 12u);
  using ::testing::Contains;
  using ::testing::Not;
  EXPECT_THAT(un, Contains("j1.theta"));    // = rotation of the frame about z
  EXPECT_THAT(un, Contains("j2.d"));        // parallel axes: d's collapse
  EXPECT_THAT(un, Contains("tool.alpha"));  // no effect on a point
  EXPECT_THAT(id, Contains("j3.a"));
  EXPECT_THAT(id, Contains("tool.d"));
  EXPECT_THAT(id, Not(Contains("tool.theta")));
  EXPECT_EQ(r.identifiability.relations.size(), un.size());
}

// When only identifiable parameters deviate, their estimates agree with the
// truth within the reported 3 sigma, and the reported sigma is honest:
// over seeds, normalised errors have an RMS near 1 (Monte-Carlo vs
// covariance).
TEST(CalibrateTest, EstimatesWithinThreeSigmaAndSigmaIsHonest) {
  const Robot nominal = Bh7();
  std::vector<std::string> identifiable;
  {
    const CalibrateResult probe =
        Calibrate(nominal, Session(11).observations, {});
    for (const ParamInfo& p : probe.identifiability.identifiable) {
      if (p.kind == ParamKind::kRow) identifiable.push_back(p.name);
    }
  }
  ASSERT_EQ(identifiable.size(), 12u);
  double sum_sq = 0.0;
  int count = 0;
  for (uint64_t seed = 20; seed < 32; ++seed) {
    SimulateOptions opt;
    opt.seed = seed;
    opt.perturbed = identifiable;
    const SimulatedSession s = Simulate(nominal, opt);
    const Chain truth = Chain::FromRobot(s.truth);
    ModelState truth_state;
    truth_state.chain = truth;
    CalibrateOptions copt;
    copt.seed = seed;
    const CalibrateResult r = Calibrate(nominal, s.observations, copt);
    for (size_t i = 0; i < r.fit.params.size(); ++i) {
      const ParamInfo& p = r.fit.params[i];
      if (p.kind != ParamKind::kRow) continue;
      const double t = p.ToInterface(ParamValue(truth_state, p));
      const double z = (r.fit.values[i] - t) / r.fit.sigmas[i];
      EXPECT_LT(std::abs(z), 4.0) << p.name << " seed " << seed;
      sum_sq += z * z;
      ++count;
    }
  }
  const double rms_z = std::sqrt(sum_sq / count);
  EXPECT_GT(rms_z, 0.7);
  EXPECT_LT(rms_z, 1.3);
}

TEST(CalibrateTest, ParameterBoundsHold) {
  SimulateOptions opt;
  opt.seed = 5;
  opt.sigma_length_mm = 20.0;  // truth far outside the +-5 mm box
  const SimulatedSession s = Simulate(Bh7(), opt);
  const CalibrateResult r = Calibrate(s.nominal, s.observations, {});
  ModelState nominal;
  nominal.chain = Chain::FromRobot(s.nominal);
  for (size_t i = 0; i < r.fit.params.size(); ++i) {
    const ParamInfo& p = r.fit.params[i];
    if (p.kind != ParamKind::kRow) continue;
    const double center = p.ToInterface(ParamValue(nominal, p));
    const double bound = p.angle ? 5.0 : 5.0;
    EXPECT_LE(std::abs(r.fit.values[i] - center), bound + 1e-9) << p.name;
  }
}

// Bounds a URDF does not state (20 mm / 10 deg by default) are a guess: a
// robot whose joint origins lie 10-20 mm from nominal (a 7-joint industrial
// arm, true deviations 10 mm / 3 deg std) pressed two parameters against
// them and stopped at 1.29 mm RMS. calibrate widens a pressed bound, refits,
// and reaches the noise floor; a stated bound is kept and the parameters on
// it are named.
TEST(CalibrateTest, UnstatedBoundsWidenWhereTheDataPressAgainstThem) {
  const Robot nominal =
      ReadRobot(testing::SourceDir() + "/data/robots/industrial7.urdf");
  ASSERT_FALSE(nominal.bounds_stated);
  SimulateOptions opt;
  opt.seed = 3;
  opt.sigma_length_mm = 10.0;
  opt.sigma_angle_deg = 3.0;
  const SimulatedSession s = Simulate(nominal, opt);
  const double noise_floor = std::sqrt(3.0) * opt.noise_mm;

  const CalibrateResult widened = Calibrate(nominal, s.observations, {});
  EXPECT_FALSE(widened.widened_bounds.empty());
  EXPECT_TRUE(widened.at_bound.empty());
  EXPECT_LT(widened.heldout.rms_mm, 1.2 * noise_floor);
  for (const WidenedBound& w : widened.widened_bounds) {
    EXPECT_DOUBLE_EQ(w.to, 2 * w.from) << w.name;
  }

  Robot stated = nominal;
  stated.bounds_stated = true;
  const CalibrateResult kept = Calibrate(stated, s.observations, {});
  EXPECT_TRUE(kept.widened_bounds.empty());
  EXPECT_FALSE(kept.at_bound.empty());
  EXPECT_GT(kept.heldout.rms_mm, 5 * noise_floor);
  // robot.yaml's `bounds:` states them.
  EXPECT_TRUE(Bh7().bounds_stated);
}

// Single-point data (two fixed points x 30 poses, no measured point)
// determine the geometry only where the tip was held: fitted without a pull
// towards nominal, a 7-joint arm 2 mm / 0.6 deg (std) from nominal predicted
// the rest of its workspace at 24.9 mm RMS, worse than the nominal model's
// 18.5 mm, for 0.075 mm at the two points. The default ridge (weight 1 for
// single-point data) keeps what the data do not determine near nominal:
// 2.5 mm. Measured points get no ridge.
TEST(CalibrateTest, SinglePointDataGetTheRidgeByDefault) {
  const Robot nominal =
      ReadRobot(testing::SourceDir() + "/data/robots/industrial7.urdf");
  SimulateOptions opt;
  opt.seed = 4;
  opt.sigma_length_mm = 2.0;
  opt.sigma_angle_deg = 0.6;
  SimulateOptions points = opt;
  points.mode = SimulateOptions::kFixedPoint;
  points.fixed_points = 2;
  points.poses_per_point = 30;
  points.measure_points = false;
  points.noise_mm = 0.05;
  const SimulatedSession single = Simulate(nominal, points);
  SimulateOptions everywhere = opt;  // the same true robot, noise-free
  everywhere.poses = 200;
  everywhere.noise_mm = 0.0;
  const SimulatedSession workspace = Simulate(nominal, everywhere);
  const double nominal_rms =
      Evaluate(nominal, workspace.observations).stats.rms_mm;

  CalibrateOptions co;
  co.holdout_fraction = 0.0;
  const CalibrateResult ridge = Calibrate(nominal, single.observations, co);
  EXPECT_EQ(ridge.prior_weight, 1.0);
  co.prior_weight = 0.0;
  const CalibrateResult plain = Calibrate(nominal, single.observations, co);
  const double ridge_rms =
      Evaluate(ridge.calibrated, workspace.observations).stats.rms_mm;
  const double plain_rms =
      Evaluate(plain.calibrated, workspace.observations).stats.rms_mm;
  EXPECT_LT(ridge_rms, 0.25 * nominal_rms);
  EXPECT_GT(plain_rms, 3 * ridge_rms);
  EXPECT_LT(ridge.train.rms_mm, 1.2 * plain.train.rms_mm);

  // Measured points: no ridge.
  const SimulatedSession measured = Simulate(nominal, opt);
  EXPECT_EQ(Calibrate(nominal, measured.observations, {}).prior_weight, 0.0);
}

TEST(CalibrateTest, RejectsDataThatDetermineNothing) {
  const Robot nominal = Bh7();
  SimulatedSession s = Session(6, 5);
  Observations one_pose = s.observations;
  for (auto& row : one_pose.rows) row.q = one_pose.rows[0].q;
  try {
    Calibrate(nominal, one_pose, {});
    FAIL() << "identical poses accepted";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), ::testing::HasSubstr("same joint readings"));
  }
  Observations few = s.observations;  // 5 poses: 15 equations, 18 unknowns
  try {
    Calibrate(nominal, few, {});
    FAIL() << "too few poses accepted";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), ::testing::HasSubstr("too few poses"));
  }
  Observations no_points = s.observations;
  for (auto& row : no_points.rows) row.has_point = false;
  EXPECT_THROW(Calibrate(nominal, no_points, {}), InputError);
}

// Single-point data (no measured points, the seed's experiment). One fixed
// point hides 6 base degrees of freedom: its 3 coordinates absorb base
// translations and rotations of the whole robot about any axis through the
// point leave every tip on it. Several points absorb the same 6 (each moves
// as a whole). So, as with 3D points and an unknown measuring frame, 12 of
// BH-7's 24 DH parameters are determined (the prismatic j1 fixes the scale);
// held-out poses of each group still land on the point.
TEST(CalibrateTest, SinglePointLeastSquares) {
  auto run = [](int points, int per_point) {
    SimulateOptions opt;
    opt.mode = SimulateOptions::kFixedPoint;
    opt.fixed_points = points;
    opt.poses_per_point = per_point;
    opt.measure_points = false;
    opt.noise_mm = 0.02;
    opt.seed = 8;
    const SimulatedSession s = Simulate(Bh7(), opt);
    EXPECT_EQ(s.observations.rows.size(),
              static_cast<size_t>(points * per_point));
    return Calibrate(s.nominal, s.observations, {});
  };
  auto robot_params = [](const CalibrateResult& r) {
    std::vector<std::string> names;
    for (const auto& p : r.identifiability.identifiable) {
      if (p.kind == ParamKind::kRow) names.push_back(p.name);
    }
    return names;
  };
  const CalibrateResult one = run(1, 40);
  const CalibrateResult three = run(3, 30);
  for (const CalibrateResult* r : {&one, &three}) {
    EXPECT_TRUE(r->has_epsilon);
    EXPECT_LT(r->heldout.rms_mm, 0.1);
    EXPECT_LT(r->epsilon.mean_mm, 0.05);
  }
  EXPECT_EQ(robot_params(one).size(), 12u)
      << ::testing::PrintToString(robot_params(one));
  EXPECT_EQ(robot_params(three).size(), 12u)
      << ::testing::PrintToString(robot_params(three));
  // A rigid rotation of the arm about the base z axis moves every group as a
  // whole: never determined by fixed points.
  EXPECT_THAT(one.identifiability.UnidentifiableNames(),
              ::testing::Contains("j1.theta"));
}

// Two campaigns of one robot (BH-7, seed 8's hidden geometry), each with
// its own hidden measuring frame: series A from the simulation's frame,
// series B 60 poses of another seed with the instrument moved (rotation
// vector z + 0.5 rad, 700 mm along x).
struct TwoSeries {
  SimulatedSession a, b;
  Observations both;
};

TwoSeries TwoSeriesCampaign() {
  TwoSeries t;
  t.a = Session(8, 120, 0.02);
  SimulateOptions so;
  so.poses = 80;
  so.seed = 21;
  so.noise_mm = 0.02;
  so.sigma_length_mm = 0.0;  // the same robot: a's truth, unchanged
  so.sigma_angle_deg = 0.0;
  const auto& f = t.a.meas_from_base;
  so.meas_from_base =
      std::array<double, 6>{f[0], f[1], f[2] + 0.5, f[3] + 700, f[4], f[5]};
  t.b = Simulate(t.a.truth, so);
  t.both = t.a.observations;
  for (Observation& o : t.both.rows) o.series = "A";
  for (Observation o : t.b.observations.rows) {
    o.pose = "b" + o.pose;
    o.series = "B";
    t.both.rows.push_back(o);
  }
  return t;
}

// B's measuring frame seen from A's: invariant to the base transform the
// frames share with the robot's base row.
Rigid3 BFromA(const double* a, const double* b) {
  return Rigid3FromPoseBlock(b) * Rigid3FromPoseBlock(a).Inverse();
}

// One frame per series, the robot shared: the fit recovers the robot (its
// predictions of the true tips at the noise level) and both frames (B's
// seen from A's); the split holds out a share of each series.
TEST(CalibrateTest, TwoSeriesRecoverTheRobotAndBothFrames) {
  const TwoSeries t = TwoSeriesCampaign();
  const CalibrateResult r = Calibrate(t.a.nominal, t.both, {});
  ASSERT_EQ(r.state.NumFrames(), 2);
  EXPECT_EQ(r.state.frame_series, (std::vector<std::string>{"A", "B"}));
  const double floor_mm = std::sqrt(3.0) * 0.02;
  EXPECT_LT(r.heldout.rms_mm, 1.2 * floor_mm);
  EXPECT_LT(r.train.rms_mm, 1.2 * floor_mm);
  int held_a = 0, held_b = 0;
  for (int row : r.heldout_rows) (row < 120 ? held_a : held_b) += 1;
  EXPECT_EQ(held_a, 24);  // 20 % of each series
  EXPECT_EQ(held_b, 16);
  const Rigid3 fitted = BFromA(r.state.FrameBlock(0), r.state.FrameBlock(1));
  const Rigid3 truth =
      BFromA(t.a.meas_from_base.data(), t.b.meas_from_base.data());
  EXPECT_LT((fitted.t - truth.t).norm(), 0.05);
  EXPECT_LT((fitted.R - truth.R).norm(), 1e-4);
  // The robot: the calibrated model's tips against the true ones, each in
  // its base frame, on B's poses.
  const Chain fitted_chain = Chain::FromRobot(r.calibrated);
  const Chain true_chain = Chain::FromRobot(t.a.truth);
  ModelState scratch;
  scratch.chain = true_chain;
  const std::vector<Measurement> ms =
      MakeMeasurements(true_chain, t.b.observations, &scratch);
  double worst = 0.0;
  const Rigid3 base_from_base =
      Rigid3FromPoseBlock(r.state.FrameBlock(1)).Inverse() *
      Rigid3FromPoseBlock(t.b.meas_from_base.data());
  for (const Measurement& m : ms) {
    const Eigen::Vector3d truth_tip = TipInBase(true_chain, m.input);
    const Eigen::Vector3d fitted_tip = TipInBase(fitted_chain, m.input);
    worst = std::max(worst, (base_from_base * truth_tip - fitted_tip).norm());
  }
  EXPECT_LT(worst, 0.1);
}

// The same rows without the `series` label cannot share a frame: calibrate
// and diagnose model refuse them with the hint to add the column.
TEST(CalibrateTest, UnlabelledConcatenationStillRefused) {
  TwoSeries t = TwoSeriesCampaign();
  for (Observation& o : t.both.rows) o.series.clear();
  try {
    RequireNoFrameJump(t.a.nominal, t.both, "calibrate");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), ::testing::HasSubstr("add a `series` column"));
    EXPECT_THAT(e.what(),
                ::testing::HasSubstr("fits one measuring frame per series"));
  }
  // Labelled, each series is searched on its own: no jump.
  EXPECT_NO_THROW(
      RequireNoFrameJump(t.a.nominal, TwoSeriesCampaign().both, "calibrate"));
}

// Real data (../shared/data, skipped when absent): the UR10 series A (every
// 8th grid row) and C (every 2nd random pose), measured with the tracker
// moved in between. Labelled, each gets its own frame and both are fitted
// near C's single-series figure (0.50 mm held out); unlabelled, one frame
// cannot hold both and the rows are refused.
TEST(CalibrateTest, RealUr10SeriesAAndCWithAFramePerSeries) {
  KINCAL_REQUIRE_SHARED_DATA("ipa-robot-accuracy");
  const std::string dir = testing::SharedDataDir() + "/ipa-robot-accuracy/";
  auto every = [](const Observations& obs, int n, const std::string& name) {
    std::vector<int> keep;
    for (int i = 0; i < static_cast<int>(obs.rows.size()); i += n)
      keep.push_back(i);
    Observations out = Subset(obs, keep);
    for (Observation& o : out.rows) {
      o.series = name;
      o.pose = name + "-" + o.pose;
    }
    return out;
  };
  Observations both =
      every(ReadIpaSeries(dir + "Series_A/measurements_grid.csv").observations,
            8, "A");
  const Observations c =
      every(ReadIpaSeries(dir + "Series_C/measurements_random_poses.csv")
                .observations,
            2, "C");
  for (const Observation& o : c.rows) both.rows.push_back(o);
  const Robot ur10 =
      ReadRobotYaml(testing::SourceDir() + "/data/robots/ur10.yaml");
  const CalibrateResult r = Calibrate(ur10, both, {});
  ASSERT_EQ(r.state.NumFrames(), 2);
  EXPECT_LT(r.heldout.rms_mm, 0.6);
  EXPECT_LT(r.train.rms_mm, 0.6);
  // The instrument moved: the two frames differ by more than a metre or a
  // large turn, which is why one frame cannot hold both.
  const Rigid3 c_from_a = BFromA(r.state.FrameBlock(0), r.state.FrameBlock(1));
  EXPECT_GT(c_from_a.t.norm() +
                1000 * (c_from_a.R - Eigen::Matrix3d::Identity()).norm(),
            100.0);
  for (Observation& o : both.rows) o.series.clear();
  EXPECT_THROW(RequireNoFrameJump(ur10, both, "calibrate"), InputError);
}

}  // namespace
}  // namespace kincal
