#include "synth/simulate.h"

#include <gtest/gtest.h>

#include <cmath>

#include "calib/model_state.h"
#include "data/error.h"
#include "data/rigid3.h"
#include "tests/testing/paths.h"

namespace kincal {
namespace {

Robot Bh7() {
  return ReadRobotYaml(testing::SourceDir() + "/data/robots/bh7.yaml");
}

TEST(Simulate, SameSeedSameSessionOtherSeedOtherSession) {
  SimulateOptions o;
  o.poses = 20;
  o.seed = 4;
  const SimulatedSession a = Simulate(Bh7(), o);
  const SimulatedSession b = Simulate(Bh7(), o);
  ASSERT_EQ(a.observations.rows.size(), 20u);
  for (size_t i = 0; i < a.observations.rows.size(); ++i) {
    EXPECT_EQ(a.observations.rows[i].q, b.observations.rows[i].q);
    EXPECT_EQ(a.observations.rows[i].p_in_meas,
              b.observations.rows[i].p_in_meas);
  }
  o.seed = 5;
  const SimulatedSession c = Simulate(Bh7(), o);
  EXPECT_NE(a.observations.rows[0].q, c.observations.rows[0].q);
}

// Without noise the measured points are the true tips in the measuring
// frame; the time column steps by seconds_per_pose.
TEST(Simulate, NoiseFreePointsAreTheTrueTipsInTheMeasuringFrame) {
  SimulateOptions o;
  o.poses = 15;
  o.noise_mm = 0.0;
  o.seconds_per_pose = 2.0;
  const SimulatedSession s = Simulate(Bh7(), o);
  const Rigid3 meas_from_base = Rigid3FromPoseBlock(s.meas_from_base.data());
  EXPECT_NEAR(meas_from_base.t.norm(), o.frame_distance_mm, 1e-9);
  ASSERT_EQ(s.base_from_tip.size(), 15u);
  for (size_t i = 0; i < s.observations.rows.size(); ++i) {
    const Observation& row = s.observations.rows[i];
    ASSERT_TRUE(row.has_point);
    const Eigen::Vector3d tip = s.base_from_tip[i].block<3, 1>(0, 3);
    EXPECT_LT((meas_from_base * tip - row.p_in_meas).norm(), 1e-6) << i;
    EXPECT_DOUBLE_EQ(row.t_s, 2.0 * i);
  }
}

TEST(Simulate, GivenMeasuringFrameIsUsed) {
  SimulateOptions o;
  o.poses = 3;
  o.meas_from_base = std::array<double, 6>{0.1, 0.2, 0.3, 10, 20, 30};
  EXPECT_EQ(Simulate(Bh7(), o).meas_from_base, *o.meas_from_base);
}

TEST(Simulate, OnlyTheNamedParametersDeviate) {
  SimulateOptions o;
  o.poses = 3;
  o.perturbed = {"j2.d"};
  const SimulatedSession s = Simulate(Bh7(), o);
  ModelState nominal, truth;
  nominal.chain = Chain::FromRobot(s.nominal);
  truth.chain = Chain::FromRobot(s.truth);
  int changed = 0;
  for (const ParamInfo& p : GeometryParams(truth.chain)) {
    if (ParamValue(truth, p) != ParamValue(nominal, p)) {
      ++changed;
      EXPECT_EQ(p.name, "j2.d");
    }
  }
  EXPECT_EQ(changed, 1);
}

TEST(Simulate, BacklashIsInjectedAndNoted) {
  const Robot robot = Bh7();
  SimulateOptions o;
  o.poses = 10;
  o.effects = {ParseEffect("backlash:j3:0.15", robot)};
  const SimulatedSession s = Simulate(robot, o);
  ASSERT_EQ(s.effect_notes.size(), 1u);
  ModelState truth;
  truth.chain = Chain::FromRobot(s.truth);
  const ParamInfo p = FindParam(truth, "j3.backlash");
  EXPECT_NEAR(p.ToInterface(ParamValue(truth, p)), 0.15, 1e-12);
}

// Fixed-point mode: every pose of a group puts the true tip on its point.
TEST(Simulate, FixedPointPosesReachTheirPoint) {
  SimulateOptions o;
  o.mode = SimulateOptions::kFixedPoint;
  o.fixed_points = 2;
  o.poses_per_point = 5;
  o.noise_mm = 0.0;
  const SimulatedSession s = Simulate(Bh7(), o);
  ASSERT_EQ(s.observations.rows.size(), 10u);
  for (size_t i = 1; i < s.observations.rows.size(); ++i) {
    const auto& a = s.observations.rows[i - 1];
    const auto& b = s.observations.rows[i];
    if (a.fixed_point != b.fixed_point) continue;
    const Eigen::Vector3d ta = s.base_from_tip[i - 1].block<3, 1>(0, 3);
    const Eigen::Vector3d tb = s.base_from_tip[i].block<3, 1>(0, 3);
    EXPECT_LT((ta - tb).norm(), 1e-6) << i;
  }
  EXPECT_EQ(s.observations.rows.front().fixed_point, "p0");
  EXPECT_EQ(s.observations.rows.back().fixed_point, "p1");
}

TEST(Simulate, BadOptionsAreBadInput) {
  SimulateOptions o;
  o.noise_mm = -1;
  EXPECT_THROW(Simulate(Bh7(), o), InputError);
  o.noise_mm = 0;
  o.poses = 0;
  EXPECT_THROW(Simulate(Bh7(), o), InputError);
}

}  // namespace
}  // namespace kincal
