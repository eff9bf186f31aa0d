// Regression tests for issue 7: numbers outside any physical range in
// target.yaml are rejected at parse time with file:line:column (before they
// reach Ceres, where `size: 1e308` ended `kincal track` with a CHECK abort).

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>

#include "data/error.h"
#include "vision/target.h"

namespace kincal {
namespace {

using ::testing::HasSubstr;

std::string Target(const std::string& size, const std::string& t,
                   const std::string& tip) {
  return "kincal_target: 1\nfamily: tag36h11\ntags:\n"
         "  - {id: 0, size: " +
         size + ", tool_from_tag: {R: [1,0,0, 0,1,0, 0,0,1], t: " + t +
         "}}\ntip_in_tool: " + tip + "\n";
}

TEST(TargetRanges, AcceptsPhysicalValues) {
  EXPECT_NO_THROW(
      ParseTargetYaml(Target("30", "[0, 0, 0]", "[0, 0, 150]"), "t.yaml"));
}

TEST(TargetRanges, RejectsOutOfRangeWithPosition) {
  struct Case {
    std::string text, where, message;
  };
  const Case cases[] = {
      {Target("1e308", "[0, 0, 0]", "[0, 0, 150]"), "t.yaml:4:", "size"},
      {Target("1e-300", "[0, 0, 0]", "[0, 0, 150]"), "t.yaml:4:", "size"},
      {Target("0.1", "[0, 0, 0]", "[0, 0, 150]"), "t.yaml:4:", "size"},
      // A tag of 0.03: metres, named with the fix.
      {Target("0.03", "[0, 0, 0]", "[0, 0, 0.15]"), "t.yaml:4:",
       "metres? target.yaml lengths are millimetres (multiply by 1000)"},
      {Target("30", "[1e308, 0, 0]", "[0, 0, 150]"), "t.yaml:4:", ".t"},
      {Target("30", "[0, 0, 0]", "[0, 0, 1e308]"), "t.yaml:5:", "tip_in_tool"},
      {Target("30", "[0, 0, 0]", "[0, -2e4, 0]"), "t.yaml:5:", "tip_in_tool"},
  };
  for (const Case& c : cases) {
    try {
      ParseTargetYaml(c.text, "t.yaml");
      ADD_FAILURE() << "accepted:\n" << c.text;
    } catch (const InputError& e) {
      EXPECT_THAT(e.what(), HasSubstr(c.where)) << c.text;
      EXPECT_THAT(e.what(), HasSubstr(c.message)) << c.text;
    }
  }
}

}  // namespace
}  // namespace kincal
