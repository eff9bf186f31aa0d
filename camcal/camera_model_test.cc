#include "camcal/camera_model.h"

#include <ceres/jet.h>
#include <gtest/gtest.h>

#include <opencv2/calib3d.hpp>
#include <random>
#include <vector>

namespace kincal {
namespace {

CameraIntrinsics MakeCamera(int num_distortion) {
  CameraIntrinsics cam;
  cam.name = "test";
  cam.width = 1280;
  cam.height = 1024;
  cam.fx = 1810.5;
  cam.fy = 1795.25;
  cam.cx = 641.3;
  cam.cy = 509.8;
  const std::vector<double> all = {-0.21, 0.13, 0.0012, -0.0008,
                                   -0.05, 0.02, -0.01,  0.004};
  cam.distortion.assign(all.begin(), all.begin() + num_distortion);
  return cam;
}

std::vector<cv::Point3d> RandomPoints(int n, std::mt19937_64* rng) {
  std::uniform_real_distribution<double> xy(-0.45, 0.45);
  std::uniform_real_distribution<double> z(200.0, 2000.0);
  std::vector<cv::Point3d> pts;
  for (int i = 0; i < n; ++i) {
    const double depth = z(*rng);
    pts.emplace_back(xy(*rng) * depth, xy(*rng) * depth, depth);
  }
  return pts;
}

class ProjectVsOpenCV : public ::testing::TestWithParam<int> {};

// The formula must equal cv::projectPoints (same model, same pixel centres).
TEST_P(ProjectVsOpenCV, MatchesProjectPoints) {
  const CameraIntrinsics cam = MakeCamera(GetParam());
  std::mt19937_64 rng(1);
  const std::vector<cv::Point3d> pts = RandomPoints(500, &rng);
  std::vector<cv::Point2d> cv_px;
  cv::Mat K =
      (cv::Mat_<double>(3, 3) << cam.fx, 0, cam.cx, 0, cam.fy, cam.cy, 0, 0, 1);
  cv::Mat dist(cam.distortion, true);
  cv::projectPoints(pts, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), K, dist,
                    cv_px);
  double max_err = 0;
  for (size_t i = 0; i < pts.size(); ++i) {
    const Eigen::Vector2d px =
        Project(cam, Eigen::Vector3d(pts[i].x, pts[i].y, pts[i].z));
    max_err = std::max(
        max_err,
        (px - Eigen::Vector2d(cv_px[i].x, cv_px[i].y)).cwiseAbs().maxCoeff());
  }
  EXPECT_LT(max_err, 1e-9) << GetParam() << " coefficients";
}

// Undistort/Unproject invert Project.
TEST_P(ProjectVsOpenCV, UnprojectInvertsProject) {
  const CameraIntrinsics cam = MakeCamera(GetParam());
  std::mt19937_64 rng(2);
  for (const cv::Point3d& p : RandomPoints(300, &rng)) {
    const Eigen::Vector3d p_in_cam(p.x, p.y, p.z);
    const Eigen::Vector2d px = Project(cam, p_in_cam);
    const Eigen::Vector3d ray = Unproject(cam, px);
    EXPECT_NEAR(ray.dot(p_in_cam.normalized()), 1.0, 1e-14);
    EXPECT_LT((Project(cam, ray * 1000.0) - px).norm(), 1e-8);
  }
}

// OpenCV's own undistortPoints agrees with UndistortPixel.
TEST_P(ProjectVsOpenCV, UndistortMatchesOpenCV) {
  const CameraIntrinsics cam = MakeCamera(GetParam());
  std::vector<cv::Point2d> px = {
      {10, 12}, {640, 512}, {1200, 1000}, {300, 800}};
  std::vector<cv::Point2d> und;
  cv::Mat K =
      (cv::Mat_<double>(3, 3) << cam.fx, 0, cam.cx, 0, cam.fy, cam.cy, 0, 0, 1);
  cv::undistortPoints(px, und, K, cv::Mat(cam.distortion, true), cv::noArray(),
                      cv::noArray(),
                      cv::TermCriteria(cv::TermCriteria::COUNT, 200, 0));
  for (size_t i = 0; i < px.size(); ++i) {
    const Eigen::Vector2d xy = UndistortPixel(cam, {px[i].x, px[i].y});
    EXPECT_NEAR(xy.x(), und[i].x, 1e-6);
    EXPECT_NEAR(xy.y(), und[i].y, 1e-6);
  }
}

// The pinhole image is OpenCV's undistorted image with the same K, and
// DistortedPixel inverts PinholePixel.
TEST_P(ProjectVsOpenCV, PinholePixelIsOpenCVsUndistortedPixel) {
  const CameraIntrinsics cam = MakeCamera(GetParam());
  const std::vector<cv::Point2d> px = {
      {10, 12}, {640, 512}, {1200, 1000}, {300, 800}};
  std::vector<cv::Point2d> und;
  const cv::Mat K =
      (cv::Mat_<double>(3, 3) << cam.fx, 0, cam.cx, 0, cam.fy, cam.cy, 0, 0, 1);
  cv::undistortPoints(px, und, K, cv::Mat(cam.distortion, true), cv::noArray(),
                      K, cv::TermCriteria(cv::TermCriteria::COUNT, 200, 0));
  for (size_t i = 0; i < px.size(); ++i) {
    const Eigen::Vector2d pinhole = PinholePixel(cam, {px[i].x, px[i].y});
    EXPECT_NEAR(pinhole.x(), und[i].x, 1e-4);
    EXPECT_NEAR(pinhole.y(), und[i].y, 1e-4);
    const Eigen::Vector2d back = DistortedPixel(cam, pinhole);
    EXPECT_NEAR(back.x(), px[i].x, 1e-6);
    EXPECT_NEAR(back.y(), px[i].y, 1e-6);
  }
}

INSTANTIATE_TEST_SUITE_P(Distortion, ProjectVsOpenCV,
                         ::testing::Values(0, 4, 5, 8));

TEST(ProjectPoint, BehindCameraReturnsFalse) {
  const std::array<double, kNumIntrinsics> a = MakeCamera(5).ToArray();
  double pixel[2] = {7, 7};
  const double p_in_cam[3] = {1, 2, -3};
  EXPECT_FALSE(ProjectPoint(a.data(), p_in_cam, pixel));
  EXPECT_EQ(pixel[0], 7);
  const double p_zero[3] = {1, 2, 0};
  EXPECT_FALSE(ProjectPoint(a.data(), p_zero, pixel));
  EXPECT_TRUE(Project(MakeCamera(5), Eigen::Vector3d(0, 0, -1)).hasNaN());
}

// Autodiff derivatives (as Ceres computes them) equal central differences.
TEST(ProjectPoint, JetDerivativesMatchFiniteDifferences) {
  using Jet = ceres::Jet<double, kNumIntrinsics + 3>;
  const std::array<double, kNumIntrinsics> a = MakeCamera(8).ToArray();
  const double p[3] = {120.0, -80.0, 900.0};
  Jet aj[kNumIntrinsics], pj[3], px[2];
  for (int i = 0; i < kNumIntrinsics; ++i) aj[i] = Jet(a[i], i);
  for (int i = 0; i < 3; ++i) pj[i] = Jet(p[i], kNumIntrinsics + i);
  ASSERT_TRUE(ProjectPoint(aj, pj, px));
  for (int k = 0; k < kNumIntrinsics + 3; ++k) {
    std::array<double, kNumIntrinsics> ap = a, am = a;
    double pp[3] = {p[0], p[1], p[2]}, pm[3] = {p[0], p[1], p[2]};
    const double h =
        k < kNumIntrinsics ? 1e-6 * std::max(1.0, std::abs(a[k])) : 1e-4;
    if (k < kNumIntrinsics) {
      ap[k] += h;
      am[k] -= h;
    } else {
      pp[k - kNumIntrinsics] += h;
      pm[k - kNumIntrinsics] -= h;
    }
    double up[2], um[2];
    ProjectPoint(ap.data(), pp, up);
    ProjectPoint(am.data(), pm, um);
    for (int c = 0; c < 2; ++c) {
      const double fd = (up[c] - um[c]) / (2 * h);
      EXPECT_NEAR(px[c].v[k], fd, 1e-5 * std::max(1.0, std::abs(fd)))
          << "parameter " << k << " coordinate " << c;
    }
  }
}

TEST(CameraIntrinsics, ArrayRoundTrip) {
  const CameraIntrinsics cam = MakeCamera(5);
  const auto a = cam.ToArray();
  EXPECT_EQ(a[kK3], -0.05);
  EXPECT_EQ(a[kK4], 0.0);
  const CameraIntrinsics back = CameraIntrinsics::FromArray(a.data(), 5);
  EXPECT_EQ(back.distortion, cam.distortion);
  EXPECT_EQ(back.fx, cam.fx);
  EXPECT_EQ(back.cy, cam.cy);
}

TEST(Rigid3, ComposeAndInverse) {
  Rigid3 a;
  a.R = Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized())
            .toRotationMatrix();
  a.t = Eigen::Vector3d(10, -20, 30);
  const Eigen::Vector3d p(1, 2, 3);
  EXPECT_LT(((a.Inverse() * a) * p - p).norm(), 1e-12);
  EXPECT_LT((a.ToIsometry() * p - a * p).norm(), 1e-12);
}

}  // namespace
}  // namespace kincal
