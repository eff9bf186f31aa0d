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

// The Panda the MUKCa authors start from (nominal model): a tree whose hand
// branches into two fingers, the second a mimic of the first.
TEST(UrdfTest, NominalPandaChainsAndBranches) {
  KINCAL_REQUIRE_SHARED_DATA("mukca/urdf/panda.urdf");
  const std::string path = testing::SharedDataDir() + "/mukca/urdf/panda.urdf";
  const Robot r = ReadUrdfChain(path, "", "ball_link");
  ASSERT_EQ(r.joints.size(), 7u);
  EXPECT_EQ(r.name, "panda");
  EXPECT_EQ(r.joints[0].name, "panda_joint1");
  EXPECT_NEAR(r.joints[0].xyz_mm.z(), 333.0, 1e-9);
  EXPECT_NEAR(r.joints[1].rpy_deg.x(), -90.0, 1e-9);
  EXPECT_NEAR(r.joints[3].upper, -0.0698 * 180 / M_PI, 1e-9);
  EXPECT_FALSE(r.joints[0].HasMass());  // the file has no <inertial>
  // No tip: the hand branches into fingers; the message lists the leaves.
  try {
    ReadUrdfChain(path);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), ::testing::HasSubstr("branches"));
    EXPECT_THAT(e.what(), ::testing::HasSubstr("panda_leftfinger"));
    EXPECT_THAT(e.what(), ::testing::HasSubstr("--tip"));
  }
  // A chain through the mimic finger is refused, naming both joints.
  try {
    ReadUrdfChain(path, "", "panda_rightfinger");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), ::testing::HasSubstr("panda_finger_joint2"));
    EXPECT_THAT(e.what(), ::testing::HasSubstr("mimics 'panda_finger_joint1'"));
    EXPECT_THAT(e.what(), ::testing::ContainsRegex("panda.urdf:[0-9]+:[0-9]+"));
  }
  // The master finger is an ordinary prismatic joint (m -> mm).
  const Robot f = ReadUrdfChain(path, "", "panda_leftfinger");
  ASSERT_EQ(f.joints.size(), 8u);
  EXPECT_EQ(f.joints[7].type, JointType::kPrismatic);
  EXPECT_NEAR(f.joints[7].upper, 40.0, 1e-9);
}

// ROS-Industrial layout: a `base` frame beside link_1 does not stop the
// default chain; meshes, materials, transmissions and gazebo tags are
// ignored; inertials become row masses.
TEST(UrdfTest, Industrial7DefaultChainAndMasses) {
  const Robot r =
      ReadUrdfChain(testing::SourceDir() + "/data/robots/industrial7.urdf");
  ASSERT_EQ(r.joints.size(), 7u);
  EXPECT_NEAR(r.tool.xyz_mm.z(), 45.0, 1e-9);
  for (int j = 0; j < 7; ++j) {
    ASSERT_TRUE(r.joints[j].HasMass());
    EXPECT_NEAR(r.joints[j].mass_kg, 7.5 - j, 1e-12);
    EXPECT_NEAR(r.joints[j].com_mm.y(), 10.0, 1e-9);
    EXPECT_NEAR(r.joints[j].com_mm.z(), 100.0, 1e-9);
  }
  // The same file with the tip named explicitly gives the same chain.
  const Robot t =
      ReadUrdfChain(testing::SourceDir() + "/data/robots/industrial7.urdf",
                    "base_link", "tool0");
  EXPECT_EQ(t.joints.size(), 7u);
}

const char* kMimic = R"(<robot name="m">
  <link name="base"/><link name="a"/><link name="b"/>
  <joint name="master" type="revolute">
    <parent link="base"/><child link="a"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/>
  </joint>
  <joint name="follower" type="revolute">
    <parent link="a"/><child link="b"/><origin xyz="0.1 0 0"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/>
    <mimic joint="master" multiplier="2" offset="0.1"/>
  </joint>
</robot>)";

