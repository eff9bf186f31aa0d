#include "data/urdf.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "data/atomic_file.h"
#include "data/error.h"
#include "tests/testing/paths.h"

namespace kincal {
namespace {

const char* kTwoLink = R"(<?xml version="1.0"?>
<robot name="two">
  <link name="base"/><link name="l1"/><link name="l2"/><link name="flange"/>
  <joint name="a" type="revolute">
    <parent link="base"/><child link="l1"/>
    <origin xyz="0 0 0.333" rpy="0 0 0"/><axis xyz="0 0 1"/>
    <limit lower="-2.8973" upper="2.8973" effort="87" velocity="2"/>
  </joint>
  <joint name="fix" type="fixed">
    <parent link="l1"/><child link="l2"/><origin xyz="0.1 0 0" rpy="0 0 1.5707963267948966"/>
  </joint>
  <joint name="b" type="prismatic">
    <parent link="l2"/><child link="flange"/><axis xyz="1 0 0"/>
    <origin xyz="0 0 0.2" rpy="0 0 0"/>
    <limit lower="-0.1" upper="0.1" effort="10" velocity="1"/>
  </joint>
</robot>)";

TEST(UrdfTest, FoldsFixedJointsAndConvertsUnits) {
  const Robot r = ParseUrdfChain(kTwoLink, "two.urdf");
  EXPECT_EQ(r.convention, Convention::kUrdf);
  ASSERT_EQ(r.joints.size(), 2u);
  EXPECT_EQ(r.joints[0].name, "a");
  EXPECT_NEAR(r.joints[0].xyz_mm.z(), 333.0, 1e-9);
  EXPECT_NEAR(r.joints[0].upper, 2.8973 * 180 / M_PI, 1e-9);
  EXPECT_EQ(r.joints[1].type, JointType::kPrismatic);
  // fixed (0.1, 0, 0, yaw 90deg) folded into b's origin (0, 0, 0.2)
  EXPECT_NEAR(r.joints[1].xyz_mm.x(), 100.0, 1e-9);
  EXPECT_NEAR(r.joints[1].xyz_mm.z(), 200.0, 1e-9);
  EXPECT_NEAR(r.joints[1].rpy_deg.z(), 90.0, 1e-9);
}

TEST(UrdfTest, RejectsBrokenFiles) {
  EXPECT_THROW(ParseUrdfChain("<robot><joint", "x.urdf"), InputError);
  EXPECT_THROW(ParseUrdfChain(kTwoLink, "x.urdf", "base", "nowhere"),
               InputError);
  try {
    std::string bad = kTwoLink;
    bad.replace(bad.find("0 0 0.333"), 9, "0 0");
    ParseUrdfChain(bad, "x.urdf");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), ::testing::HasSubstr("x.urdf:6:"));
  }
}

// Issue 7: a ROS-Industrial style description (fixed flange and tool0
// joints carrying <axis xyz="0 0 0"/>, which the URDF spec ignores) loads.
TEST(UrdfTest, LoadsRosIndustrialStyleArmWithZeroAxesOnFixedJoints) {
  const Robot r =
      ReadUrdfChain(testing::SourceDir() + "/data/robots/industrial7.urdf");
  ASSERT_EQ(r.joints.size(), 7u);
  EXPECT_EQ(r.joints[0].name, "joint_a1");
  EXPECT_EQ(r.joints[6].name, "joint_a7");
  EXPECT_NEAR(r.joints[3].axis.y(), -1.0, 1e-12);
  EXPECT_NEAR(r.tool.xyz_mm.z(), 45.0, 1e-9);  // flange + tool0 folded
  EXPECT_DOUBLE_EQ(r.bound_length_mm, 20.0);
  // A zero axis on a movable joint is still an error, with its line.
  std::string text =
      ReadFile(testing::SourceDir() + "/data/robots/industrial7.urdf");
  text.replace(text.find("<axis xyz=\"0 1 0\"/>"), 19, "<axis xyz=\"0 0 0\"/>");
  try {
    ParseUrdfChain(text, "i7.urdf");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), ::testing::HasSubstr("i7.urdf:"));
    EXPECT_THAT(e.what(), ::testing::HasSubstr("axis"));
  }
}

TEST(UrdfTest, LoadsMukcaPanda) {
  KINCAL_REQUIRE_SHARED_DATA("mukca");
  const std::string path =
      testing::SharedDataDir() +
      "/mukca/calibrated_urdf/panda_2/panda_calibrated.urdf";
  if (!testing::Exists(path)) GTEST_SKIP() << path << " absent";
  const Robot r = ReadUrdfChain(path, "panda_link0", "panda_link8");
  EXPECT_EQ(r.joints.size(), 7u);
}

}  // namespace
}  // namespace kincal
