#include "synth/povray_scene.h"

#include <gtest/gtest.h>

#include <cmath>
#include <regex>
#include <sstream>

#include "data/error.h"

namespace kincal {
namespace {

Eigen::Vector3d ParseVector(const std::string& text, const std::string& key) {
  const std::regex re(key + R"(\s*<([^,]+),([^,]+),([^>]+)>)");
  std::smatch m;
  EXPECT_TRUE(std::regex_search(text, m, re)) << key;
  return {std::stod(m[1]), std::stod(m[2]), std::stod(m[3])};
}

// POV-Ray's ray for pixel (u, v) of a W x H image: the screen coordinates
// of the pixel's centre are s = (u + 0.5) / W, t = (v + 0.5) / H from the
// top left, and the ray is direction + (s - 0.5) right + (0.5 - t) up.
TEST(PovrayScene, CameraRayOfAPixelIsTheOpenCvPinholeRay) {
  CameraIntrinsics in;
  in.width = 640;
  in.height = 512;
  in.fx = 900;
  in.fy = 880;
  in.cx = 322.3;
  in.cy = 250.7;
  const std::string cam = PovCamera(in);
  const Eigen::Vector3d dir = ParseVector(cam, "direction");
  const Eigen::Vector3d right = ParseVector(cam, "right");
  const Eigen::Vector3d up = ParseVector(cam, "up");
  for (const Eigen::Vector2d& px :
       {Eigen::Vector2d(in.cx, in.cy), Eigen::Vector2d(0, 0),
        Eigen::Vector2d(639, 511), Eigen::Vector2d(100.25, 400.75)}) {
    const double s = (px.x() + 0.5) / in.width;
    const double t = (px.y() + 0.5) / in.height;
    const Eigen::Vector3d ray = dir + (s - 0.5) * right + (0.5 - t) * up;
    EXPECT_NEAR(ray.x() / ray.z(), (px.x() - in.cx) / in.fx, 1e-9);
    EXPECT_NEAR(ray.y() / ray.z(), (px.y() - in.cy) / in.fy, 1e-9);
  }
}

Target TwoTags() {
  Target t;
  for (int id : {3, 7}) {
    TargetTag tag;
    tag.id = id;
    tag.size_mm = 20;
    tag.tool_from_tag.t = Eigen::Vector3d(id * 10.0, 0, 0);
    t.tags.push_back(tag);
  }
  t.tip_in_tool = Eigen::Vector3d(0, 150, 10);
  return t;
}

TEST(PovrayScene, SceneHoldsEveryTagTheNeedleTheLightsAndTheTable) {
  CameraIntrinsics in;
  in.width = 320;
  in.height = 240;
  in.fx = in.fy = 400;
  in.cx = 160;
  in.cy = 120;
  Rigid3 rig_from_tool;
  rig_from_tool.t = Eigen::Vector3d(0, 0, 500);
  PovSceneOptions options;
  options.margin_cells = 1;
  const std::string scene =
      PovViewScene(in, Rigid3(), TwoTags(), rig_from_tool, 500, options);
  EXPECT_NE(scene.find("\"tag_3.pgm\""), std::string::npos);
  EXPECT_NE(scene.find("\"tag_7.pgm\""), std::string::npos);
  EXPECT_NE(scene.find("cone {"), std::string::npos);
  EXPECT_NE(scene.find("area_light"), std::string::npos);
  EXPECT_NE(scene.find("plane {"), std::string::npos);
  // Two printed tags, two margins of paper.
  std::istringstream is(scene);
  int polygons = 0;
  for (std::string line; std::getline(is, line);)
    polygons += line.rfind("polygon", 0) == 0;
  EXPECT_EQ(polygons, 4);
  options.margin_cells = -1;
  EXPECT_THROW(
      PovViewScene(in, Rigid3(), TwoTags(), rig_from_tool, 500, options),
      InputError);
}

TEST(PovrayScene, SensorImageAddsTheStatedNoise) {
  cv::Mat flat(200, 200, CV_8UC3, cv::Scalar(100, 100, 100));
  std::mt19937_64 rng(5);
  const cv::Mat gray = SensorImage(flat, 2.0, 0.05, &rng);
  ASSERT_EQ(gray.type(), CV_8UC1);
  cv::Scalar mean, sd;
  cv::meanStdDev(gray, mean, sd);
  EXPECT_NEAR(mean[0], 100, 0.1);
  // sqrt(2^2 + 0.05 * 100) = 3, plus the rounding's 1/12.
  EXPECT_NEAR(sd[0], std::sqrt(9 + 1.0 / 12), 0.1);
}

}  // namespace
}  // namespace kincal
