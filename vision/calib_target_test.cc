#include "vision/calib_target.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "data/error.h"
#include "tests/testing/paths.h"
#include "vision/apriltag_detector.h"

namespace kincal {
namespace {

using ::testing::HasSubstr;

TEST(CalibTargetSpec, ParsesChessboardAndAprilGrid) {
  const CalibTargetSpec c = ParseCalibTargetSpec("chessboard:9x6:25.5");
  EXPECT_EQ(c.kind, CalibTargetSpec::Kind::kChessboard);
  EXPECT_EQ(c.cols, 9);
  EXPECT_EQ(c.rows, 6);
  EXPECT_EQ(c.size, 25.5);
  const std::vector<Eigen::Vector3d> cp = c.Points();
  ASSERT_EQ(cp.size(), 54u);
  EXPECT_EQ(cp[10], Eigen::Vector3d(25.5, 25.5, 0));  // row 1, col 1

  const CalibTargetSpec a = ParseCalibTargetSpec("aprilgrid:6x4:30:0.3");
  EXPECT_EQ(a.kind, CalibTargetSpec::Kind::kAprilGrid);
  EXPECT_EQ(a.cols, 6);
  EXPECT_EQ(a.rows, 4);
  EXPECT_EQ(a.spacing_ratio, 0.3);
  const std::vector<Eigen::Vector3d> ap = a.Points();
  ASSERT_EQ(ap.size(), 4u * 24);
  // Tag 7 = row 1, col 1; corners bl, br, tr, tl with y up.
  EXPECT_LT((ap[4 * 7 + 0] - Eigen::Vector3d(39, 39, 0)).norm(), 1e-12);
  EXPECT_LT((ap[4 * 7 + 1] - Eigen::Vector3d(69, 39, 0)).norm(), 1e-12);
  EXPECT_LT((ap[4 * 7 + 2] - Eigen::Vector3d(69, 69, 0)).norm(), 1e-12);
  EXPECT_LT((ap[4 * 7 + 3] - Eigen::Vector3d(39, 69, 0)).norm(), 1e-12);
}

TEST(CalibTargetSpec, RejectsBadSpecs) {
  for (const char* bad :
       {"", "chessboard", "chessboard:9x6", "chessboard:9x6:0",
        "chessboard:9x6:-1", "chessboard:9:25", "chessboard:9x6:abc",
        "chessboard:1x6:25", "chessboard:9x6:25:1", "aprilgrid:6x6:30",
        "aprilgrid:6x6:30:0", "aprilgrid:100x100:30:0.3", "circles:4x11:20"}) {
    try {
      ParseCalibTargetSpec(bad);
      ADD_FAILURE() << "accepted '" << bad << "'";
    } catch (const InputError& e) {
      EXPECT_THAT(e.what(), HasSubstr("--target")) << bad;
    }
  }
}

// A rendered AprilGrid, seen through a homography: every tag found, every
// corner where the homography puts it.
TEST(CalibTargetDetector, AprilGridRenderedThroughHomography) {
  const CalibTargetSpec spec = ParseCalibTargetSpec("aprilgrid:5x4:8:0.25");
  const int cell = 8;    // px per tag cell (tag36h11: 8 cells black square)
  const int margin = 3;  // cells of white around the grid
  const double pitch = spec.size * (1 + spec.spacing_ratio);  // 10 cells
  const int board_w = static_cast<int>((2 * margin + 4 * pitch + 8) * cell);
  const int board_h = static_cast<int>((2 * margin + 3 * pitch + 8) * cell);
  cv::Mat board(board_h, board_w, CV_8UC1, cv::Scalar(255));
  // Target (x, y up) -> board pixel (OpenCV centres).
  auto to_board = [&](const Eigen::Vector3d& p) {
    return Eigen::Vector2d((margin + p.x()) * cell - 0.5,
                           board_h - (margin + p.y()) * cell - 0.5);
  };
  for (int id = 0; id < spec.cols * spec.rows; ++id) {
    cv::Mat tag;
    cv::resize(TagImage("tag36h11", id), tag, cv::Size(), cell, cell,
               cv::INTER_NEAREST);
    // Top-left of the black square = corner 3 (tl) of the tag.
    const Eigen::Vector2d tl = to_board(spec.Points()[4 * id + 3]);
    const int x0 = static_cast<int>(std::lround(tl.x() + 0.5)) - cell;
    const int y0 = static_cast<int>(std::lround(tl.y() + 0.5)) - cell;
    tag.copyTo(board(cv::Rect(x0, y0, tag.cols, tag.rows)));
  }
  const cv::Point2f src[4] = {{0, 0},
                              {float(board_w - 1), 0},
                              {float(board_w - 1), float(board_h - 1)},
                              {0, float(board_h - 1)}};
  const cv::Point2f dst[4] = {{60, 40}, {700, 80}, {660, 560}, {90, 520}};
  const cv::Mat H = cv::getPerspectiveTransform(src, dst);
  cv::Mat image;
  cv::warpPerspective(board, image, H, cv::Size(800, 600), cv::INTER_LINEAR,
                      cv::BORDER_CONSTANT, cv::Scalar(128));

  CalibTargetDetector detector(spec);
  const TargetObservation obs = detector.Detect(image);
  ASSERT_EQ(obs.pixels.size(), 4u * 20);
  double ss = 0;
  for (size_t i = 0; i < obs.pixels.size(); ++i) {
    const Eigen::Vector2d b = to_board(obs.p_in_target[i]);
    std::vector<cv::Point2d> in = {{b.x(), b.y()}}, out;
    cv::perspectiveTransform(in, out, H);
    const double e =
        (obs.pixels[i] - Eigen::Vector2d(out[0].x, out[0].y)).norm();
    EXPECT_LT(e, 0.5) << "point " << i;
    ss += e * e;
  }
  EXPECT_LT(std::sqrt(ss / obs.pixels.size()), 0.25);
}

TEST(CalibTargetDetector, ChessboardOnRealImageAndBlankImage) {
  const CalibTargetSpec spec = ParseCalibTargetSpec("chessboard:9x6:1");
  CalibTargetDetector detector(spec);
  EXPECT_TRUE(
      detector.Detect(cv::Mat(480, 640, CV_8UC1, cv::Scalar(90))).empty());
  KINCAL_REQUIRE_SHARED_DATA("opencv-stereo-left-right");
  const std::string dir =
      testing::SharedDataDir() + "/opencv-stereo-left-right";
  const cv::Mat left = cv::imread(dir + "/left01.jpg", cv::IMREAD_GRAYSCALE);
  const cv::Mat right = cv::imread(dir + "/right01.jpg", cv::IMREAD_GRAYSCALE);
  const TargetObservation l = detector.Detect(left);
  const TargetObservation r = detector.Detect(right);
  ASSERT_EQ(l.pixels.size(), 54u);
  ASSERT_EQ(r.pixels.size(), 54u);
  // Left and right corners of the same point lie on similar image rows
  // (nearly rectified rig), so the orders agree.
  for (size_t i = 0; i < 54; i += 13) {
    EXPECT_NEAR(l.pixels[i].y(), r.pixels[i].y(), 40) << i;
  }
}

// Layout options: parsed, and the grid cell of an id follows them.
TEST(CalibTargetSpec, AprilGridLayoutOptions) {
  const CalibTargetSpec s = ParseCalibTargetSpec(
      "aprilgrid:8x5:31.5:1:first=1:order=columns:origin=top-left:"
      "rotation=180");
  EXPECT_EQ(s.first_id, 1);
  EXPECT_TRUE(s.column_major);
  EXPECT_TRUE(s.origin_top);
  EXPECT_EQ(s.rotation_deg, 180);
  EXPECT_EQ(s.TagCell(0), Eigen::Vector2i(0, 4));  // id 1: top-left
  EXPECT_EQ(s.TagCell(1), Eigen::Vector2i(0, 3));  // id 2: below it
  EXPECT_EQ(s.TagCell(5), Eigen::Vector2i(1, 4));  // id 6: next column
  // Turned 180 deg: corner 0 (the tag's bottom-left) is the cell's top-right.
  const auto p = s.Points();
  const double pitch = 31.5 * 2;
  EXPECT_NEAR(p[0].x(), 31.5, 1e-12);
  EXPECT_NEAR(p[0].y(), 4 * pitch + 31.5, 1e-12);
  const CalibTargetSpec kalibr = ParseCalibTargetSpec("aprilgrid:6x6:30:0.3");
  EXPECT_EQ(kalibr.TagCell(7), Eigen::Vector2i(1, 1));
  EXPECT_THROW(ParseCalibTargetSpec("aprilgrid:6x6:30:0.3:rotation=45"),
               InputError);
  EXPECT_THROW(ParseCalibTargetSpec("aprilgrid:6x6:30:0.3:order=diagonal"),
               InputError);
  EXPECT_THROW(ParseCalibTargetSpec("aprilgrid:6x6:30:0.3:first=570"),
               InputError);
}

// The real photo of AprilTags.jl's grid (8 x 5 tags, ids 1..40 column by
// column from the top-left, 31.5 mm; upright as libapriltag reports the
// corners): with its layout
// every detected corner lands where the grid model puts it (one homography
// explains all of them to a few px in a 4032 px photo); with Kalibr's
// default layout the same detections do not fit a plane at all.
TEST(CalibTargetDetector, RealAprilGridPhotoInItsOwnLayout) {
  KINCAL_REQUIRE_SHARED_DATA("apriltags-jl");
  const cv::Mat gray =
      cv::imread(testing::SharedDataDir() +
                     "/apriltags-jl/data/CameraCalibration/taggridphoto.jpg",
                 cv::IMREAD_GRAYSCALE);
  ASSERT_FALSE(gray.empty());
  const auto homography_rms = [&](const std::string& spec, int* corners) {
    CalibTargetDetector detector(ParseCalibTargetSpec(spec));
    const TargetObservation obs = detector.Detect(gray);
    *corners = static_cast<int>(obs.pixels.size());
    if (obs.pixels.size() < 8) return 1e9;
    std::vector<cv::Point2f> src, dst;
    for (size_t i = 0; i < obs.pixels.size(); ++i) {
      src.emplace_back(obs.p_in_target[i].x(), obs.p_in_target[i].y());
      dst.emplace_back(obs.pixels[i].x(), obs.pixels[i].y());
    }
    const cv::Mat h = cv::findHomography(src, dst, 0);
    std::vector<cv::Point2f> mapped;
    cv::perspectiveTransform(src, mapped, h);
    double ss = 0;
    for (size_t i = 0; i < dst.size(); ++i) {
      const cv::Point2f d = mapped[i] - dst[i];
      ss += d.dot(d);
    }
    return std::sqrt(ss / dst.size());
  };
  int corners = 0;
  const double own = homography_rms(
      "aprilgrid:8x5:31.5:1:first=1:order=columns:origin=top-left", &corners);
  // Turned tags put every corner one position round: no plane fits.
  int turned_corners = 0;
  const double turned = homography_rms(
      "aprilgrid:8x5:31.5:1:first=1:order=columns:origin=top-left:"
      "rotation=180",
      &turned_corners);
  EXPECT_GT(turned, 10 * own);
  RecordProperty("own_layout_rms_px", std::to_string(own));
  RecordProperty("turned_rms_px", std::to_string(turned));
  EXPECT_GE(corners, 4 * 36) << "most of the 40 tags detected";
  EXPECT_LT(own, 15.0) << "px RMS of one homography over " << corners;
  int kalibr_corners = 0;
  const double kalibr = homography_rms("aprilgrid:8x5:31.5:1", &kalibr_corners);
  RecordProperty("kalibr_layout_rms_px", std::to_string(kalibr));
  EXPECT_GT(kalibr, 10 * own) << kalibr_corners << " corners";
}

}  // namespace
}  // namespace kincal
