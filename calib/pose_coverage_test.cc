#include "calib/pose_coverage.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <random>

#include "data/error.h"
#include "data/import_ipa.h"
#include "tests/testing/paths.h"

namespace kincal {
namespace {

Robot Ur10() {
  return ReadRobotYaml(testing::SourceDir() + "/data/robots/ur10.yaml");
}

// `n` poses with tips (placeholders: the check reads joints only); joint j
// drawn over [lo[j], hi[j]].
Observations Poses(const Robot& robot, int n, const std::vector<double>& lo,
                   const std::vector<double>& hi, uint64_t seed) {
  std::mt19937_64 rng(seed);
  Observations obs;
  obs.source = "test.csv";
  obs.joint_names = robot.JointNames();
  for (int i = 0; i < n; ++i) {
    Observation o;
    o.has_point = true;
    for (size_t j = 0; j < robot.joints.size(); ++j) {
      o.q.push_back(std::uniform_real_distribution<double>(lo[j], hi[j])(rng));
    }
    obs.rows.push_back(o);
  }
  return obs;
}

TEST(PoseCoverage, PosesOverTheLimitsDetermineTheRobot) {
  const Robot robot = Ur10();
  std::vector<double> lo, hi;
  for (const RobotRow& r : robot.joints) {
    lo.push_back(r.lower);
    hi.push_back(r.upper);
  }
  const PoseCoverage c = CheckPoseCoverage(robot, Poses(robot, 60, lo, hi, 3));
  EXPECT_TRUE(c.ok()) << PoseCoverageMessage(c);
  ASSERT_EQ(c.travel.size(), robot.joints.size());
  for (const JointTravel& t : c.travel) EXPECT_FALSE(t.small) << t.joint;
}

// The wrist seen over 24 deg only (issue 21: -31..-7 deg), the other joints
// over their limits: the wrist's parameters are undetermined, the wrist
// joints named with their travel, and the fix pointed to.
TEST(PoseCoverage, SmallWristTravelIsNamed) {
  const Robot robot = Ur10();
  std::vector<double> lo, hi;
  for (const RobotRow& r : robot.joints) {
    lo.push_back(r.lower);
    hi.push_back(r.upper);
  }
  const size_t n = robot.joints.size();
  for (size_t j = n - 3; j < n; ++j) {
    lo[j] = -31;
    hi[j] = -7;
  }
  const PoseCoverage c = CheckPoseCoverage(robot, Poses(robot, 60, lo, hi, 3));
  EXPECT_FALSE(c.ok());
  for (size_t j = 0; j < n; ++j) {
    EXPECT_EQ(c.travel[j].small, j >= n - 3) << c.travel[j].joint;
    if (j >= n - 3) {
      EXPECT_LT(c.travel[j].seen, 24.0);
      EXPECT_GT(c.travel[j].seen, 15.0);
    }
  }
  const std::string m = PoseCoverageMessage(c);
  std::printf("%s\n", m.c_str());
  EXPECT_NE(m.find(c.undetermined.front()), std::string::npos);
  EXPECT_NE(m.find(robot.joints[n - 1].name), std::string::npos);
  EXPECT_NE(m.find("kincal bundle"), std::string::npos);
  EXPECT_NE(m.find("kincal plan --rig"), std::string::npos);
}

TEST(PoseCoverage, FewRowsOrBadOptions) {
  const Robot robot = Ur10();
  Observations one =
      Poses(robot, 1, std::vector<double>(6, 0), std::vector<double>(6, 10), 1);
  EXPECT_TRUE(CheckPoseCoverage(robot, one).ok());
  PoseCoverageOptions o;
  o.noise_sigma_mm = 0;
  EXPECT_THROW(o.Check(), InputError);
  o = PoseCoverageOptions();
  o.small_travel_fraction = 1.5;
  EXPECT_THROW(o.Check(), InputError);
}

// The laser-tracker recordings of a UR10 (shared real data) raise no
// warning: their poses determine the robot as poses over the limits do.
TEST(PoseCoverage, NoFalseAlarmOnRealUr10Series) {
  KINCAL_REQUIRE_SHARED_DATA("ipa-robot-accuracy");
  const std::string dir = testing::SharedDataDir() + "/ipa-robot-accuracy/";
  const Robot robot = Ur10();
  for (const std::string file :
       {"Series_A/measurements_grid.csv",
        "Series_B/measurements_joint_configurations.csv",
        "Series_C/measurements_random_poses.csv"}) {
    const PoseCoverage c =
        CheckPoseCoverage(robot, ReadIpaSeries(dir + file).observations);
    EXPECT_TRUE(c.ok()) << file << ": " << PoseCoverageMessage(c);
  }
}

}  // namespace
}  // namespace kincal