TEST(UrdfTest, MimicJointOnTheChainIsRefusedByName) {
  try {
    ParseUrdfChain(kMimic, "m.urdf");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), ::testing::HasSubstr("m.urdf:7:3:"));
    EXPECT_THAT(e.what(),
                ::testing::HasSubstr("joint 'follower' mimics 'master'"));
  }
  // Up to the master only, the chain is fine.
  EXPECT_EQ(ParseUrdfChain(kMimic, "m.urdf", "", "a").joints.size(), 1u);
  // A malformed multiplier is located at its attribute.
  std::string bad = kMimic;
  bad.replace(bad.find("multiplier=\"2\""), 14, "multiplier=\"x\"");
  try {
    ParseUrdfChain(bad, "m.urdf");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), ::testing::HasSubstr("m.urdf:10:27:"));
    EXPECT_THAT(e.what(), ::testing::HasSubstr("multiplier"));
  }
}

const char* kContinuous = R"(<robot name="c">
  <link name="base"/><link name="a"/><link name="b"/>
  <joint name="spin" type="continuous">
    <parent link="base"/><child link="a"/><origin xyz="0 0 0.5" rpy="0.1 -0.2 0.3"/>
  </joint>
  <joint name="lift" type="revolute">
    <parent link="a"/><child link="b"/><axis xyz="0 2 0"/>
    <limit lower="-1.5" upper="1.5" effort="1" velocity="1"/>
  </joint>
</robot>)";

TEST(UrdfTest, ContinuousJointsDefaultAxisAndRpy) {
  const Robot r = ParseUrdfChain(kContinuous, "c.urdf");
  ASSERT_EQ(r.joints.size(), 2u);
  EXPECT_EQ(r.joints[0].type, JointType::kRevolute);
  EXPECT_FALSE(r.joints[0].HasLimits());  // continuous: no limits
  // No <axis>: URDF's default (1, 0, 0).
  EXPECT_NEAR((r.joints[0].axis - Eigen::Vector3d::UnitX()).norm(), 0, 1e-15);
  // rpy is fixed-axis roll, pitch, yaw (R = Rz Ry Rx), read back unchanged.
  EXPECT_NEAR(r.joints[0].rpy_deg.x(), 0.1 * 180 / M_PI, 1e-9);
  EXPECT_NEAR(r.joints[0].rpy_deg.y(), -0.2 * 180 / M_PI, 1e-9);
  EXPECT_NEAR(r.joints[0].rpy_deg.z(), 0.3 * 180 / M_PI, 1e-9);
  EXPECT_NEAR((r.joints[1].axis - Eigen::Vector3d::UnitY()).norm(), 0, 1e-15);
  EXPECT_NEAR(r.joints[1].lower, -1.5 * 180 / M_PI, 1e-9);
  // ROS rejects a revolute joint without <limit>; so does kincal, at the
  // joint's line.
  std::string bad = kContinuous;
  bad.erase(bad.find("<limit"),
            bad.find("/>", bad.find("<limit")) + 2 - bad.find("<limit"));
  try {
    ParseUrdfChain(bad, "c.urdf");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), ::testing::HasSubstr("c.urdf:6:3:"));
    EXPECT_THAT(e.what(), ::testing::HasSubstr("does not specify limits"));
  }
}

// Default tip: at a branch, the one child with a movable joint below or
// into it; among fixed frames only (ROS-I ee_link and tool0 side by side),
// tool0.
TEST(UrdfTest, DefaultTipRules) {
  const std::string head = R"(<robot name="t">
  <link name="base"/><link name="a"/><link name="b"/><link name="cam"/>
  <link name="ee_link"/><link name="tool0"/>
  <joint name="j1" type="continuous"><parent link="base"/><child link="a"/></joint>
  <joint name="cam_mount" type="fixed"><parent link="a"/><child link="cam"/></joint>
  <joint name="j2" type="continuous"><parent link="a"/><child link="b"/>
    <origin xyz="0.2 0 0"/></joint>
  <joint name="ee" type="fixed"><parent link="b"/><child link="ee_link"/></joint>
  <joint name="t0" type="fixed"><parent link="b"/><child link="tool0"/>
    <origin xyz="0 0 0.1"/></joint>
</robot>)";
  const Robot r = ParseUrdfChain(head, "t.urdf");
  ASSERT_EQ(r.joints.size(), 2u);  // past the camera, j2 ends in a leaf
  EXPECT_NEAR(r.tool.xyz_mm.z(), 100.0, 1e-9);  // tool0, not ee_link
  std::string no_tool0 = head;
  no_tool0.replace(no_tool0.find("child link=\"tool0\""), 18,
                   "child link=\"tcp\"  ");
  no_tool0.replace(no_tool0.find("<link name=\"tool0\"/>"), 20,
                   "<link name=\"tcp\"/>  ");
  try {
    ParseUrdfChain(no_tool0, "t.urdf");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), ::testing::HasSubstr("link 'b' branches"));
  }
}

