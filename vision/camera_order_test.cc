#include "vision/camera_order.h"

#include <gtest/gtest.h>

#include "synth/render.h"
#include "tests/testing/paths.h"

namespace kincal {
namespace {

// The gate of `kincal track`: a tight fit with tags in both cameras.
bool Gate(const ToolPoseResult& r) {
  bool cameras[2] = {false, false};
  for (const TagObservationResult& t : r.tags) {
    if (t.used && t.camera >= 0 && t.camera < 2) cameras[t.camera] = true;
  }
  return r.found && r.tags_used >= 2 && r.rms_px <= 1.0 && cameras[0] &&
         cameras[1];
}

TEST(CameraOrderTest, ExchangedImagesAreRecognised) {
  const std::string dir = testing::MakeTempDir("camera_order");
  const Rig rig = ExampleStereoRig(640, 512);
  RenderOptions o;
  o.noise_sigma = 1.0;
  std::vector<Rigid3> poses;
  for (int i = 0; i < 4; ++i) poses.push_back(ExampleToolPose(i));
  RenderSession(rig, ExampleTarget(), poses, o, 1, dir);
  std::vector<std::string> left, right;
  for (int i = 0; i < 4; ++i) {
    char name[32];
    std::snprintf(name, sizeof(name), "_%06d.png", i);
    left.push_back(dir + "/left" + name);
    right.push_back(dir + "/right" + name);
  }
  ASSERT_TRUE(testing::Exists(left[0])) << left[0];
  AprilTagOptions detector;
  const CameraOrderCheck given =
      CheckCameraOrder(rig, ExampleTarget(), left, right, Gate, detector);
  EXPECT_EQ(given.sampled, 4);
  EXPECT_EQ(given.pass_as_given, 4);
  EXPECT_FALSE(given.LooksSwapped());
  const CameraOrderCheck swapped =
      CheckCameraOrder(rig, ExampleTarget(), right, left, Gate, detector);
  EXPECT_EQ(swapped.pass_swapped, 4);
  EXPECT_LT(swapped.pass_as_given, 2);
  EXPECT_TRUE(swapped.LooksSwapped());
}

TEST(CameraOrderTest, RuleNeedsTwoAndAMajority) {
  CameraOrderCheck c;
  c.sampled = 6;
  c.pass_swapped = 1;
  EXPECT_FALSE(c.LooksSwapped());  // one pair proves nothing
  c.pass_swapped = 3;
  EXPECT_TRUE(c.LooksSwapped());
  c.pass_as_given = 2;
  EXPECT_FALSE(c.LooksSwapped());  // both orders work about as well
  c.pass_as_given = 0;
  c.pass_swapped = 2;
  EXPECT_FALSE(c.LooksSwapped());  // not half of the sample
}

}  // namespace
}  // namespace kincal
