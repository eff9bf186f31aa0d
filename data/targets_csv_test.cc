#include "data/targets_csv.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "data/error.h"

namespace kincal {
namespace {

using ::testing::HasSubstr;

const std::vector<std::string> kJoints = {"j1", "j2"};

std::string ErrorOf(const std::string& text) {
  try {
    ParseTargetsCsv(text, "t.csv", kJoints);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(TargetsCsvTest, ReadsPoseTargetsWithSeedsInAnyColumnOrder) {
  const TargetsFile t = ParseTargetsCsv(
      "# targets\nz,target,x,y,rx,ry,rz,j2,j1,temp_c\n"
      "3,a,1,2,0,0,90,20,10,24.5\n6,b,4,5,0,0,0,21,11,25\n",
      "t.csv", kJoints);
  ASSERT_EQ(t.rows.size(), 2u);
  EXPECT_FALSE(t.program);
  EXPECT_EQ(t.rows[0].id, "a");
  EXPECT_EQ(t.rows[0].position_mm, Eigen::Vector3d(1, 2, 3));
  EXPECT_TRUE(t.rows[0].has_rotation);
  EXPECT_EQ(t.rows[0].rotation_deg.z(), 90.0);
  EXPECT_EQ(t.rows[1].joints, (std::vector<double>{11, 21}));
  EXPECT_EQ(t.rows[1].temp_c, 25.0);
  EXPECT_EQ(t.rows[1].line, 4);
}

TEST(TargetsCsvTest, JointColumnsAloneAreAProgram) {
  const TargetsFile t =
      ParseTargetsCsv("target,j1,j2\np1,0,90\np2,10,80\n", "t.csv", kJoints);
  EXPECT_TRUE(t.program);
  EXPECT_FALSE(t.rows[0].has_position);
  EXPECT_EQ(t.rows[1].joints, (std::vector<double>{10, 80}));
}

TEST(TargetsCsvTest, RejectsBadFilesWithPlace) {
  EXPECT_THAT(ErrorOf("x,y,z\n1,2,3\n"), HasSubstr("'target' column"));
  EXPECT_THAT(ErrorOf("target,x,y\na,1,2\n"),
              HasSubstr("all of x, y, z or none"));
  EXPECT_THAT(ErrorOf("target,x,y,z,j1\na,1,2,3,4\n"),
              HasSubstr("all of the joint columns or none"));
  EXPECT_THAT(ErrorOf("target,x,y,z,q7\na,1,2,3,4\n"),
              HasSubstr("t.csv:1:14: header: unknown column 'q7'"));
  EXPECT_THAT(ErrorOf("target,x,y,z\na,1,2,3\na,4,5,6\n"),
              HasSubstr("t.csv:3:1: target: duplicate id 'a'"));
  EXPECT_THAT(ErrorOf("target,x,y,z\na,1,abc,3\n"),
              HasSubstr("t.csv:2:5: y: expected a number, got 'abc'"));
  EXPECT_THAT(ErrorOf("target,rx,ry,rz,j1,j2\na,1,2,3,4,5\n"),
              HasSubstr("rx, ry, rz need x, y, z"));
  EXPECT_THAT(ErrorOf("target\na\n"), HasSubstr("expected x, y, z"));
  EXPECT_THAT(ErrorOf("target,x,y,z\n"), HasSubstr("no target rows"));
}

}  // namespace
}  // namespace kincal
