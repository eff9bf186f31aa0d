#include "synth/flange_scene.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "data/robot.h"
#include "synth/render.h"
#include "synth/simulate.h"
#include "tests/testing/paths.h"

namespace kincal {
namespace {

struct Scene {
  Rig rig;
  Target board;
  Rigid3 tip_from_rig;
  std::vector<Eigen::Matrix4d> base_from_tip;
};

// Random BH-7 poses, the example stereo pair on the flange looking along
// the tip frame's z (tilted 10 deg), a 5 x 4 AprilGrid of 20 mm tags.
Scene MakeScene(int poses) {
  Scene s;
  s.rig = ExampleStereoRig(640, 512);
  s.rig.mount = RigMount::kFlange;
  AprilGrid grid;
  grid.cols = 5;
  grid.rows = 4;
  grid.tag_size_mm = 20;
  s.board = grid.AsTarget();
  s.tip_from_rig.R =
      Eigen::AngleAxisd(10 * M_PI / 180, Eigen::Vector3d::UnitX())
          .toRotationMatrix();
  SimulateOptions so;
  so.poses = poses;
  so.seed = 4;
  const Robot bh7 =
      ReadRobotYaml(testing::SourceDir() + "/data/robots/bh7.yaml");
  s.base_from_tip = Simulate(bh7, so).base_from_tip;
  return s;
}

int VisibleTags(const Scene& s, const Rigid3& base_from_board, int pose) {
  const Rigid3 rig_from_board =
      (Rigid3::FromMatrix(s.base_from_tip[pose]) * s.tip_from_rig).Inverse() *
      base_from_board;
  int n = 0;
  for (const TagTruth& t :
       ProjectTargetCorners(s.rig.cameras[0], s.board, rig_from_board)) {
    n += t.visible;
  }
  return n;
}

TEST(FlangeScene, SeenPosesSeeHalfTheBoardNearAndFrontally) {
  const Scene s = MakeScene(2000);
  const FlangeBoardPlacement p = PlaceBoardForFlangeRig(
      s.base_from_tip, s.rig, s.tip_from_rig, s.board, 450.0, 10);
  EXPECT_GT(p.seen.size(), 25u);  // 36 of 2000 when written
  Eigen::Vector3d middle = Eigen::Vector3d::Zero();
  for (const TargetTag& tag : s.board.tags) middle += tag.tool_from_tag.t;
  const Eigen::Vector3d centre = p.base_from_board * (middle / 20.0);
  const Eigen::Vector3d normal = p.base_from_board.R.col(2);
  int visible_unseen = 0;
  size_t k = 0;
  for (int i = 0; i < static_cast<int>(s.base_from_tip.size()); ++i) {
    const bool seen = k < p.seen.size() && p.seen[k] == i;
    const bool visible = VisibleTags(s, p.base_from_board, i) >= 10;
    visible_unseen += visible && !seen;
    if (!seen) continue;
    ++k;
    EXPECT_TRUE(visible) << i;
    const Eigen::Vector3d camera =
        (Rigid3::FromMatrix(s.base_from_tip[i]) * s.tip_from_rig).t;
    const Eigen::Vector3d ray = centre - camera;
    EXPECT_GT(ray.norm(), 0.6 * 450.0) << i;
    EXPECT_LT(ray.norm(), 1.5 * 450.0) << i;
    EXPECT_GT(ray.normalized().dot(normal), 0.5) << i;  // within 60 deg
  }
  EXPECT_EQ(k, p.seen.size());  // in order, no index twice
  // Far or grazing views that still show half the tags are left out.
  EXPECT_GT(visible_unseen, 0);
  // A proper rotation, and deterministic.
  EXPECT_NEAR(p.base_from_board.R.determinant(), 1.0, 1e-12);
  const FlangeBoardPlacement q = PlaceBoardForFlangeRig(
      s.base_from_tip, s.rig, s.tip_from_rig, s.board, 450.0, 10);
  EXPECT_EQ(q.seen, p.seen);
}

TEST(FlangeScene, CamerasLookingBackwardsSeeNothing) {
  Scene s = MakeScene(300);
  const FlangeBoardPlacement p = PlaceBoardForFlangeRig(
      s.base_from_tip, s.rig, s.tip_from_rig, s.board, 450.0, 10);
  ASSERT_FALSE(p.seen.empty());
  // The same board seen by the rig turned around (looking at the flange):
  // no pose that saw it still sees it.
  s.tip_from_rig.R =
      s.tip_from_rig.R *
      Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()).toRotationMatrix();
  for (int i : p.seen) EXPECT_EQ(VisibleTags(s, p.base_from_board, i), 0);
}

}  // namespace
}  // namespace kincal
