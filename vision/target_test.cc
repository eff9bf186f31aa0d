#include "vision/target.h"

#include <gtest/gtest.h>

#include <string>

#include "data/error.h"
#include "tests/testing/paths.h"

namespace kincal {
namespace {

const char* kValid = R"(kincal_target: 1
family: tag36h11
tags:
  - {id: 0, size: 30.0, tool_from_tag: {R: [1,0,0, 0,1,0, 0,0,1], t: [0, 0, 0]}}
  - {id: 5, size: 20, tool_from_tag: {R: [0,-1,0, 1,0,0, 0,0,1], t: [40, 0, 5]}}
tip_in_tool: [0, 0, 150]
)";

TEST(TargetYaml, ReadsSpecExample) {
  const Target t = ParseTargetYaml(kValid, "target.yaml");
  EXPECT_EQ(t.family, "tag36h11");
  ASSERT_EQ(t.tags.size(), 2u);
  EXPECT_EQ(t.tags[1].id, 5);
  EXPECT_DOUBLE_EQ(t.tags[1].size_mm, 20.0);
  EXPECT_DOUBLE_EQ(t.tags[1].tool_from_tag.R(0, 1), -1.0);
  EXPECT_DOUBLE_EQ(t.tags[1].tool_from_tag.t.x(), 40.0);
  EXPECT_DOUBLE_EQ(t.tip_in_tool.z(), 150.0);
  ASSERT_NE(t.FindTag(5), nullptr);
  EXPECT_EQ(t.FindTag(4), nullptr);
  // Corner 3 = top-left (-s/2, -s/2) of tag 0.
  EXPECT_TRUE(t.tags[0].CornerInTool(3).isApprox(Eigen::Vector3d(-15, -15, 0)));
}

TEST(TargetYaml, RoundTrips) {
  Target t = ParseTargetYaml(kValid, "target.yaml");
  t.tags[0].tool_from_tag.R =
      Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized())
          .toRotationMatrix();
  t.tags[0].tool_from_tag.t = Eigen::Vector3d(1.25, -3.5, 1e-3);
  const std::string dir = testing::MakeTempDir("target");
  WriteTargetYaml(dir + "/t.yaml", t);
  const Target back = ReadTargetYaml(dir + "/t.yaml");
  ASSERT_EQ(back.tags.size(), t.tags.size());
  for (size_t i = 0; i < t.tags.size(); ++i) {
    EXPECT_EQ(back.tags[i].id, t.tags[i].id);
    EXPECT_NEAR(
        (back.tags[i].tool_from_tag.R - t.tags[i].tool_from_tag.R).norm(), 0,
        1e-12);
    EXPECT_NEAR(
        (back.tags[i].tool_from_tag.t - t.tags[i].tool_from_tag.t).norm(), 0,
        1e-12);
  }
  EXPECT_EQ(back.tip_in_tool, t.tip_in_tool);
}

// Each bad file is rejected with the position of the fault.
struct BadCase {
  const char* text;
  const char* position;  // "file:line:column" prefix expected
  const char* words;     // part of the message
};

TEST(TargetYaml, RejectsBadFilesWithPosition) {
  const BadCase cases[] = {
      {"kincal_target: 2\ntags: []\ntip_in_tool: [0,0,0]\n", "t.yaml:1:16",
       "version"},
      {"kincal_target: 1\nfamily: tag99\ntags: []\n", "t.yaml:2:9", "family"},
      {"kincal_target: 1\ntags:\n  - {id: 0, size: -3, tool_from_tag: {R: "
       "[1,0,0,0,1,0,0,0,1], t: [0,0,0]}}\ntip_in_tool: [0,0,1]\n",
       "t.yaml:3:19", "positive"},
      {"kincal_target: 1\ntags:\n  - {id: 0, size: 3, tool_from_tag: {R: "
       "[1,0,0,0,1,0,0,0,2], t: [0,0,0]}}\ntip_in_tool: [0,0,1]\n",
       "t.yaml:3:", "rotation"},
      {"kincal_target: 1\ntags:\n  - {id: 0, size: 3, tool_from_tag: {R: "
       "[1,0,0,0,1,0,0,0,1], t: [0,0,0]}}\n  - {id: 0, size: 3, "
       "tool_from_tag: {R: [1,0,0,0,1,0,0,0,1], t: [0,0,0]}}\ntip_in_tool: "
       "[0,0,1]\n",
       "t.yaml:4:", "duplicate"},
      {"kincal_target: 1\ntags:\n  - {id: 600, size: 3, tool_from_tag: {R: "
       "[1,0,0,0,1,0,0,0,1], t: [0,0,0]}}\ntip_in_tool: [0,0,1]\n",
       "t.yaml:3:", "not in tag36h11"},
      {"kincal_target: 1\ntags:\n  - {id: 1, size: 3, tool_from_tag: {R: "
       "[1,0,0,0,1,0,0,0,1], t: [0,0,0]}, colour: red}\ntip_in_tool: "
       "[0,0,1]\n",
       "t.yaml:3:", "unknown key 'colour'"},
      {"kincal_target: 1\ntags:\n  - {id: 1, size: 3, tool_from_tag: {R: "
       "[1,0,0,0,1,0,0,0,1], t: [0,0]}}\ntip_in_tool: [0,0,1]\n",
       "t.yaml:3:", "t"},
      {"kincal_target: 1\ntags:\n  - {id: 1, size: 3, tool_from_tag: {R: "
       "[1,0,0,0,1,0,0,0,1], t: [0,0,0]}}\n",
       "t.yaml:1:", "tip_in_tool"},
      {"kincal_target: 1\ntags: [\n", "t.yaml:", "invalid YAML"},
      {"", "t.yaml", "empty"},
  };
  for (const BadCase& c : cases) {
    try {
      ParseTargetYaml(c.text, "t.yaml");
      ADD_FAILURE() << "accepted:\n" << c.text;
    } catch (const InputError& e) {
      const std::string msg = e.what();
      EXPECT_EQ(msg.rfind(c.position, 0), 0u) << msg;
      EXPECT_NE(msg.find(c.words), std::string::npos) << msg;
    }
  }
}

TEST(TargetYaml, MissingFileIsInputError) {
  EXPECT_THROW(ReadTargetYaml("/nonexistent/target.yaml"), InputError);
}

}  // namespace
}  // namespace kincal
