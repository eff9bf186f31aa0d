#include "vision/pivot.h"

#include <gtest/gtest.h>

#include <random>

#include "data/error.h"
#include "synth/render.h"
#include "vision/tool_pose.h"

namespace kincal {
namespace {

// Poses of a tool whose tip (tip_in_tool) stays at pivot_in_rig, tilted by
// up to ~20 deg about two axes.
std::vector<Rigid3> PivotPoses(const Eigen::Vector3d& tip_in_tool,
                               const Eigen::Vector3d& pivot_in_rig,
                               const Eigen::Matrix3d& base, int n) {
  std::vector<Rigid3> poses;
  for (int i = 0; i < n; ++i) {
    const double a = 2 * M_PI * i / n;
    Rigid3 p;
    p.R = Eigen::AngleAxisd(0.3 * std::sin(a), Eigen::Vector3d::UnitX()) *
          Eigen::AngleAxisd(0.3 * std::cos(a), Eigen::Vector3d::UnitY()) * base;
    p.t = pivot_in_rig - p.R * tip_in_tool;
    poses.push_back(p);
  }
  return poses;
}

TEST(Pivot, ExactPosesGiveExactTip) {
  const Eigen::Vector3d tip(3, 100, 12), pivot(40, 60, 480);
  const auto poses = PivotPoses(tip, pivot, Eigen::Matrix3d::Identity(), 8);
  const PivotResult r = PivotCalibration(poses);
  EXPECT_LT((r.tip_in_tool - tip).norm(), 1e-9);
  EXPECT_LT((r.pivot_in_rig - pivot).norm(), 1e-9);
  EXPECT_LT(r.rms_mm, 1e-9);
  EXPECT_EQ(r.residuals_mm.size(), 8u);
}

TEST(Pivot, RejectsTooFewOrDegeneratePoses) {
  const Eigen::Vector3d tip(0, 100, 0), pivot(0, 0, 500);
  auto poses = PivotPoses(tip, pivot, Eigen::Matrix3d::Identity(), 8);
  poses.resize(2);
  EXPECT_THROW(PivotCalibration(poses), InputError);
  // Rotations about one axis only.
  std::vector<Rigid3> one_axis;
  for (int i = 0; i < 6; ++i) {
    Rigid3 p;
    p.R =
        Eigen::AngleAxisd(0.1 * i, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    p.t = pivot - p.R * tip;
    one_axis.push_back(p);
  }
  EXPECT_THROW(PivotCalibration(one_axis), InputError);
}

// Rendered stereo frames of the example tool pivoting about its tip: poses
// from the images, then the pivot calibration recovers tip_in_tool.
TEST(Pivot, RenderedPivotRecoversTipOffset) {
  const Rig rig = ExampleStereoRig(640, 512);
  const Target target = ExampleTarget();
  const Rigid3 mid = ExampleToolPose(0);
  const Eigen::Vector3d pivot = mid * target.tip_in_tool;
  RenderOptions o;
  o.blur_sigma_px = 0.7;
  o.noise_sigma = 1.0;
  StereoRenderer renderer(rig, target, o);
  AprilTagDetector detector;
  std::mt19937_64 rng(8);
  std::vector<Rigid3> estimated;
  for (const Rigid3& pose : PivotPoses(target.tip_in_tool, pivot, mid.R, 8)) {
    const StereoFrameTruth frame = renderer.Render(pose, &rng);
    std::vector<std::vector<TagDetection>> dets;
    for (const auto& v : frame.views) dets.push_back(detector.Detect(v.image));
    const ToolPoseResult r = EstimateToolPose(rig, target, dets);
    ASSERT_TRUE(r.found) << r.why_not;
    estimated.push_back(r.rig_from_tool);
  }
  const PivotResult r = PivotCalibration(estimated);
  std::printf("pivot: tip error %.4f mm, pivot error %.4f mm, RMS %.4f mm\n",
              (r.tip_in_tool - target.tip_in_tool).norm(),
              (r.pivot_in_rig - pivot).norm(), r.rms_mm);
  EXPECT_LT((r.tip_in_tool - target.tip_in_tool).norm(), 0.3);
  EXPECT_LT((r.pivot_in_rig - pivot).norm(), 0.3);
  EXPECT_LT(r.rms_mm, 0.2);
}

}  // namespace
}  // namespace kincal
