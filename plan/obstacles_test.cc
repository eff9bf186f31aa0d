#include "plan/obstacles.h"

#include <gtest/gtest.h>

#include <cmath>

#include "data/error.h"

namespace kincal {
namespace {

std::string ErrorOf(const std::string& text) {
  try {
    ParseObstaclesYaml(text, "obst.yaml");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(Obstacles, ParsesPlanesAndBoxes) {
  const Obstacles o = ParseObstaclesYaml(
      "kincal_obstacles: 1\n"
      "planes:\n"
      "  - {name: table, point: [0, 0, -5], normal: [0, 0, 2], "
      "clearance_mm: 20}\n"
      "boxes:\n"
      "  - {center: [900, 0, 600], size: [200, 100, 1200], "
      "rpy_deg: [0, 0, 90]}\n",
      "obst.yaml");
  ASSERT_EQ(o.planes.size(), 1u);
  ASSERT_EQ(o.boxes.size(), 1u);
  EXPECT_EQ(o.planes[0].name, "table");
  EXPECT_DOUBLE_EQ(o.planes[0].point.z(), -5);
  EXPECT_DOUBLE_EQ(o.planes[0].normal.z(), 1);  // normalised
  EXPECT_DOUBLE_EQ(o.planes[0].clearance_mm, 20);
  EXPECT_EQ(o.boxes[0].name, "boxes[0]");
  EXPECT_DOUBLE_EQ(o.boxes[0].size.y(), 100);
  EXPECT_DOUBLE_EQ(o.boxes[0].clearance_mm, 0);
  // Yaw 90 deg: the box's x axis is the base's y axis.
  EXPECT_NEAR(o.boxes[0].base_from_box(1, 0), 1, 1e-12);
  EXPECT_NEAR(o.boxes[0].base_from_box(0, 0), 0, 1e-12);
}

TEST(Obstacles, ErrorsNameTheLineAndTheField) {
  EXPECT_NE(ErrorOf("planes: []\n").find("kincal_obstacles"),
            std::string::npos);
  EXPECT_NE(ErrorOf("kincal_obstacles: 2\n").find("unsupported"),
            std::string::npos);
  const std::string zero = ErrorOf(
      "kincal_obstacles: 1\nplanes:\n"
      "  - {point: [0, 0, 0], normal: [0, 0, 0]}\n");
  EXPECT_NE(zero.find("obst.yaml:3:"), std::string::npos) << zero;
  EXPECT_NE(zero.find("planes[0].normal"), std::string::npos) << zero;
  const std::string far = ErrorOf(
      "kincal_obstacles: 1\nplanes:\n"
      "  - {point: [0, 0, 1e9], normal: [0, 0, 1]}\n");
  EXPECT_NE(far.find("100 m"), std::string::npos) << far;
  const std::string nan = ErrorOf(
      "kincal_obstacles: 1\nboxes:\n"
      "  - {center: [0, 1e999, 0], size: [1, 1, 1]}\n");
  EXPECT_NE(nan.find("finite"), std::string::npos) << nan;
  const std::string flat = ErrorOf(
      "kincal_obstacles: 1\nboxes:\n"
      "  - {center: [0, 0, 0], size: [1, 0, 1]}\n");
  EXPECT_NE(flat.find("boxes[0].size"), std::string::npos) << flat;
  const std::string typo = ErrorOf(
      "kincal_obstacles: 1\nplanes:\n"
      "  - {point: [0, 0, 0], normal: [0, 0, 1], clearance: 20}\n");
  EXPECT_NE(typo.find("clearance"), std::string::npos) << typo;
  const std::string negative = ErrorOf(
      "kincal_obstacles: 1\nplanes:\n"
      "  - {point: [0, 0, 0], normal: [0, 0, 1], clearance_mm: -1}\n");
  EXPECT_NE(negative.find("clearance_mm"), std::string::npos) << negative;
  const std::string two = ErrorOf(
      "kincal_obstacles: 1\nplanes:\n  - {point: [0, 0], normal: [0, 0, 1]}\n");
  EXPECT_NE(two.find("expected 3 numbers"), std::string::npos) << two;
}

}  // namespace
}  // namespace kincal