// Links hanging on fixed joints (and a side branch) are lumped into the row
// of the movable joint they ride on: mass sum, mass-weighted centre of mass
// in the frame after that row. Links before the first movable joint (the
// base) carry no row.
const char* kLumped = R"(<robot name="l">
  <link name="base"><inertial><mass value="50"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
  <link name="a"><inertial><origin xyz="0.1 0 0"/><mass value="2"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
  <link name="motor"><inertial><origin xyz="0 0.05 0"/><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
  <link name="b"><inertial><origin xyz="0 0 0.2"/><mass value="3"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
  <link name="tool"><inertial><origin xyz="0.01 0 0"/><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
  <joint name="j1" type="continuous"><parent link="base"/><child link="a"/><axis xyz="0 0 1"/></joint>
  <joint name="motor_mount" type="fixed"><parent link="a"/><child link="motor"/>
    <origin xyz="0.3 0 0" rpy="0 0 1.5707963267948966"/></joint>
  <joint name="j2" type="continuous"><parent link="a"/><child link="b"/><origin xyz="0.5 0 0"/><axis xyz="0 1 0"/></joint>
  <joint name="flange" type="fixed"><parent link="b"/><child link="tool"/>
    <origin xyz="0 0 0.4" rpy="0 3.141592653589793 0"/><axis xyz="0 0 0"/></joint>
</robot>)";

TEST(UrdfTest, InertialsLumpedIntoRows) {
  const Robot r = ParseUrdfChain(kLumped, "l.urdf", "base", "tool");
  ASSERT_EQ(r.joints.size(), 2u);
  // Row j1: link a (2 kg at (0.1, 0, 0)) + motor (1 kg at its (0, 0.05, 0),
  // turned 90 deg about z and moved to (0.3, 0, 0): (0.25, 0, 0) in a).
  EXPECT_NEAR(r.joints[0].mass_kg, 3.0, 1e-12);
  EXPECT_NEAR(r.joints[0].com_mm.x(), (2 * 100.0 + 1 * 250.0) / 3, 1e-9);
  EXPECT_NEAR(r.joints[0].com_mm.y(), 0.0, 1e-9);
  // Row j2: link b (3 kg at (0, 0, 0.2)) + tool (1 kg at its (0.01, 0, 0),
  // turned 180 deg about y at (0, 0, 0.4): (-0.01, 0, 0.4) in b).
  EXPECT_NEAR(r.joints[1].mass_kg, 4.0, 1e-12);
  EXPECT_NEAR(r.joints[1].com_mm.x(), -10.0 / 4, 1e-9);
  EXPECT_NEAR(r.joints[1].com_mm.z(), (3 * 200.0 + 1 * 400.0) / 4, 1e-9);
  EXPECT_FALSE(r.tool.HasMass());
  // A tip above the tool: the tool still hangs on j2 and is lumped there.
  const Robot s = ParseUrdfChain(kLumped, "l.urdf", "base", "b");
  EXPECT_NEAR(s.joints[1].mass_kg, 4.0, 1e-12);
}

void ExpectError(const std::string& xml, const std::string& where,
                 const std::string& what) {
  try {
    ParseUrdfChain(xml, "e.urdf");
    ADD_FAILURE() << "accepted; expected " << what;
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), ::testing::HasSubstr("e.urdf:" + where + ": "));
    EXPECT_THAT(e.what(), ::testing::HasSubstr(what));
  }
}

