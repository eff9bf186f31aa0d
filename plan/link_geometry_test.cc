#include "plan/link_geometry.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>

#include "calib/chain.h"
#include "data/atomic_file.h"
#include "data/urdf.h"
#include "plan/plan.h"
#include "plan/safety.h"
#include "tests/testing/paths.h"

namespace kincal {
namespace {

// A 3-joint arm whose links carry every kind of collision element: the base
// a cylinder, link 1 a box, link 2 a cylinder turned along x, link 3 an STL
// mesh (a 300 x 60 x 60 mm bar), the tool (fixed to link 3) a sphere.
std::string TinyUrdf(const std::string& l3_mesh) {
  return R"(<?xml version="1.0"?>
<robot name="tiny">
  <link name="base"><collision><origin xyz="0 0 0.05"/>
    <geometry><cylinder radius="0.08" length="0.1"/></geometry></collision></link>
  <link name="l1"><collision><origin xyz="0 0 0.15"/>
    <geometry><box size="0.1 0.1 0.3"/></geometry></collision></link>
  <link name="l2"><collision><origin xyz="0.2 0 0" rpy="0 1.5707963267948966 0"/>
    <geometry><cylinder radius="0.04" length="0.4"/></geometry></collision></link>
  <link name="l3"><collision><origin xyz="0.15 0 0"/>
    <geometry><mesh filename=")" +
         l3_mesh + R"("/></geometry></collision></link>
  <link name="tool"><collision>
    <geometry><sphere radius="0.03"/></geometry></collision></link>
  <joint name="j1" type="revolute"><origin xyz="0 0 0.1"/><parent link="base"/>
    <child link="l1"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <joint name="j2" type="revolute"><origin xyz="0 0 0.3"/><parent link="l1"/>
    <child link="l2"/><axis xyz="0 1 0"/>
    <limit lower="-2" upper="2" effort="1" velocity="1"/></joint>
  <joint name="j3" type="revolute"><origin xyz="0.4 0 0"/><parent link="l2"/>
    <child link="l3"/><axis xyz="0 1 0"/>
    <limit lower="-2.5" upper="2.5" effort="1" velocity="1"/></joint>
  <joint name="tool_joint" type="fixed"><origin xyz="0.3 0 0"/>
    <parent link="l3"/><child link="tool"/></joint>
</robot>
)";
}

// An ASCII STL of a bar [-0.15, 0.15] x [-0.03, 0.03]^2 m (two facets
// spanning its corners).
std::string WriteBarStl(const std::string& dir) {
  WriteFileAtomic(dir + "/bar.stl",
                  "solid bar\n"
                  " facet normal 0 0 1\n  outer loop\n"
                  "   vertex -0.15 -0.03 -0.03\n   vertex 0.15 -0.03 -0.03\n"
                  "   vertex 0.15 0.03 -0.03\n  endloop\n endfacet\n"
                  " facet normal 0 0 1\n  outer loop\n"
                  "   vertex -0.15 0.03 0.03\n   vertex 0.15 0.03 0.03\n"
                  "   vertex 0.15 -0.03 0.03\n  endloop\n endfacet\n"
                  "endsolid bar\n");
  return "bar.stl";
}

struct Tiny {
  std::string dir, xml;
  Robot robot;
};

Tiny MakeTiny() {
  Tiny t;
  t.dir = testing::MakeTempDir("link_geometry");
  t.xml = TinyUrdf(WriteBarStl(t.dir));
  t.robot = ParseUrdfChain(t.xml, "tiny.urdf");
  return t;
}

void ExpectCapsule(const LinkCapsule& c, const std::string& link, int frame,
                   const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                   double radius, double tolerance = 1e-6) {
  EXPECT_EQ(c.link, link);
  EXPECT_EQ(c.frame, frame) << link;
  const bool same =
      (c.a - a).norm() < tolerance && (c.b - b).norm() < tolerance;
  const bool swapped =
      (c.a - b).norm() < tolerance && (c.b - a).norm() < tolerance;
  EXPECT_TRUE(same || swapped)
      << link << ": " << c.a.transpose() << " / " << c.b.transpose();
  EXPECT_NEAR(c.radius_mm, radius, tolerance) << link;
}

TEST(LinkGeometry, EveryElementKindBecomesItsEnclosingCapsule) {
  const Tiny t = MakeTiny();
  const LinkGeometry g = ParseUrdfLinkGeometry(t.xml, t.dir, t.robot);
  EXPECT_TRUE(g.warnings.empty());
  ASSERT_EQ(g.capsules.size(), 5u);
  using V = Eigen::Vector3d;
  ExpectCapsule(g.capsules[0], "base", -1, V(0, 0, 0), V(0, 0, 100), 80);
  ExpectCapsule(g.capsules[1], "l1", 0, V(0, 0, 0), V(0, 0, 300),
                50 * std::sqrt(2.0));
  ExpectCapsule(g.capsules[2], "l2", 1, V(0, 0, 0), V(400, 0, 0), 40);
  ExpectCapsule(g.capsules[3], "l3", 2, V(0, 0, 0), V(300, 0, 0),
                30 * std::sqrt(2.0));
  ExpectCapsule(g.capsules[4], "tool", 2, V(300, 0, 0), V(300, 0, 0), 30);
}

// The same bar as a binary STL and as an OBJ gives the same capsule.
TEST(LinkGeometry, BinaryStlAndObjMeshesAreRead) {
  const Tiny t = MakeTiny();
  const float corners[2][3][3] = {
      {{-0.15f, -0.03f, -0.03f},
       {0.15f, -0.03f, -0.03f},
       {0.15f, 0.03f, -0.03f}},
      {{-0.15f, 0.03f, 0.03f}, {0.15f, 0.03f, 0.03f}, {0.15f, -0.03f, 0.03f}}};
  std::string stl(80, ' ');
  const uint32_t triangles = 2;
  stl.append(reinterpret_cast<const char*>(&triangles), 4);
  for (const auto& triangle : corners) {
    const float normal[3] = {0, 0, 1};
    stl.append(reinterpret_cast<const char*>(normal), 12);
    stl.append(reinterpret_cast<const char*>(triangle), 36);
    stl.append(2, '\0');
  }
  WriteFileAtomic(t.dir + "/bar_binary.stl", stl);
  WriteFileAtomic(t.dir + "/bar.obj",
                  "v -0.15 -0.03 -0.03\nv 0.15 0.03 0.03\nf 1 2 1\n");
  for (const char* mesh : {"bar_binary.stl", "bar.obj"}) {
    const LinkGeometry g =
        ParseUrdfLinkGeometry(TinyUrdf(mesh), t.dir, t.robot);
    ASSERT_EQ(g.capsules.size(), 5u) << mesh;
    // float32 vertices: 1e-5 mm.
    ExpectCapsule(g.capsules[3], "l3", 2, Eigen::Vector3d(0, 0, 0),
                  Eigen::Vector3d(300, 0, 0), 30 * std::sqrt(2.0), 1e-4);
  }
}

// The chain's frames carry the URDF's links: the frames against the
// transforms written out from the file.
TEST(LinkGeometry, ChainFramesAreTheUrdfLinkFrames) {
  const Tiny t = MakeTiny();
  const Chain chain = Chain::FromRobot(t.robot);
  const std::vector<double> q = {0.3, -0.7, 1.1};
  const std::vector<Eigen::Matrix4d> frames = BaseFromLinkFrames(chain, q);
  ASSERT_EQ(frames.size(), 4u);
  Eigen::Isometry3d m = Eigen::Isometry3d::Identity();
  m = m * Eigen::Translation3d(0, 0, 100) *
      Eigen::AngleAxisd(q[0], Eigen::Vector3d::UnitZ());
  EXPECT_LT((frames[1] - m.matrix()).norm(), 1e-9);
  m = m * Eigen::Translation3d(0, 0, 300) *
      Eigen::AngleAxisd(q[1], Eigen::Vector3d::UnitY());
  EXPECT_LT((frames[2] - m.matrix()).norm(), 1e-9);
  m = m * Eigen::Translation3d(400, 0, 0) *
      Eigen::AngleAxisd(q[2], Eigen::Vector3d::UnitY());
  EXPECT_LT((frames[3] - m.matrix()).norm(), 1e-9);
  EXPECT_LT((BaseFromTipAt(chain, q).block<3, 1>(0, 3) -
             m * Eigen::Vector3d(300, 0, 0))
                .norm(),
            1e-9);
}

TEST(LinkGeometry, UnreadableOrMissingGeometryFallsBackWithAWarning) {
  const Tiny t = MakeTiny();
  LinkGeometry g = ParseUrdfLinkGeometry(
      TinyUrdf("package://tiny/meshes/l3.stl"), t.dir, t.robot);
  EXPECT_TRUE(g.empty());
  ASSERT_EQ(g.warnings.size(), 1u);
  EXPECT_NE(
      g.warnings[0].find("link 'l3': mesh 'package://tiny/meshes/l3.stl'"),
      std::string::npos)
      << g.warnings[0];
  g = ParseUrdfLinkGeometry(TinyUrdf("missing.dae"), t.dir, t.robot);
  EXPECT_TRUE(g.empty());
  EXPECT_NE(g.warnings.at(0).find("not a readable STL or OBJ"),
            std::string::npos);
  // The repository's 7-joint arm: package:// meshes.
  const std::string industrial7 =
      testing::SourceDir() + "/data/robots/industrial7.urdf";
  g = ReadUrdfLinkGeometry(industrial7, ReadRobot(industrial7));
  EXPECT_TRUE(g.empty());
  EXPECT_NE(g.warnings.at(0).find("package://"), std::string::npos);
  // The Panda of the shared data: no <collision> at all.
  const std::string panda = testing::SharedDataDir() + "/mukca/urdf/panda.urdf";
  if (testing::Exists(panda)) {
    g = ReadUrdfLinkGeometry(panda, ReadRobot(panda, "", "panda_hand"));
    EXPECT_TRUE(g.empty());
    EXPECT_NE(g.warnings.at(0).find("no <collision>"), std::string::npos);
  }
}

TEST(LinkGeometry, AlwaysTouchingPairsAreFound) {
  const Tiny t = MakeTiny();
  const Chain chain = Chain::FromRobot(t.robot);
  LinkGeometry g = ParseUrdfLinkGeometry(t.xml, t.dir, t.robot);
  MarkAlwaysTouching(chain, t.robot, &g);
  EXPECT_TRUE(g.always_touching.empty());
  // A sphere of 500 mm on link 1's frame covers the origin of joint 3's
  // frame (400 mm from it at most): link 1 and link 3 always touch.
  LinkCapsule big;
  big.link = "l1";
  big.frame = 0;
  big.a = big.b = Eigen::Vector3d(0, 0, 300);
  big.radius_mm = 500;
  g.capsules.insert(g.capsules.begin() + 2, big);
  MarkAlwaysTouching(chain, t.robot, &g);
  EXPECT_NE(std::find(g.always_touching.begin(), g.always_touching.end(),
                      std::make_pair(2, 4)),
            g.always_touching.end());
}

// The lowest point (z, base frame) of the tiny arm's true shapes beyond
// link 1 (the base and link 1 stand on the table) at joint values q
// (radians), written out from the URDF: link 2's cylinder exactly, link 3's
// bar by its 8 corners, the tool's sphere.
double LowestShapeZ(const std::vector<double>& q) {
  const Eigen::Isometry3d l1 =
      Eigen::Translation3d(0, 0, 100) *
      Eigen::AngleAxisd(q[0], Eigen::Vector3d::UnitZ());
  const Eigen::Isometry3d l2 =
      l1 * Eigen::Translation3d(0, 0, 300) *
      Eigen::AngleAxisd(q[1], Eigen::Vector3d::UnitY());
  const Eigen::Isometry3d l3 =
      l2 * Eigen::Translation3d(400, 0, 0) *
      Eigen::AngleAxisd(q[2], Eigen::Vector3d::UnitY());
  // Cylinder along l2's x from 0 to 400, radius 40.
  const Eigen::Vector3d axis = l2.linear() * Eigen::Vector3d::UnitX();
  const double rim = 40 * std::sqrt(std::max(0.0, 1 - axis.z() * axis.z()));
  double lowest = std::min((l2 * Eigen::Vector3d(0, 0, 0)).z(),
                           (l2 * Eigen::Vector3d(400, 0, 0)).z()) -
                  rim;
  for (int k = 0; k < 8; ++k) {
    const Eigen::Vector3d corner(k & 1 ? 300 : 0, k & 2 ? 30 : -30,
                                 k & 4 ? 30 : -30);
    lowest = std::min(lowest, (l3 * corner).z());
  }
  return std::min(lowest, (l3 * Eigen::Vector3d(300, 0, 0)).z() - 30);
}

std::vector<double> Radians(const std::vector<double>& deg) {
  std::vector<double> rad;
  for (double d : deg) rad.push_back(d * M_PI / 180);
  return rad;
}

// plan with a table under the tiny arm: no planned, random or evaluation
// pose puts a true shape within the clearance of the table, checked on the
// shapes themselves; without the table some do.
TEST(LinkGeometry, PlanWithATableKeepsTheShapesAboveIt) {
  const Tiny t = MakeTiny();
  PlanOptions options;
  options.n = 12;
  options.candidates = 300;
  options.evaluation_poses = 100;
  options.safety.links = ParseUrdfLinkGeometry(t.xml, t.dir, t.robot);
  MarkAlwaysTouching(Chain::FromRobot(t.robot), t.robot, &options.safety.links);
  const PlanResult free = PlanPoses(t.robot, options);
  int below = 0;
  for (const auto& q : free.evaluation_poses)
    below += LowestShapeZ(Radians(q)) < 0;
  EXPECT_GT(below, 10) << "the arm should reach under the table's plane";

  ObstaclePlane table;
  table.name = "table";
  table.clearance_mm = 10;
  options.safety.obstacles.planes.push_back(table);
  const PlanResult plan = PlanPoses(t.robot, options);
  EXPECT_GT(plan.collisions.at("plane 'table'"), 0);
  std::vector<std::vector<double>> all = plan.poses;
  all.insert(all.end(), plan.random_poses.begin(), plan.random_poses.end());
  all.insert(all.end(), plan.evaluation_poses.begin(),
             plan.evaluation_poses.end());
  double lowest = 1e9;
  for (const auto& q : all) lowest = std::min(lowest, LowestShapeZ(Radians(q)));
  EXPECT_GE(lowest, 10.0 - 1e-9);
  std::printf(
      "tiny arm: lowest shape point %.2f mm over %zu poses with the "
      "table (clearance 10 mm); %d of %zu evaluation poses below z = "
      "0 without it\n",
      lowest, all.size(), below, free.evaluation_poses.size());
}

}  // namespace
}  // namespace kincal
