#include "vision/triangulate.h"

#include <gtest/gtest.h>

namespace kincal {
namespace {

// Two pinhole cameras 100 mm apart along x, both looking down +z.
Rig StereoRig() {
  Rig rig;
  for (int c = 0; c < 2; ++c) {
    Camera cam;
    cam.intrinsics.width = 1280;
    cam.intrinsics.height = 1024;
    cam.intrinsics.fx = cam.intrinsics.fy = 1500;
    cam.intrinsics.cx = 640;
    cam.intrinsics.cy = 512;
    cam.cam_from_rig.t = Eigen::Vector3d(-100.0 * c, 0, 0);
    rig.cameras.push_back(cam);
  }
  return rig;
}

TagDetection Tag(int id, double shift) {
  TagDetection d;
  d.id = id;
  for (int k = 0; k < 4; ++k) {
    d.corners[k] = Eigen::Vector2d(10 * id + k + shift, 20 * id + k);
  }
  return d;
}

TEST(MatchTagCorners, PairsCornersOfTagsSeenInBothViews) {
  const std::vector<StereoCorner> m =
      MatchTagCorners({Tag(1, 0), Tag(2, 0)}, {Tag(2, 5), Tag(3, 5)});
  ASSERT_EQ(m.size(), 4u);
  for (int k = 0; k < 4; ++k) {
    EXPECT_EQ(m[k].tag_id, 2);
    EXPECT_EQ(m[k].corner, k);
    EXPECT_EQ(m[k].px0, Tag(2, 0).corners[k]);
    EXPECT_EQ(m[k].px1, Tag(2, 5).corners[k]);
  }
}

TEST(MatchTagCorners, LeavesOutIdsSeenTwiceInAView) {
  EXPECT_TRUE(MatchTagCorners({Tag(4, 0), Tag(4, 1)}, {Tag(4, 5)}).empty());
}

TEST(TriangulatePoint, RecoversAPointFromItsTwoProjections) {
  const Rig rig = StereoRig();
  const Eigen::Vector3d p(30, -20, 1200);
  std::vector<PixelObservation> obs;
  for (int c = 0; c < 2; ++c) {
    const Camera& cam = rig.cameras[c];
    obs.push_back({c, Project(cam.intrinsics, cam.cam_from_rig * p)});
  }
  const TriangulatedPoint t = TriangulatePoint(rig, obs);
  ASSERT_TRUE(t.ok);
  EXPECT_LT((t.p_in_rig - p).norm(), 1e-6);
  EXPECT_LT(t.rms_px, 1e-6);
  // One pixel across the epipolar line (y: the baseline is along x) cannot
  // be met by any point: the RMS shows it.
  obs[1].px.y() += 1.0;
  const TriangulatedPoint off = TriangulatePoint(rig, obs);
  ASSERT_TRUE(off.ok);
  EXPECT_GT(off.rms_px, 0.3);
  EXPECT_LT(off.rms_px, 0.6);
}

TEST(TriangulatePoint, OneRayIsNotEnough) {
  const Rig rig = StereoRig();
  EXPECT_FALSE(TriangulatePoint(rig, {{0, Eigen::Vector2d(640, 512)}}).ok);
}

}  // namespace
}  // namespace kincal