TEST(UrdfTest, ErrorsCarryFileLineColumn) {
  const std::string head =
      "<robot name=\"e\">\n<link name=\"a\"/>\n<link name=\"b\"/>\n";
  auto joint = [&](const std::string& type, const std::string& inner) {
    return head + "<joint name=\"j\" type=\"" + type +
           "\">\n<parent link=\"a\"/><child link=\"b\"/>\n" + inner +
           "\n</joint>\n</robot>";
  };
  // Pre-pass (tinyxml2): attribute-level locations.
  ExpectError(joint("continuous", "  <origin xyz=\"0 0 abc\"/>"), "6:11",
              "origin xyz: expected three numbers");
  ExpectError(joint("continuous", "<axis xyz=\"0 0 0\"/>"), "6:7",
              "axis must not be zero");
  ExpectError(joint("continuous", "<origin xyz=\"0 0 1e3\"/>"), "6:9",
              "within +-100 m");
  ExpectError(joint("continuous", "<axis xyz=\"1e300 1e300 0\"/>"), "6:7",
              "axis length overflows");
  // A limit beyond +-1e5 (deg or mm) means none, as in robot.yaml.
  EXPECT_FALSE(ParseUrdfChain(joint("revolute",
                                    "<limit lower=\"-1e300\" upper=\"1e300\" "
                                    "effort=\"1\" velocity=\"1\"/>"),
                              "e.urdf")
                   .joints[0]
                   .HasLimits());
  ExpectError(joint("spherical", ""), "4:17", "not a URDF joint type");
  ExpectError(joint("floating", ""), "4:17", "joint 'j' is floating");
  ExpectError(joint("planar", "<axis xyz=\"0 0 1\"/>"), "4:17",
              "joint 'j' is planar");
  ExpectError(head +
                  "<link name=\"c\"><inertial><mass value=\"-1\"/>"
                  "<inertia ixx=\"1\" ixy=\"0\" ixz=\"0\" iyy=\"1\" iyz=\"0\" "
                  "izz=\"1\"/></inertial></link>\n</robot>",
              "4:32", "mass: expected a value in kg");
  ExpectError(head +
                  "<link name=\"c\">\n <inertial><mass value=\"1\"/>"
                  "</inertial></link>\n</robot>",
              "5:2", "without <inertia>");
  // Fuzz finding: urdfdom logs a bad material's name as a printf format
  // ("%n" wrote through a null pointer); refused before urdfdom runs.
  ExpectError(head +
                  "<material name=\"or%nge\"><color rgba=\"1.x 0.5 0 1\"/>"
                  "</material>\n</robot>",
              "4:11", "'%' is not allowed");
  ExpectError(
      "<robot name=\"x\" xmlns:xacro=\"http://www.ros.org/wiki/xacro\">"
      "\n<link name=\"a\"/></robot>",
      "1:1", "xacro file");
  ExpectError(head + "  <xacro:include filename=\"x.xacro\"/>\n</robot>", "4:3",
              "unexpanded xacro");
  // Loops (urdfdom accepts a link that is its own ancestor; found by the
  // fuzzer as a hang).
  ExpectError(head +
                  "<joint name=\"j\" type=\"fixed\"><parent link=\"a\"/>"
                  "<child link=\"b\"/></joint>\n"
                  "<link name=\"c\"/><joint name=\"k\" type=\"fixed\">"
                  "<parent link=\"c\"/><child link=\"c\"/></joint>\n"
                  "</robot>",
              "5:17", "joint 'k' closes a loop");
  // urdfdom's verdicts, located at the element they name.
  ExpectError(head +
                  "<joint name=\"j\" type=\"fixed\">\n"
                  "  <parent link=\"a\"/><child link=\"nowhere\"/></joint>\n"
                  "</robot>",
              "4:1", "child link [nowhere] of joint [j] not found");
  ExpectError(head +
                  "<joint name=\"j\" type=\"fixed\"><parent link=\"a\"/>"
                  "<child link=\"b\"/></joint>\n"
                  "<link name=\"c\"/> <joint name=\"j\" type=\"fixed\">"
                  "<parent link=\"b\"/><child link=\"c\"/></joint>\n</robot>",
              "5:18", "joint 'j' is not unique");
  ExpectError(head +
                  "<link name=\"c\"/>\n<joint name=\"j\" type=\"fixed\">"
                  "<parent link=\"a\"/><child link=\"b\"/></joint>\n"
                  "</robot>",
              "2:1", "Two root links found");
  ExpectError("<robot>\n<link name=\"a\"/></robot>", "1:1",
              "No name given for the robot");
  // Invalid XML: tinyxml2's line.
  ExpectError("<robot name=\"e\">\n<link name=\"a\">\n</robot>", "2",
              "invalid XML");
}

}  // namespace
}  // namespace kincal
