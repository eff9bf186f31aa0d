#include "plan/iso9283_cube.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <limits>

#include "calib/chain.h"
#include "calib/inverse_kinematics.h"
#include "data/error.h"
#include "data/observations.h"
#include "data/rigid3.h"
#include "tests/testing/paths.h"

namespace kincal {
namespace {

Robot LoadRobot(const std::string& name) {
  return ReadRobotYaml(testing::SourceDir() + "/data/robots/" + name);
}

std::vector<double> Internal(const Chain& chain, const std::vector<double>& q) {
  std::vector<double> qi(q.size());
  for (size_t j = 0; j < q.size(); ++j) {
    qi[j] = chain.ReadingToInternal(static_cast<int>(j), q[j]);
  }
  return qi;
}

// The message of the InputError `plan` throws ("" when none).
std::string Refusal(const Robot& robot, const IsoCubeOptions& options) {
  try {
    PlanIsoCube(robot, options);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(IsoCubeTest, PositionsAreTheStandards) {
  const Eigen::Vector3d c(100, -200, 300);
  const double a = 400;
  const auto corners = IsoCubePlaneCorners(c, a);  // C1 C2 C7 C8
  // The plane C1-C2-C7-C8: two opposite edges of the cube (length a),
  // joined by face diagonals (a sqrt 2); its diagonals are the cube's
  // (a sqrt 3) and cross at the centre.
  EXPECT_NEAR((corners[1] - corners[0]).norm(), a, 1e-9);
  EXPECT_NEAR((corners[3] - corners[2]).norm(), a, 1e-9);
  EXPECT_NEAR((corners[2] - corners[1]).norm(), a * std::sqrt(2.0), 1e-9);
  EXPECT_NEAR((corners[2] - corners[0]).norm(), a * std::sqrt(3.0), 1e-9);
  EXPECT_NEAR((corners[3] - corners[1]).norm(), a * std::sqrt(3.0), 1e-9);
  for (const auto& corner : corners) {
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(std::abs(corner[k] - c[k]), a / 2, 1e-9);  // a cube corner
    }
  }
  const auto p = IsoCubePositions(c, a);
  EXPECT_NEAR((p[0] - c).norm(), 0.0, 1e-12);  // P1: the centre
  const double diagonal = a * std::sqrt(3.0);
  // P2..P5 next to C1, C2, C7, C8, on the diagonal to the opposite corner.
  const int corner_of[4] = {0, 1, 2, 3}, opposite_of[4] = {2, 3, 0, 1};
  const Eigen::Vector3d normal =
      (corners[1] - corners[0]).cross(corners[3] - corners[0]).normalized();
  for (int i = 1; i <= 4; ++i) {
    const Eigen::Vector3d& corner = corners[corner_of[i - 1]];
    const Eigen::Vector3d& other = corners[opposite_of[i - 1]];
    EXPECT_NEAR((p[i] - corner).norm(), 0.1 * diagonal, 1e-9) << "P" << i + 1;
    EXPECT_NEAR((p[i] - corner).norm() + (other - p[i]).norm(), diagonal,
                1e-9);                                        // on the diagonal
    EXPECT_NEAR((p[i] - corners[0]).dot(normal), 0.0, 1e-9);  // on the plane
  }
  EXPECT_NEAR((p[0] - corners[0]).dot(normal), 0.0, 1e-9);
  // The order of a cycle: P5 P4 P3 P2 P1.
  EXPECT_EQ(IsoCubeCycleOrder(), (std::array<int, 5>{4, 3, 2, 1, 0}));
}

// Every planned row reaches its position (and the fixed orientation) by the
// nominal forward kinematics, within the limits less the margin, clear of
// obstacles, at the standard's positions.
void ExpectPlanHolds(const Robot& robot, const IsoCubeOptions& options,
                     const IsoCubePlan& plan) {
  const Chain chain = Chain::FromRobot(robot);
  const auto positions = IsoCubePositions(plan.center_mm, plan.cube_mm);
  for (int i = 0; i < 5; ++i) {
    const IsoCubePose& pose = plan.poses[i];
    EXPECT_EQ(pose.label, "P" + std::to_string(i + 1));
    EXPECT_LT((pose.position_mm - positions[i]).norm(), 1e-12);
    ASSERT_EQ(pose.joints.size(), robot.joints.size());
    const Eigen::Matrix4d at = ModelPoseAtReadings(chain, pose.joints, {});
    EXPECT_LT((at.block<3, 1>(0, 3) - pose.position_mm).norm(), 1e-6)
        << pose.label;
    if (plan.fixed_orientation) {
      const Eigen::AngleAxisd off(at.block<3, 3>(0, 0) *
                                  plan.rotation.transpose());
      EXPECT_LT(off.angle() * 180 / M_PI, 1e-6) << pose.label;
    }
    for (size_t j = 0; j < robot.joints.size(); ++j) {
      const RobotRow& row = robot.joints[j];
      const double keep = options.limit_margin * (row.upper - row.lower);
      EXPECT_GE(pose.joints[j], row.lower + keep - 1e-9) << row.name;
      EXPECT_LE(pose.joints[j], row.upper - keep + 1e-9) << row.name;
    }
    EXPECT_EQ(
        FindContact(chain, Internal(chain, pose.joints), options.safety).kind,
        Contact::kNone);
  }
}

TEST(IsoCubeTest, Ur10HoldsPositionsAndOneOrientation) {
  const Robot robot = LoadRobot("ur10.yaml");
  IsoCubeOptions options;
  options.cube_mm = 400;
  const IsoCubePlan plan = PlanIsoCube(robot, options);
  EXPECT_TRUE(plan.fixed_orientation);
  ExpectPlanHolds(robot, options, plan);
  // The default centre is a feasible tip (within the arm's reach).
  EXPECT_LT(plan.center_mm.norm(), 1500.0);
  // Whole turns moved toward the middle of the +-360 deg ranges: every
  // joint's mean over the five poses within half a turn of 0.
  for (size_t j = 0; j < robot.joints.size(); ++j) {
    double mean = 0;
    for (const IsoCubePose& pose : plan.poses) mean += pose.joints[j] / 5;
    EXPECT_LE(std::abs(mean), 180.0) << robot.joints[j].name;
  }
}

TEST(IsoCubeTest, Bh7HoldsPositionsWithoutOrientation) {
  const Robot robot = LoadRobot("bh7.yaml");
  IsoCubeOptions options;
  options.cube_mm = 100;
  const IsoCubePlan plan = PlanIsoCube(robot, options);
  EXPECT_FALSE(plan.fixed_orientation);
  ExpectPlanHolds(robot, options, plan);
}

TEST(IsoCubeTest, GivenCentreAndOrientationAreHeld) {
  const Robot robot = LoadRobot("ur10.yaml");
  IsoCubeOptions options;
  options.cube_mm = 300;
  options.center_mm = Eigen::Vector3d(-600, -300, 400);
  options.orientation_deg = Eigen::Vector3d(180, 0, 0);  // tool z down
  const IsoCubePlan plan = PlanIsoCube(robot, options);
  EXPECT_LT((plan.center_mm - *options.center_mm).norm(), 1e-12);
  EXPECT_LT(
      (plan.rotation - RotationMatrixFromVector(Eigen::Vector3d(M_PI, 0, 0)))
          .norm(),
      1e-12);
  ExpectPlanHolds(robot, options, plan);
  const Chain chain = Chain::FromRobot(robot);
  const Eigen::Matrix4d p1 =
      ModelPoseAtReadings(chain, plan.poses[0].joints, {});
  EXPECT_NEAR(p1(2, 2), -1.0, 1e-9);  // the tool's z axis points down
}

TEST(IsoCubeTest, RowsVisitTheCyclesAndReadAsObservations) {
  const Robot robot = LoadRobot("bh7.yaml");
  IsoCubeOptions options;
  options.cube_mm = 80;
  options.cycles = 3;
  const IsoCubePlan plan = PlanIsoCube(robot, options);
  ASSERT_EQ(plan.rows.size(), 15u);
  const char* order[5] = {"P5", "P4", "P3", "P2", "P1"};
  std::vector<std::string> names;
  for (const RobotRow& row : robot.joints) names.push_back(row.name);
  const Observations obs =
      ParseObservationsCsv(FormatIsoCubeCsv(robot, plan), "poses.csv", names);
  ASSERT_EQ(obs.rows.size(), 15u);
  for (size_t r = 0; r < obs.rows.size(); ++r) {
    EXPECT_EQ(obs.rows[r].pose, std::to_string(r));
    EXPECT_EQ(obs.rows[r].fixed_point, order[r % 5]) << r;
    EXPECT_FALSE(obs.rows[r].has_point);
    const IsoCubePose& pose = plan.poses[plan.rows[r]];
    EXPECT_EQ(pose.label, order[r % 5]);
    for (size_t j = 0; j < names.size(); ++j) {
      EXPECT_NEAR(obs.rows[r].q[j], pose.joints[j], 1e-9);
    }
  }
}

TEST(IsoCubeTest, TooLargeCubeIsRefusedNamingThePosition) {
  IsoCubeOptions options;
  options.cube_mm = 3000;  // its P2..P5 lie 2.1 m from the centre
  const std::string ur10 = Refusal(LoadRobot("ur10.yaml"), options);
  EXPECT_NE(ur10.find("does not fit: P2 at ("), std::string::npos) << ur10;
  EXPECT_NE(ur10.find("unreachable"), std::string::npos) << ur10;
  options.cube_mm = 600;
  const std::string bh7 = Refusal(LoadRobot("bh7.yaml"), options);
  EXPECT_NE(bh7.find("does not fit: P"), std::string::npos) << bh7;
}

TEST(IsoCubeTest, CollisionAndLimitAreNamed) {
  IsoCubeOptions options;
  options.cube_mm = 200;
  options.safety.obstacles.planes.push_back(
      {"table", Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ(), 20});
  options.center_mm = Eigen::Vector3d(-700, 0, 50);  // P1 60 mm too low
  const std::string low = Refusal(LoadRobot("ur10.yaml"), options);
  EXPECT_NE(low.find("P1 at (-700.0, 0.0, 50.0) mm is in collision: plane "
                     "'table' is met"),
            std::string::npos)
      << low;
  // The elbow may not bend past 30 deg: a cube near the base needs more.
  Robot tight = LoadRobot("ur10.yaml");
  tight.joints[2].lower = -30;
  tight.joints[2].upper = 30;
  IsoCubeOptions near_base;
  near_base.cube_mm = 200;
  near_base.limit_margin = 0;
  near_base.center_mm = Eigen::Vector3d(-300, -300, 300);
  const std::string limit = Refusal(tight, near_base);
  EXPECT_NE(limit.find("is beyond a joint limit: joint 'elbow_joint'"),
            std::string::npos)
      << limit;
}

TEST(IsoCubeTest, BadOptionsAreRefused) {
  IsoCubeOptions options;
  EXPECT_NE(Refusal(LoadRobot("bh7.yaml"), options).find("--cube"),
            std::string::npos);
  options.cube_mm = 50;
  options.orientation_deg = Eigen::Vector3d(180, 0, 0);
  EXPECT_NE(Refusal(LoadRobot("bh7.yaml"), options).find("--orientation"),
            std::string::npos);
  options.orientation_deg.reset();
  options.cycles = 0;
  EXPECT_NE(Refusal(LoadRobot("bh7.yaml"), options).find("--cycles"),
            std::string::npos);
  options.cycles = 30;
  Robot no_limits = LoadRobot("bh7.yaml");
  no_limits.joints[2].lower = std::numeric_limits<double>::quiet_NaN();
  EXPECT_NE(Refusal(no_limits, options).find("joint 'j3' has no limits"),
            std::string::npos);
}

}  // namespace
}  // namespace kincal
