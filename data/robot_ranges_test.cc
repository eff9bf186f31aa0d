// Regression tests for issue 7: numbers outside any physical range in
// robot.yaml are rejected with file:line:column.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>

#include "data/error.h"
#include "data/observations.h"
#include "data/robot.h"

namespace kincal {
namespace {

using ::testing::HasSubstr;

std::string Dh(const std::string& d, const std::string& theta,
               const std::string& bounds) {
  return "kincal_robot: 1\nname: r\nconvention: dh\njoints:\n"
         "  - {name: j1, type: revolute, d: " +
         d + ", a: 100, alpha: 90, theta: " + theta +
         "}\ntool: {d: 10, a: 0, alpha: 0, theta: 0}\nbounds: " + bounds + "\n";
}

TEST(RobotRanges, AcceptsPhysicalValues) {
  EXPECT_NO_THROW(
      ParseRobotYaml(Dh("300", "0", "{length: 5, angle: 5}"), "r.yaml"));
}

TEST(RobotRanges, RejectsOutOfRangeWithPosition) {
  struct Case {
    std::string text, where, message;
  };
  const Case cases[] = {
      {Dh("1e308", "0", "{length: 5, angle: 5}"), "r.yaml:5:", ".d"},
      {Dh("300", "1e6", "{length: 5, angle: 5}"), "r.yaml:5:", ".theta"},
      {Dh("300", "0", "{length: 1e300, angle: 5}"), "r.yaml:7:", "bounds"},
      {Dh("300", "0", "{length: 5, angle: 720}"), "r.yaml:7:", "bounds"},
  };
  for (const Case& c : cases) {
    try {
      ParseRobotYaml(c.text, "r.yaml");
      ADD_FAILURE() << "accepted:\n" << c.text;
    } catch (const InputError& e) {
      EXPECT_THAT(e.what(), HasSubstr(c.where)) << c.text;
      EXPECT_THAT(e.what(), HasSubstr(c.message)) << c.text;
    }
  }
}

// fuzz/robot_yaml_fuzz.cc finding: a huge integer (format version) was cast
// to int (undefined behaviour) instead of being rejected.
TEST(RobotRanges, HugeIntegerIsAnInputError) {
  std::string text = Dh("300", "0", "{length: 5, angle: 5}");
  text.replace(text.find("kincal_robot: 1"), 15,
               "kincal_robot: 555555555555555555555551");
  try {
    ParseRobotYaml(text, "r.yaml");
    ADD_FAILURE() << "accepted";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("r.yaml:1:"));
    EXPECT_THAT(e.what(), HasSubstr("integer out of range"));
  }
}

TEST(ObservationRanges, RejectsOutOfRangeWithPosition) {
  const std::vector<std::string> joints = {"j1"};
  EXPECT_NO_THROW(
      ParseObservationsCsv("pose,j1,x,y,z\np1,10,1,2,3\n", "o.csv", joints));
  for (const std::string text : {"pose,j1,x,y,z\np1,1e300,1,2,3\n",
                                 "pose,j1,x,y,z\np1,10,1,2e300,3\n"}) {
    try {
      ParseObservationsCsv(text, "o.csv", joints);
      ADD_FAILURE() << "accepted:\n" << text;
    } catch (const InputError& e) {
      EXPECT_THAT(e.what(), HasSubstr("o.csv:2:")) << text;
      EXPECT_THAT(e.what(), HasSubstr("range")) << text;
    }
  }
}

}  // namespace
}  // namespace kincal
