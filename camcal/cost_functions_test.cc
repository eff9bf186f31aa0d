#include "camcal/cost_functions.h"

#include <gtest/gtest.h>

#include <memory>

namespace kincal {
namespace {

CameraIntrinsics Pinhole() {
  CameraIntrinsics c;
  c.width = 640;
  c.height = 480;
  c.fx = 500;
  c.fy = 500;
  c.cx = 320;
  c.cy = 240;
  return c;
}

// Evaluates a cost function at `blocks`; false when the functor refused.
bool Evaluate(const ceres::CostFunction& cost,
              const std::vector<const double*>& blocks, double residual[2]) {
  return cost.Evaluate(blocks.data(), residual, nullptr);
}

TEST(CostFunctionsTest, TargetReprojectionIsPixelDifference) {
  const std::array<double, kNumIntrinsics> intr = Pinhole().ToArray();
  const double q[4] = {0, 0, 0, 1};  // Eigen order x, y, z, w
  const double t[3] = {0, 0, 100};
  // (10, -20, 0) at z = 100 projects to (320 + 50, 240 - 100).
  std::unique_ptr<ceres::CostFunction> cost(TargetReprojectionError::Create(
      Eigen::Vector3d(10, -20, 0), Eigen::Vector2d(369, 141)));
  double r[2];
  ASSERT_TRUE(Evaluate(*cost, {intr.data(), q, t}, r));
  EXPECT_NEAR(r[0], 1.0, 1e-12);
  EXPECT_NEAR(r[1], -1.0, 1e-12);
}

TEST(CostFunctionsTest, RationalRegularizationScalesK4ToK6) {
  CameraIntrinsics cam = Pinhole();
  cam.distortion = {0.1, -0.2, 0.01, 0.02, 0.3, 0.4, -0.5, 0.6};
  const std::array<double, kNumIntrinsics> intr = cam.ToArray();
  std::unique_ptr<ceres::CostFunction> cost(
      RationalDistortionRegularizationError::Create(2.0));
  ASSERT_EQ(cost->num_residuals(), 3);
  double r[3];
  ASSERT_TRUE(Evaluate(*cost, {intr.data()}, r));
  EXPECT_DOUBLE_EQ(r[0], 0.8);
  EXPECT_DOUBLE_EQ(r[1], -1.0);
  EXPECT_DOUBLE_EQ(r[2], 1.2);
}

TEST(CostFunctionsTest, LensRegularizerPullsDistortionAndCentre) {
  std::array<double, kNumIntrinsics> intr = Pinhole().ToArray();
  intr[kCx] = 330.0;
  intr[kCy] = 235.0;
  intr[kK1] = -0.3;
  intr[kK1 + 4] = 0.1;  // k3
  std::unique_ptr<ceres::CostFunction> cost(
      LensRegularizationError::Create(0.5, 0.01, 319.5, 239.5));
  ASSERT_EQ(cost->num_residuals(), 10);
  double r[10];
  ASSERT_TRUE(Evaluate(*cost, {intr.data()}, r));
  EXPECT_DOUBLE_EQ(r[0], -0.15);
  EXPECT_DOUBLE_EQ(r[1], 0.0);
  EXPECT_DOUBLE_EQ(r[4], 0.05);
  EXPECT_DOUBLE_EQ(r[7], 0.0);
  EXPECT_NEAR(r[8], 0.105, 1e-12);
  EXPECT_NEAR(r[9], -0.045, 1e-12);
}

TEST(CostFunctionsTest, RigTargetAppliesCamFromRig) {
  const std::array<double, kNumIntrinsics> intr = Pinhole().ToArray();
  const double q_identity[4] = {0, 0, 0, 1};
  const double t_cam[3] = {-10, 0, 0};  // camera 10 mm to the right
  const double t_target[3] = {0, 0, 100};
  std::unique_ptr<ceres::CostFunction> cost(RigTargetReprojectionError::Create(
      Eigen::Vector3d(10, 0, 0), Eigen::Vector2d(320, 240)));
  double r[2];
  ASSERT_TRUE(Evaluate(
      *cost, {intr.data(), q_identity, t_cam, q_identity, t_target}, r));
  EXPECT_NEAR(r[0], 0.0, 1e-12);
  EXPECT_NEAR(r[1], 0.0, 1e-12);
}

TEST(CostFunctionsTest, PointBehindCameraIsRefused) {
  const std::array<double, kNumIntrinsics> intr = Pinhole().ToArray();
  const double q[4] = {0, 0, 0, 1};
  const double t[3] = {0, 0, -100};
  std::unique_ptr<ceres::CostFunction> cost(TargetReprojectionError::Create(
      Eigen::Vector3d(0, 0, 0), Eigen::Vector2d(320, 240)));
  double r[2];
  EXPECT_FALSE(Evaluate(*cost, {intr.data(), q, t}, r));
}

TEST(CostFunctionsTest, RotatedRayQuarterTurn) {
  const std::array<double, kNumIntrinsics> intr = Pinhole().ToArray();
  // The ray (1, 0, 1) turned -45 deg about y lands on the optical axis.
  const double aa[3] = {0, -M_PI / 4, 0};
  std::unique_ptr<ceres::CostFunction> cost(RotatedRayError::Create(
      Eigen::Vector3d(1, 0, 1), Eigen::Vector2d(320, 240), intr));
  double r[2];
  ASSERT_TRUE(Evaluate(*cost, {aa}, r));
  EXPECT_NEAR(r[0], 0.0, 1e-9);
  EXPECT_NEAR(r[1], 0.0, 1e-9);
}

TEST(CostFunctionsTest, ToolCornerComposesToolRigAndCamera) {
  Camera camera;
  camera.intrinsics = Pinhole();
  camera.cam_from_rig.t = Eigen::Vector3d(0, 5, 0);
  const double q[4] = {1, 0, 0, 0};  // Ceres order w, x, y, z
  const double t[3] = {0, 0, 200};
  // (0, 0, 0) in the tool -> (0, 5, 200) in the camera -> v = 240 + 12.5.
  std::unique_ptr<ceres::CostFunction> cost(ToolCornerReprojectionCost::Create(
      Eigen::Vector2d(320, 250), Eigen::Vector3d(0, 0, 0), camera));
  double r[2];
  ASSERT_TRUE(Evaluate(*cost, {q, t}, r));
  EXPECT_NEAR(r[0], 0.0, 1e-12);
  EXPECT_NEAR(r[1], 2.5, 1e-12);
}

}  // namespace
}  // namespace kincal
