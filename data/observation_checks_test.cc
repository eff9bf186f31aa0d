#include "data/observation_checks.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>

#include "data/error.h"
#include "data/import_ipa.h"
#include "data/import_mukca.h"
#include "data/urdf.h"

namespace kincal {
namespace {

using ::testing::HasSubstr;

// A 3-joint arm, 500 + 400 + 100 mm, j2 limited to +-120 deg.
Robot Arm() {
  Robot robot;
  robot.name = "arm";
  for (const char* name : {"j1", "j2", "j3"}) {
    RobotRow row;
    row.name = name;
    row.a_mm = 300.0;
    robot.joints.push_back(row);
  }
  robot.joints[1].lower = -120.0;
  robot.joints[1].upper = 120.0;
  robot.tool.type = JointType::kFixed;
  robot.tool.d_mm = 100.0;
  return robot;
}

const std::vector<std::string> kJoints = {"j1", "j2", "j3"};

std::string RefusalOf(const std::string& csv) {
  Warnings w;
  try {
    CheckObservationsAgainstRobot(
        Arm(), ParseObservationsCsv(csv, "o.csv", kJoints), "robot.yaml", &w);
  } catch (const InputError& e) {
    return e.what();
  }
  return "(accepted)";
}

Warnings WarningsOf(const std::string& csv) {
  Warnings w;
  CheckObservationsAgainstRobot(
      Arm(), ParseObservationsCsv(csv, "o.csv", kJoints), "robot.yaml", &w);
  return w;
}

const char* kDegreesMm =
    "pose,j1,j2,j3,x,y,z\n"
    "0,10,20,30,800,10,5\n"
    "1,-40,60,-30,500,400,20\n"
    "2,90,-100,45,100,700,-30\n"
    "3,0,0,0,1000,0,100\n";

TEST(ObservationChecksTest, GoodDataPassesSilently) {
  EXPECT_EQ(RefusalOf(kDegreesMm), "(accepted)");
  EXPECT_TRUE(WarningsOf(kDegreesMm).empty());
}

TEST(ObservationChecksTest, ReadingOutsideLimitsNamesRowAndJoint) {
  const std::string csv =
      "pose,j1,j2,j3,x,y,z\n"
      "0,10,20,30,800,10,5\n"
      "1,-40,500,-30,500,400,20\n";
  const std::string e = RefusalOf(csv);
  EXPECT_THAT(e, HasSubstr("o.csv:3:"));
  EXPECT_THAT(e, HasSubstr("joint j2 reads 500 deg"));
  EXPECT_THAT(e, HasSubstr("[-120, 120]"));
}

TEST(ObservationChecksTest, ReadingJustPastTheLimitWithinMarginPasses) {
  EXPECT_EQ(RefusalOf("pose,j1,j2,j3\n0,10,121.5,30\n"), "(accepted)");
  EXPECT_NE(RefusalOf("pose,j1,j2,j3\n0,10,122.5,30\n"), "(accepted)");
  // A joint without limits takes any reading.
  EXPECT_EQ(RefusalOf("pose,j1,j2,j3\n0,720,0,-900\n"), "(accepted)");
}

TEST(ObservationChecksTest, PointsInMetresAreRefusedWithTheFix) {
  const std::string csv =
      "pose,j1,j2,j3,x,y,z\n"
      "0,10,20,30,0.8,0.01,0.005\n"
      "1,-40,60,-30,0.5,0.4,0.02\n"
      "2,90,-100,45,0.1,0.7,-0.03\n";
  const std::string e = RefusalOf(csv);
  EXPECT_THAT(e, HasSubstr("o.csv:2:"));
  EXPECT_THAT(e, HasSubstr("metres"));
  EXPECT_THAT(e, HasSubstr("multiply x,y,z by 1000"));
}

TEST(ObservationChecksTest, RepeatedPointOfOnePoseIsNotMetres) {
  // A repeatability set: one pose, points within 0.1 mm.
  const std::string csv =
      "pose,j1,j2,j3,x,y,z\n"
      "0,10,20,30,800.0,10.0,5.0\n"
      "1,10,20,30,800.1,10.0,5.0\n"
      "2,10,20,30,800.0,10.1,5.0\n";
  EXPECT_EQ(RefusalOf(csv), "(accepted)");
}

TEST(ObservationChecksTest, RadiansWarnWithTheFactor) {
  const std::string csv =
      "pose,j1,j2,j3,x,y,z\n"
      "0,0.17,0.35,0.52,800,10,5\n"
      "1,-0.70,1.05,-0.52,500,400,20\n"
      "2,1.57,-1.75,0.79,100,700,-30\n";
  const Warnings w = WarningsOf(csv);
  ASSERT_EQ(w.list().size(), 1u);
  EXPECT_EQ(w.list()[0].code, "joint_units_radians");
  EXPECT_THAT(w.list()[0].message, HasSubstr("radians"));
  EXPECT_THAT(w.list()[0].message, HasSubstr("180/pi"));
}

TEST(ObservationChecksTest, SmallDegreeMotionIsNotRadians) {
  // Readings within +-2 pi but hardly moving (0.4 of a unit): no warning.
  const std::string csv =
      "pose,j1,j2,j3\n0,1.0,2.0,3.0\n1,1.2,2.2,3.2\n2,1.4,2.4,3.4\n";
  EXPECT_TRUE(WarningsOf(csv).empty());
  // And readings beyond 2 pi are degrees.
  EXPECT_TRUE(WarningsOf(kDegreesMm).empty());
}

TEST(ObservationChecksTest, LinkLengthSum) {
  EXPECT_DOUBLE_EQ(LinkLengthSumMm(Arm()), 1000.0);
}

// The shared real data (../shared/data from the worktree root) raises no
// refusal and no warning: UR10 series A/B/C against data/robots/ur10.yaml,
// every MUKCa Panda recording against the Panda URDF, and the BH-7 demo.
const std::string kShared = "../shared/data";

void ExpectQuiet(const Robot& robot, const Observations& obs,
                 const std::string& label) {
  Warnings w;
  EXPECT_NO_THROW(CheckObservationsAgainstRobot(robot, obs, label, &w))
      << obs.source;
  EXPECT_TRUE(w.empty()) << obs.source << ": "
                         << (w.empty() ? "" : w.list()[0].message);
}

TEST(ObservationChecksTest, NoFalseAlarmOnRealData) {
  ASSERT_TRUE(std::filesystem::exists("data/robots/ur10.yaml"));
  const Robot bh7 = ReadRobot("data/sessions/bh7_demo/robot.yaml");
  ExpectQuiet(bh7,
              ReadObservationsCsv("data/sessions/bh7_demo/observations.csv",
                                  bh7.JointNames()),
              "bh7");
  const std::string ipa = kShared + "/ipa-robot-accuracy";
  const std::string mukca = kShared + "/mukca";
  if (!std::filesystem::exists(ipa) || !std::filesystem::exists(mukca))
    GTEST_SKIP() << "shared data absent";
  const Robot ur10 = ReadRobot("data/robots/ur10.yaml");
  for (const char* series : {"Series_A/measurements_grid.csv",
                             "Series_B/measurements_joint_configurations.csv",
                             "Series_C/measurements_random_poses.csv"}) {
    const std::string path = ipa + "/" + series;
    ASSERT_TRUE(std::filesystem::exists(path)) << path;
    ExpectQuiet(ur10, ReadIpaSeries(path, ur10.JointNames()).observations,
                "ur10");
  }
  const Robot panda = ReadRobot(mukca + "/urdf/panda.urdf", "", "ball_link");
  int recordings = 0;
  for (const auto& entry :
       std::filesystem::recursive_directory_iterator(mukca + "/data")) {
    if (entry.path().filename() != "hole_0.csv") continue;
    ExpectQuiet(
        panda,
        ReadMukcaDir(entry.path().parent_path().string(), panda.JointNames()),
        "panda.urdf");
    ++recordings;
  }
  EXPECT_GE(recordings, 5);
}

}  // namespace
}  // namespace kincal
