#include "vision/pose_uncertainty.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

#include "synth/render.h"

namespace kincal {
namespace {

// Detections of the target at `rig_from_tool` in the first `num_cameras`
// cameras of the rig, every corner moved by Gaussian noise of sigma_px.
std::vector<std::vector<TagDetection>> Detections(
    const Rig& rig, const Target& target, const Rigid3& rig_from_tool,
    int num_cameras, double sigma_px, std::mt19937_64* rng) {
  std::normal_distribution<double> noise(0.0, sigma_px);
  std::vector<std::vector<TagDetection>> dets(num_cameras);
  for (int c = 0; c < num_cameras; ++c) {
    const Camera& cam = rig.cameras[c];
    for (const TargetTag& tag : target.tags) {
      TagDetection d;
      d.id = tag.id;
      for (int k = 0; k < 4; ++k) {
        d.corners[k] =
            Project(cam.intrinsics,
                    cam.cam_from_rig * (rig_from_tool * tag.CornerInTool(k))) +
            Eigen::Vector2d(noise(*rng), noise(*rng));
      }
      d.detector_corners = d.corners;
      dets[c].push_back(d);
    }
  }
  return dets;
}

// The tip covariance predicted from one frame's fit matches the scatter of
// the tips over repeated noisy detections (one camera and two), and one
// camera's depth sigma is well above two cameras' (2.25x here).
TEST(TipUncertainty, MatchesMonteCarloForOneAndTwoCameras) {
  Rig rig = ExampleStereoRig(640, 512);
  const Target target = ExampleTarget();
  const Rigid3 pose = ExampleToolPose(1);
  const double sigma_px = 0.2;
  double depth_sigma[2] = {0, 0};
  ToolPoseOptions options;
  options.outlier_px = 100;  // keep every observation (Gaussian noise only)
  options.hard_outlier_px = 100;
  options.corner_outlier_px = 100;
  for (int nc = 1; nc <= 2; ++nc) {
    std::mt19937_64 rng(17 + nc);
    const Eigen::Vector3d truth = pose * target.tip_in_tool;
    const Eigen::Vector3d centre = rig.cameras[0].cam_from_rig.Inverse().t;
    const Eigen::Vector3d sight = (truth - centre).normalized();
    double ss_depth = 0, predicted = 0;
    const int trials = 200;
    for (int t = 0; t < trials; ++t) {
      const ToolPoseResult r = EstimateToolPose(
          rig, target, Detections(rig, target, pose, nc, sigma_px, &rng),
          options);
      ASSERT_TRUE(r.found) << r.why_not;
      const double d = sight.dot(r.tip_in_rig - truth);
      ss_depth += d * d;
      const TipUncertainty u = TipUncertaintyOf(rig, target, r, sigma_px);
      ASSERT_TRUE(u.ok);
      EXPECT_GE(u.max_sigma_mm, u.depth_sigma_mm - 1e-12);
      predicted += u.depth_sigma_mm / trials;
    }
    const double actual = std::sqrt(ss_depth / trials);
    EXPECT_GT(actual / predicted, 0.8) << nc << " camera(s)";
    EXPECT_LT(actual / predicted, 1.25) << nc << " camera(s)";
    depth_sigma[nc - 1] = predicted;
  }
  EXPECT_GT(depth_sigma[0], 1.5 * depth_sigma[1]);
  std::printf("tip depth sigma: one camera %.3f mm, two %.3f mm\n",
              depth_sigma[0], depth_sigma[1]);
}

TEST(TipUncertainty, NotFoundHasNone) {
  const ToolPoseResult none;
  EXPECT_FALSE(
      TipUncertaintyOf(ExampleStereoRig(), ExampleTarget(), none, 0.2).ok);
}

}  // namespace
}  // namespace kincal
