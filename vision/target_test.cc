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
  EXPECT_TRUE(back.has_tip);
  EXPECT_FALSE(back.tags[0].has_sigma);
  EXPECT_FALSE(back.has_tip_sigma);
  EXPECT_TRUE(back.made_by.empty());
}

// The measured-target fields (format version 3): per-tag sigma, the tip's
// sigma, made_by (quoted, any characters), and a board without a tip.
TEST(TargetYaml, MeasuredFieldsRoundTrip) {
  Target t = ParseTargetYaml(kValid, "target.yaml");
  t.tags[0].has_sigma = true;
  t.tags[0].sigma_t_mm = Eigen::Vector3d(0.01, 0.02, 0.125);
  t.tags[0].sigma_r_deg = Eigen::Vector3d(0.03, 0.5, 0.0);
  t.has_tip_sigma = true;
  t.tip_sigma_mm = Eigen::Vector3d(0.05, 0.06, 0.25);
  t.made_by = "kincal target --session 'a b' --out \"t: x.yaml\"";
  const Target back = ParseTargetYaml(FormatTargetYaml(t), "t.yaml");
  ASSERT_TRUE(back.tags[0].has_sigma);
  EXPECT_FALSE(back.tags[1].has_sigma);
  EXPECT_EQ(back.tags[0].sigma_t_mm, t.tags[0].sigma_t_mm);
  EXPECT_EQ(back.tags[0].sigma_r_deg, t.tags[0].sigma_r_deg);
  ASSERT_TRUE(back.has_tip_sigma);
  EXPECT_EQ(back.tip_sigma_mm, t.tip_sigma_mm);
  EXPECT_EQ(back.made_by, t.made_by);

  t.has_tip = false;
  t.has_tip_sigma = false;
  const std::string text = FormatTargetYaml(t);
  EXPECT_EQ(text.find("tip_in_tool"), std::string::npos) << text;
  const Target board = ParseTargetYaml(text, "t.yaml");
  EXPECT_FALSE(board.has_tip);
  EXPECT_EQ(board.tip_in_tool, Eigen::Vector3d::Zero());
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
       "[1,0,0,0,1,0,0,0,1], t: [0,0,0]}, sigma: {t_mm: [0, -1, 0], r_deg: "
       "[0, 0, 0]}}\n",
       "t.yaml:3:", "non-negative"},
      {"kincal_target: 1\ntags:\n  - {id: 1, size: 3, tool_from_tag: {R: "
       "[1,0,0,0,1,0,0,0,1], t: [0,0,0]}}\ntip_sigma_mm: [1, 2]\n",
       "t.yaml:4:", "tip_sigma_mm"},
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
