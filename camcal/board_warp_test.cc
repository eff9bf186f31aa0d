// The board-warp paraboloid and its reprojection functors.

#include "camcal/board_warp.h"

#include <gtest/gtest.h>

#include <memory>

namespace kincal {
namespace {

TEST(BoardWarp, ExtentAndParaboloid) {
  const std::vector<Eigen::Vector3d> points = {
      {0, 0, 0}, {8, 0, 0}, {0, 5, 0}, {8, 5, 0}, {4, 2.5, 0}};
  const BoardExtent e = BoardExtent::Of(points);
  EXPECT_DOUBLE_EQ(e.x_min, 0);
  EXPECT_DOUBLE_EQ(e.x_max, 8);
  EXPECT_DOUBLE_EQ(e.y_max, 5);
  const double warp[2] = {0.02, -0.01};
  // Edges stay in the plane, the centre moves by warp_x + warp_y, the
  // middle of an edge by one of them.
  EXPECT_DOUBLE_EQ(WarpedPoint(points[0], e, warp).z(), 0.0);
  EXPECT_DOUBLE_EQ(WarpedPoint(points[3], e, warp).z(), 0.0);
  EXPECT_NEAR(WarpedPoint(points[4], e, warp).z(), 0.01, 1e-15);
  EXPECT_NEAR(WarpedPoint(Eigen::Vector3d(4, 0, 0), e, warp).z(), 0.02, 1e-15);
  EXPECT_NEAR(WarpedPoint(Eigen::Vector3d(2, 2.5, 0), e, warp).z(),
              0.02 * 0.75 - 0.01, 1e-15);
  // One point: a degenerate extent of width 1, no division by zero.
  const BoardExtent one = BoardExtent::Of({Eigen::Vector3d(3, 3, 0)});
  EXPECT_DOUBLE_EQ(one.x_max - one.x_min, 1.0);
}

// With zero warp the warped functors equal the plain ones; with a warp the
// residual is that of the moved point.
TEST(BoardWarp, FunctorsMatchThePlainOnesAtZeroWarp) {
  const BoardExtent e{0, 8, 0, 5};
  const Eigen::Vector3d p(3, 2, 0);
  const Eigen::Vector2d pixel(300, 200);
  std::array<double, kNumIntrinsics> intrinsics{};
  intrinsics[kFx] = 800;
  intrinsics[kFy] = 790;
  intrinsics[kCx] = 320;
  intrinsics[kCy] = 240;
  intrinsics[kK1] = -0.1;
  const double q[4] = {0.01, -0.02, 0.03, 0.999};
  const double t[3] = {-4, -2, 20};
  const double q_cr[4] = {0, 0.01, 0, 1};
  const double t_cr[3] = {-3.3, 0, 0.1};
  double zero[2] = {0, 0};
  double warp[2] = {0.05, 0.03};
  double plain[2], warped[2], moved[2];
  std::unique_ptr<ceres::CostFunction> a(
      TargetReprojectionError::Create(p, pixel));
  std::unique_ptr<ceres::CostFunction> b(
      WarpedTargetReprojectionError::Create(p, pixel, e));
  const double* pa[] = {intrinsics.data(), q, t};
  const double* pb[] = {intrinsics.data(), q, t, zero};
  ASSERT_TRUE(a->Evaluate(pa, plain, nullptr));
  ASSERT_TRUE(b->Evaluate(pb, warped, nullptr));
  EXPECT_DOUBLE_EQ(plain[0], warped[0]);
  EXPECT_DOUBLE_EQ(plain[1], warped[1]);
  const double* pw[] = {intrinsics.data(), q, t, warp};
  ASSERT_TRUE(b->Evaluate(pw, warped, nullptr));
  std::unique_ptr<ceres::CostFunction> c(TargetReprojectionError::Create(
      Eigen::Vector3d(p.x(), p.y(), WarpedPoint(p, e, warp).z()), pixel));
  ASSERT_TRUE(c->Evaluate(pa, moved, nullptr));
  EXPECT_NEAR(warped[0], moved[0], 1e-12);
  EXPECT_NEAR(warped[1], moved[1], 1e-12);
  EXPECT_GT(std::abs(warped[0] - plain[0]) + std::abs(warped[1] - plain[1]),
            0.1);
  // Second camera.
  std::unique_ptr<ceres::CostFunction> d(
      RigTargetReprojectionError::Create(p, pixel));
  std::unique_ptr<ceres::CostFunction> f(
      WarpedRigTargetReprojectionError::Create(p, pixel, e));
  const double* pd[] = {intrinsics.data(), q_cr, t_cr, q, t};
  const double* pf[] = {intrinsics.data(), q_cr, t_cr, q, t, zero};
  ASSERT_TRUE(d->Evaluate(pd, plain, nullptr));
  ASSERT_TRUE(f->Evaluate(pf, warped, nullptr));
  EXPECT_DOUBLE_EQ(plain[0], warped[0]);
  EXPECT_DOUBLE_EQ(plain[1], warped[1]);
}

}  // namespace
}  // namespace kincal
