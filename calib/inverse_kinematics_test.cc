#include "calib/inverse_kinematics.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <random>

#include "data/robot.h"
#include "tests/testing/paths.h"

namespace kincal {
namespace {

Robot LoadRobot(const std::string& name) {
  return ReadRobotYaml(testing::SourceDir() + "/data/robots/" + name);
}

IkTarget TargetAt(const Eigen::Matrix4d& pose, bool rotation) {
  IkTarget t;
  t.position_mm = pose.block<3, 1>(0, 3);
  t.has_rotation = rotation;
  t.rotation = pose.block<3, 3>(0, 0);
  return t;
}

TEST(InverseKinematicsTest, RedundantBh7ReachesPositionsNearTheSeed) {
  const Robot robot = LoadRobot("bh7.yaml");
  const Chain chain = Chain::FromRobot(robot);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-40.0, 40.0);
  IkOptions options;
  options.limits = JointLimits(robot);
  for (int trial = 0; trial < 20; ++trial) {
    const std::vector<double> truth = {20 + u(rng) / 4, u(rng), u(rng), u(rng),
                                       u(rng)};
    const Eigen::Matrix4d pose = ModelPoseAtReadings(chain, truth, {});
    std::vector<double> seed = truth;
    for (double& q : seed) q += 2.0;  // 2 deg (2 mm for j1) away
    const IkResult r =
        SolveIk(chain, TargetAt(pose, false), seed, IkContext{}, options);
    ASSERT_TRUE(r.reached) << "trial " << trial << " err "
                           << r.position_error_mm << " it " << r.iterations;
    EXPECT_LT(r.position_error_mm, 1e-6);
    const Eigen::Vector3d reached =
        ModelPoseAtReadings(chain, r.q, {}).block<3, 1>(0, 3);
    EXPECT_LT((reached - pose.block<3, 1>(0, 3)).norm(), 1e-6);
    // Redundant (5 joints, 3 equations): the nearest solution, a few
    // degrees from the seed, not another branch.
    for (int j = 0; j < 5; ++j) EXPECT_LT(std::abs(r.q[j] - seed[j]), 5.0);
  }
}

TEST(InverseKinematicsTest, Ur10PoseTargetKeepsTheSeedsConfiguration) {
  const Robot robot = LoadRobot("ur10.yaml");
  const Chain chain = Chain::FromRobot(robot);
  const std::vector<double> truth = {30, -70, 95, -110, -85, 40};
  const Eigen::Matrix4d pose = ModelPoseAtReadings(chain, truth, {});
  std::vector<double> seed = {33, -66, 91, -113, -88, 44};
  const IkResult r =
      SolveIk(chain, TargetAt(pose, true), seed, IkContext{}, IkOptions{});
  ASSERT_TRUE(r.reached);
  for (int j = 0; j < 6; ++j) EXPECT_NEAR(r.q[j], truth[j], 1e-6) << j;
  EXPECT_LT(r.rotation_error_deg, 1e-6);
  // The elbow-down branch reaches the same position with the elbow's sign
  // flipped; seeded there, the solve stays there.
  IkTarget position_only = TargetAt(pose, false);
  const IkResult down =
      SolveIk(chain, position_only, {30, -70 + 60, -95, -110, -85, 40},
              IkContext{}, IkOptions{});
  ASSERT_TRUE(down.reached);
  EXPECT_LT(down.q[2], 0.0);
}

TEST(InverseKinematicsTest, InvertsTheErrorModel) {
  // A UR10 with backlash, a gain, compliance and a transmission series:
  // the readings that put the modelled tip at a target differ from the
  // geometric solution by the modelled joint errors.
  Robot robot = LoadRobot("ur10.yaml");
  robot.extensions.push_back(
      {"backlash", "shoulder_lift_joint", {{"width", 0.05}}});
  robot.extensions.push_back({"gain", "elbow_joint", {{"g", 2e-4}}});
  robot.extensions.push_back(
      {"compliance", "shoulder_lift_joint", {{"per_torque", 2e-5}}});
  robot.extensions.push_back({"transmission",
                              "wrist_1_joint",
                              {{"lo", -180}, {"hi", 0}, {"s1", 0.02}}});
  const Chain chain = Chain::FromRobot(robot);
  IkContext context;
  context.s = {1, 1, -1, 1, 1, 1};
  const std::vector<double> seed = {10, -80, 100, -100, -90, 0};
  const Eigen::Matrix4d goal =
      ModelPoseAtReadings(Chain::FromRobot(LoadRobot("ur10.yaml")),
                          {12, -78, 97, -104, -88, 3}, {});
  IkOptions geometric;
  geometric.use_error_model = false;
  const IkResult plain =
      SolveIk(chain, TargetAt(goal, true), seed, context, geometric);
  const IkResult model =
      SolveIk(chain, TargetAt(goal, true), seed, context, IkOptions{});
  ASSERT_TRUE(plain.reached);
  ASSERT_TRUE(model.reached);
  const Eigen::Matrix4d at = ModelPoseAtReadings(chain, model.q, context);
  EXPECT_LT((at.block<3, 1>(0, 3) - goal.block<3, 1>(0, 3)).norm(), 1e-6);
  // Commanding the geometric solution misses by the joint errors (mm).
  const Eigen::Matrix4d missed = ModelPoseAtReadings(chain, plain.q, context);
  EXPECT_GT((missed.block<3, 1>(0, 3) - goal.block<3, 1>(0, 3)).norm(), 0.1);
  // Elbow: q = (1 + g) q_read, so the read value is smaller by g q.
  EXPECT_NEAR(model.q[2] - plain.q[2], -2e-4 * plain.q[2], 2e-3);
}

TEST(InverseKinematicsTest, LimitsStopTheSolveAndAreNamed) {
  Robot robot = LoadRobot("ur10.yaml");
  robot.joints[1].lower = -60;  // shoulder lift may not go below -60 deg
  const Chain chain = Chain::FromRobot(robot);
  const Eigen::Matrix4d pose =
      ModelPoseAtReadings(chain, {0, -80, 90, -90, -90, 0}, {});
  IkOptions options;
  options.limits = JointLimits(robot);
  const IkResult r = SolveIk(chain, TargetAt(pose, true),
                             {0, -55, 85, -90, -90, 0}, IkContext{}, options);
  EXPECT_FALSE(r.reached);
  ASSERT_FALSE(r.at_limit.empty());
  EXPECT_EQ(r.at_limit[0], "shoulder_lift_joint");
  EXPECT_GE(r.q[1], -60.0);
}

TEST(InverseKinematicsTest, ApproachDirectionsKeepTheLastSignOfStillJoints) {
  const std::vector<double> s =
      ApproachDirections({0, 5, 3}, {1, 5, 2}, {-1, -1, 1});
  EXPECT_EQ(s, (std::vector<double>{1, -1, -1}));
  EXPECT_EQ(ApproachDirections({}, {1, 2}, {}), (std::vector<double>{0, 0}));
}

}  // namespace
}  // namespace kincal
