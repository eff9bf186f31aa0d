#include "data/robot_program.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "data/error.h"
#include "tests/testing/paths.h"

namespace kincal {
namespace {

using ::testing::HasSubstr;

Robot Load(const std::string& name) {
  return ReadRobotYaml(testing::SourceDir() + "/data/robots/" + name);
}

const std::vector<std::vector<double>> kRows = {{0, -90, 90, -90, -90, 0},
                                                {10, -80, 85, -95, -90, 180}};

TEST(RobotProgramTest, UrscriptMovesInRadians) {
  const std::string s =
      FormatJointProgram(ProgramFormat::kUrscript, Load("ur10.yaml"),
                         {"a", "b"}, kRows, {"compensated by kincal"});
  EXPECT_THAT(s, HasSubstr("# compensated by kincal\n"));
  EXPECT_THAT(s, HasSubstr("  # b\n  movej([0.174532925, -1.396263402, "
                           "1.483529864, -1.658062789, -1.570796327, "
                           "3.141592654], a=0.5, v=0.2)\n"));
  EXPECT_THAT(s, HasSubstr("def kincal_compensated():"));
}

TEST(RobotProgramTest, KrlAndRapidInDegrees) {
  const Robot ur = Load("ur10.yaml");
  const std::string krl =
      FormatJointProgram(ProgramFormat::kKrl, ur, {"a", "b"}, kRows, {});
  EXPECT_THAT(krl, HasSubstr("POSES[2] = {A1 10.000000, A2 -80.000000, A3 "
                             "85.000000, A4 -95.000000, A5 -90.000000, A6 "
                             "180.000000}  ; b"));
  const std::string rapid =
      FormatJointProgram(ProgramFormat::kRapid, ur, {"a", "b"}, kRows, {});
  EXPECT_THAT(rapid, HasSubstr("[[10.000000,-80.000000,85.000000,-95.000000,"
                               "-90.000000,180.000000],[9E9,9E9,9E9,9E9,9E9,"
                               "9E9]]  ! b"));
  EXPECT_THAT(rapid, HasSubstr("MoveAbsJ poses{i}"));
}

TEST(RobotProgramTest, RefusesRobotsTheFormatCannotTake) {
  try {
    FormatJointProgram(ProgramFormat::kUrscript, Load("bh7.yaml"), {"a"},
                       {{0, 0, 0, 0, 0}}, {});
    FAIL();
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("prismatic"));
  }
  try {
    FormatJointProgram(ProgramFormat::kFranka, Load("ur10.yaml"), {"a"},
                       {kRows[0]}, {});
    FAIL();
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("the robot has 6 joints; the format "
                                    "takes 7"));
  }
  EXPECT_THROW(ParseProgramFormat("gcode"), InputError);
  EXPECT_EQ(ProgramExtension(ParseProgramFormat("rapid")), ".mod");
}

}  // namespace
}  // namespace kincal
