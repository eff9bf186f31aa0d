#include "synth/rig_placement.h"

#include <gtest/gtest.h>

#include <random>

#include "synth/render.h"

namespace kincal {
namespace {

// Tips spread over a 300 mm box around (500, 0, 300) in the base frame.
std::vector<Eigen::Matrix4d> Tips(int n) {
  std::mt19937_64 rng(2);
  std::uniform_real_distribution<double> u(-150, 150);
  std::vector<Eigen::Matrix4d> out;
  for (int i = 0; i < n; ++i) {
    Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
    m.block<3, 1>(0, 3) = Eigen::Vector3d(500 + u(rng), u(rng), 300 + u(rng));
    out.push_back(m);
  }
  return out;
}

int TipsInView(const std::vector<Eigen::Matrix4d>& tips, const Rig& rig,
               const Rigid3& rig_from_base) {
  const CameraIntrinsics& k = rig.cameras[0].intrinsics;
  int in = 0;
  for (const Eigen::Matrix4d& m : tips) {
    const Eigen::Vector2d px =
        Project(k, rig.cameras[0].cam_from_rig *
                       (rig_from_base * Eigen::Vector3d(m.block<3, 1>(0, 3))));
    in += px.allFinite() && px.x() >= 0 && px.x() < k.width && px.y() >= 0 &&
          px.y() < k.height;
  }
  return in;
}

TEST(PlaceRigFacingTips, TheRequestedShareOfTipsIsInView) {
  const Rig rig = ExampleStereoRig(640, 512);
  const Rigid3 tip_from_tool = TipFromTool(ExampleTarget());
  const std::vector<Eigen::Matrix4d> tips = Tips(50);
  for (double share : {1.0, 0.9}) {
    double distance = 0;
    const Rigid3 rig_from_base =
        PlaceRigFacingTips(tips, rig, tip_from_tool, share, &distance);
    EXPECT_TRUE((rig_from_base.R.transpose() * rig_from_base.R)
                    .isApprox(Eigen::Matrix3d::Identity(), 1e-12));
    EXPECT_GT(distance, 0);
    EXPECT_GE(TipsInView(tips, rig, rig_from_base), share * 50 - 1e-9)
        << "share " << share;
  }
}

TEST(PlaceRigFacingTips, AllTipsInViewNeedsAtLeastTheDistanceOfMost) {
  const Rig rig = ExampleStereoRig(640, 512);
  const Rigid3 tip_from_tool = TipFromTool(ExampleTarget());
  const std::vector<Eigen::Matrix4d> tips = Tips(50);
  double all = 0, most = 0;
  PlaceRigFacingTips(tips, rig, tip_from_tool, 1.0, &all);
  PlaceRigFacingTips(tips, rig, tip_from_tool, 0.5, &most);
  EXPECT_GE(all, most);
}

}  // namespace
}  // namespace kincal
