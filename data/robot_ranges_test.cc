// Regression tests for issue 7: numbers outside any physical range in
// robot.yaml are rejected with file:line:column.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>

#include "data/error.h"
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

}  // namespace
}  // namespace kincal
