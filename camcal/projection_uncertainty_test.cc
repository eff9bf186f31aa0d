#include "camcal/projection_uncertainty.h"

#include <gtest/gtest.h>

#include <cmath>

#include "data/error.h"

namespace kincal {
namespace {

// One pinhole camera (f = 500 px, 640 x 480) and `num_views` target poses
// 1000 units in front of it; delta = 4 intrinsics (fx fy cx cy) then 6 per
// view; covariance zero.
CalibrationCovariance PinholeWithViews(int num_views) {
  CalibrationCovariance cal;
  std::array<double, kNumIntrinsics> intrinsics{};
  intrinsics[kFx] = 500;
  intrinsics[kFy] = 500;
  intrinsics[kCx] = 319.5;
  intrinsics[kCy] = 239.5;
  cal.intrinsics = {intrinsics};
  std::array<int, kNumIntrinsics> index;
  index.fill(-1);
  for (int i = 0; i < 4; ++i) index[i] = i;
  cal.intrinsic_index = {index};
  cal.cam_from_rig = {Rigid3()};
  cal.cam_from_rig_index = {-1};
  for (int v = 0; v < num_views; ++v) {
    Rigid3 pose;
    pose.R = RotationMatrixFromVector(Eigen::Vector3d(0.2 * v, -0.1, 0.05 * v));
    pose.t = Eigen::Vector3d(10.0 * v, -5, 1000);
    cal.rig_from_target.push_back(pose);
    cal.rig_from_target_index.push_back(4 + 6 * v);
  }
  const int n = 4 + 6 * num_views;
  cal.covariance = Eigen::MatrixXd::Zero(n, n);
  return cal;
}

const double kInf = std::numeric_limits<double>::infinity();

TEST(ProjectionUncertainty, PrincipalPointSigmaMovesEveryPixel) {
  CalibrationCovariance cal = PinholeWithViews(2);
  cal.covariance(2, 2) = 4.0;  // sigma(cx) = 2 px
  for (const Eigen::Vector2d& px :
       {Eigen::Vector2d(319.5, 239.5), Eigen::Vector2d(0, 0),
        Eigen::Vector2d(639, 479)}) {
    for (double distance : {kInf, 2000.0}) {
      const Eigen::Matrix2d cov = ProjectionCovariance(cal, 0, px, distance);
      EXPECT_NEAR(cov(0, 0), 4.0, 1e-6);
      EXPECT_NEAR(cov(1, 1), 0.0, 1e-9);
      EXPECT_NEAR(WorstDirectionSigma(cov), 2.0, 1e-6);
    }
  }
}

TEST(ProjectionUncertainty, FocalLengthSigmaGrowsTowardTheEdges) {
  CalibrationCovariance cal = PinholeWithViews(1);
  cal.covariance(0, 0) = 1.0;  // sigma(fx) = 1 px: u - cx scales with fx
  EXPECT_NEAR(WorstDirectionSigma(ProjectionCovariance(
                  cal, 0, Eigen::Vector2d(319.5, 100), kInf)),
              0.0, 1e-6);
  EXPECT_NEAR(WorstDirectionSigma(ProjectionCovariance(
                  cal, 0, Eigen::Vector2d(619.5, 100), kInf)),
              300.0 / 500.0, 1e-6);
}

TEST(ProjectionUncertainty, ViewPosesMoveTheReferenceAndAverage) {
  // sigma 1 mrad on each rotation component of every view pose: a point at
  // infinity fixed relative to the targets moves by f * sigma / sqrt(views)
  // at the centre (the mean over the views averages independent errors).
  for (int views : {1, 4}) {
    CalibrationCovariance cal = PinholeWithViews(views);
    for (int v = 0; v < views; ++v) {
      for (int k = 0; k < 3; ++k) {
        const int i = cal.rig_from_target_index[v] + k;
        cal.covariance(i, i) = 1e-6;
      }
    }
    const Eigen::Vector2d centre(319.5, 239.5);
    EXPECT_NEAR(WorstDirectionSigma(ProjectionCovariance(cal, 0, centre, kInf)),
                500 * 1e-3 / std::sqrt(views), 1e-6)
        << views;
  }
}

TEST(ProjectionUncertainty, TranslationsMatterOnlyAtFiniteDistance) {
  CalibrationCovariance cal = PinholeWithViews(1);
  const int t = cal.rig_from_target_index[0] + 3;
  cal.covariance(t, t) = 1.0;  // sigma 1 unit in x of the only view
  const Eigen::Vector2d centre(319.5, 239.5);
  EXPECT_NEAR(WorstDirectionSigma(ProjectionCovariance(cal, 0, centre, kInf)),
              0.0, 1e-9);
  // At 2000 units the point moves 1 unit sideways: f / Z px.
  EXPECT_NEAR(WorstDirectionSigma(ProjectionCovariance(cal, 0, centre, 2000.0)),
              500.0 / 2000.0, 1e-6);
}

TEST(ProjectionUncertainty, CorrelatedParametersCancel) {
  // A focal length and a view rotation that move the edge pixel in opposite
  // directions, perfectly correlated: the uncertainty vanishes there.
  CalibrationCovariance cal = PinholeWithViews(1);
  const Eigen::Vector2d px(619.5, 239.5);  // x = 0.6 in normalised units
  // dq/dfx = 0.6; dq/d(rotation about y) = fx (1 + x^2) = 680 px/rad.
  Eigen::Vector2d a(0.6, 680);  // the two derivatives
  Eigen::Matrix2d block;
  block << a.y() * a.y(), -a.x() * a.y(), -a.x() * a.y(), a.x() * a.x();
  const int ry = cal.rig_from_target_index[0] + 1;
  cal.covariance(0, 0) = block(0, 0) * 1e-8;
  cal.covariance(0, ry) = cal.covariance(ry, 0) = block(0, 1) * 1e-8;
  cal.covariance(ry, ry) = block(1, 1) * 1e-8;
  EXPECT_LT(WorstDirectionSigma(ProjectionCovariance(cal, 0, px, kInf)), 1e-4);
  cal.covariance(0, ry) = cal.covariance(ry, 0) = 0;  // uncorrelated: not 0
  EXPECT_GT(WorstDirectionSigma(ProjectionCovariance(cal, 0, px, kInf)), 0.05);
}

TEST(ProjectionUncertainty, MapAndValidRegion) {
  CalibrationCovariance cal = PinholeWithViews(1);
  cal.covariance(0, 0) = 1.0;  // sigma(fx) = 1 px
  // sigma at pixel u is |u - cx| / fx * sigma(fx) = |u - cx| / 500 px:
  // below 0.5 px where |u - cx| < 250.
  UncertaintyOptions options;
  options.valid_threshold_px = 0.5;
  options.region_rays = 8;
  const ProjectionUncertaintyMap map =
      MapProjectionUncertainty(cal, 0, 640, 480, options);
  EXPECT_NEAR(map.centre_px, 0.0, 1e-6);
  for (double s : map.corner_px) EXPECT_NEAR(s, 319.5 / 500, 1e-6);
  ASSERT_EQ(map.grid_px.size(), 48u);
  EXPECT_NEAR(map.grid_px[0], (319.5 - 39.5) / 500, 1e-6);  // cell centre
  ASSERT_EQ(map.valid_region.size(), 9u);                   // closed
  EXPECT_EQ(map.valid_region.front(), map.valid_region.back());
  EXPECT_NEAR(map.valid_region[0].x(), 319.5 + 250, 1.0);  // ray along +x
  EXPECT_NEAR(map.valid_region[2].y(), 479, 1e-9);         // +y: to the edge
  EXPECT_NEAR(map.valid_region[4].x(), 319.5 - 250, 1.0);
  options.valid_threshold_px = 1e-9;  // not even the centre
  cal.covariance(2, 2) = 1.0;
  EXPECT_TRUE(
      MapProjectionUncertainty(cal, 0, 640, 480, options).valid_region.empty());
  options.distance = -1;
  EXPECT_THROW(MapProjectionUncertainty(cal, 0, 640, 480, options), InputError);
}

}  // namespace
}  // namespace kincal
