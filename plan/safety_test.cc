#include "plan/safety.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>

#include "data/robot.h"
#include "tests/testing/paths.h"

namespace kincal {
namespace {

Segment Seg(double ax, double ay, double az, double bx, double by, double bz) {
  return {Eigen::Vector3d(ax, ay, az), Eigen::Vector3d(bx, by, bz)};
}

TEST(Safety, SegmentPlaneDistanceIsTheLowerEndpoint) {
  ObstaclePlane table;  // z = 10, free side +z
  table.point = Eigen::Vector3d(5, 5, 10);
  EXPECT_DOUBLE_EQ(SegmentPlaneDistance(Seg(0, 0, 50, 100, 0, 30), table), 20);
  EXPECT_DOUBLE_EQ(SegmentPlaneDistance(Seg(0, 0, 50, 0, 0, -40), table), -50);
  ObstaclePlane wall;  // x = 100, free side -x
  wall.point = Eigen::Vector3d(100, 0, 0);
  wall.normal = Eigen::Vector3d(-1, 0, 0);
  EXPECT_DOUBLE_EQ(SegmentPlaneDistance(Seg(0, 0, 0, 70, 3, 9), wall), 30);
}

TEST(Safety, SegmentBoxDistanceKnownGeometry) {
  ObstacleBox box;  // [-50, 50] x [-20, 20] x [0, 200]
  box.center = Eigen::Vector3d(0, 0, 100);
  box.size = Eigen::Vector3d(100, 40, 200);
  // Parallel to the +x face, 30 mm out.
  EXPECT_NEAR(SegmentBoxDistance(Seg(80, -100, 50, 80, 100, 50), box), 30,
              1e-6);
  // Passing through the box.
  EXPECT_NEAR(SegmentBoxDistance(Seg(-200, 0, 100, 200, 0, 100), box), 0, 1e-9);
  // Nearest an edge: from the corner line x = 50, y = 20 diagonally out.
  EXPECT_NEAR(SegmentBoxDistance(Seg(80, 60, 0, 80, 60, 200), box), 50, 1e-6);
  // Endpoint nearest: the segment points away from the top face.
  EXPECT_NEAR(SegmentBoxDistance(Seg(0, 0, 210, 0, 0, 400), box), 10, 1e-6);
  // A box turned 45 deg about z: its corner reaches x = 50 sqrt(2) at y = 0
  // (a square 100 x 100 footprint).
  ObstacleBox turned = box;
  turned.size = Eigen::Vector3d(100, 100, 200);
  turned.base_from_box =
      Eigen::AngleAxisd(M_PI / 4, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  EXPECT_NEAR(SegmentBoxDistance(Seg(100, -5, 100, 100, 5, 100), turned),
              100 - 50 * std::sqrt(2.0), 1e-6);
}

TEST(Safety, SegmentSegmentDistanceKnownGeometry) {
  // Skew perpendicular lines 7 apart, crossing inside both segments.
  EXPECT_NEAR(SegmentSegmentDistance(Seg(-10, 0, 0, 10, 0, 0),
                                     Seg(0, -10, 7, 0, 10, 7)),
              7, 1e-12);
  // Parallel, overlapping: 3 apart.
  EXPECT_NEAR(
      SegmentSegmentDistance(Seg(0, 0, 0, 10, 0, 0), Seg(5, 3, 0, 15, 3, 0)), 3,
      1e-12);
  // Collinear with a gap of 4.
  EXPECT_NEAR(
      SegmentSegmentDistance(Seg(0, 0, 0, 10, 0, 0), Seg(14, 0, 0, 20, 0, 0)),
      4, 1e-12);
  // The crossing lies outside the second segment: endpoint to line.
  EXPECT_NEAR(
      SegmentSegmentDistance(Seg(-10, 0, 0, 10, 0, 0), Seg(0, 5, 2, 0, 10, 2)),
      std::sqrt(29.0), 1e-12);
  // A degenerate segment (a point).
  EXPECT_NEAR(
      SegmentSegmentDistance(Seg(3, 4, 0, 3, 4, 0), Seg(0, 0, 0, 0, 0, 0)), 5,
      1e-12);
}

Chain Ur10Chain() {
  return Chain::FromRobot(
      ReadRobotYaml(testing::SourceDir() + "/data/robots/ur10.yaml"));
}

TEST(Safety, Ur10CapsulesFollowTheDhChain) {
  const Chain chain = Ur10Chain();
  // All joints 0: the UR10's zero pose stretches the arm along -x at the
  // shoulder height (d1 = 127.3 mm), wrist offsets d4, d5, d6 + tool.
  const LinkCapsules links = LinkSegments(chain, std::vector<double>(6, 0.0));
  ASSERT_EQ(links.segments.size(), 6u);
  EXPECT_EQ(links.base_count, 1);
  EXPECT_NEAR(links.segments[0].b.z(), 127.3, 1e-9);
  EXPECT_NEAR((links.segments[1].b - links.segments[1].a).norm(), 612, 1e-9);
  EXPECT_NEAR((links.segments[2].b - links.segments[2].a).norm(), 572.3, 1e-9);
  EXPECT_NEAR((links.segments[5].b - links.segments[5].a).norm(), 92.2 + 93.0,
              1e-9);
}

TEST(Safety, TablePlaneRejectsALoweredArmButNotTheBase) {
  const Chain chain = Ur10Chain();
  SafetyOptions options;
  ObstaclePlane table;  // the base stands on z = 0
  table.name = "table";
  table.clearance_mm = 20;
  options.obstacles.planes.push_back(table);
  options.self_collision = false;
  // Zero pose: the arm horizontal at 127.3 mm, the wrist hanging down by
  // d5 = 115.7 mm to 11.6 mm above the table (radius + clearance = 60 mm).
  std::vector<double> q(6, 0.0);
  const Contact wrist = FindContact(chain, q, options);
  EXPECT_EQ(wrist.kind, Contact::kPlane);
  EXPECT_GE(wrist.link, 3);
  EXPECT_EQ(wrist.Describe(options), "plane 'table'");
  q[1] = -M_PI / 6;  // the shoulder lifts the arm 30 deg up
  EXPECT_EQ(FindContact(chain, q, options).kind, Contact::kNone);
  q[1] = M_PI / 6;  // and down: the elbow goes below the table
  const Contact elbow = FindContact(chain, q, options);
  EXPECT_EQ(elbow.kind, Contact::kPlane);
  EXPECT_EQ(elbow.link, 1);
  // A plane away from the base origin is checked for the base too: a
  // ceiling 100 mm above the base meets the column (link 0).
  options.obstacles.planes[0].point.z() = 100;
  options.obstacles.planes[0].normal = -Eigen::Vector3d::UnitZ();
  q[1] = -M_PI / 6;
  EXPECT_EQ(FindContact(chain, q, options).kind, Contact::kPlane);
  EXPECT_EQ(FindContact(chain, q, options).link, 0);
}

TEST(Safety, BoxAndSelfCollision) {
  const Chain chain = Ur10Chain();
  SafetyOptions options;
  options.self_collision = false;
  ObstacleBox stand;  // a post where the stretched arm's wrist is
  stand.name = "stand";
  stand.center = Eigen::Vector3d(-1184, -164, 500);
  stand.size = Eigen::Vector3d(100, 100, 1000);
  options.obstacles.boxes.push_back(stand);
  std::vector<double> q(6, 0.0);
  EXPECT_EQ(FindContact(chain, q, options).kind, Contact::kBox);
  q[0] = M_PI / 2;  // turned away
  EXPECT_EQ(FindContact(chain, q, options).kind, Contact::kNone);
  options.obstacles.boxes.clear();
  options.self_collision = true;
  // The elbow folded back fully: the forearm lies on the upper arm.
  q = std::vector<double>(6, 0.0);
  q[2] = M_PI * 175 / 180;
  const Contact folded = FindContact(chain, q, options);
  EXPECT_EQ(folded.kind, Contact::kSelf);
  q[2] = M_PI / 2;
  EXPECT_EQ(FindContact(chain, q, options).kind, Contact::kNone);
}

}  // namespace
}  // namespace kincal
