// Tests of the fast lossless PNG encoder (capture/png_encode.cc).

#include "capture/png_encode.h"

#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>

namespace kincal::capture {
namespace {

// A camera-like image: a gradient with a little noise.
cv::Mat CameraImage(int type) {
  cv::Mat image(48, 64, type);
  cv::RNG rng(7);
  rng.fill(image, cv::RNG::UNIFORM, 0, 8);
  for (int r = 0; r < image.rows; ++r) {
    for (int c = 0; c < image.cols * image.channels(); ++c) {
      image.ptr<uint8_t>(r)[c] += static_cast<uint8_t>(2 * r + c);
    }
  }
  return image;
}

cv::Mat Decode(const std::vector<uint8_t>& png) {
  return cv::imdecode(png, cv::IMREAD_UNCHANGED);
}

TEST(PngEncodeTest, GrayAndBgrAreLosslessAtEveryLevel) {
  for (int type : {CV_8UC1, CV_8UC3}) {
    const cv::Mat image = CameraImage(type);
    for (int level : {0, 1, 6, 9}) {
      std::vector<uint8_t> png;
      std::string error;
      ASSERT_TRUE(EncodePng(image, level, &png, &error)) << error;
      const cv::Mat back = Decode(png);
      ASSERT_EQ(back.type(), type) << "level " << level;
      EXPECT_EQ(cv::norm(back, image, cv::NORM_INF), 0) << "level " << level;
    }
  }
}

TEST(PngEncodeTest, LevelZeroStoresAndHigherLevelsCompress) {
  const cv::Mat image = CameraImage(CV_8UC1);
  std::vector<uint8_t> stored, compressed;
  std::string error;
  ASSERT_TRUE(EncodePng(image, 0, &stored, &error)) << error;
  ASSERT_TRUE(EncodePng(image, 9, &compressed, &error)) << error;
  EXPECT_GE(stored.size(), image.total());  // the raw size and headers
  EXPECT_LT(compressed.size(), stored.size());
}

TEST(PngEncodeTest, SixteenBitGoesThroughOpenCvAndStaysLossless) {
  cv::Mat image(16, 16, CV_16UC1);
  cv::randu(image, 0, 65535);
  std::vector<uint8_t> png;
  std::string error;
  ASSERT_TRUE(EncodePng(image, 1, &png, &error)) << error;
  const cv::Mat back = Decode(png);
  ASSERT_EQ(back.type(), CV_16UC1);
  EXPECT_EQ(cv::norm(back, image, cv::NORM_INF), 0);
}

TEST(PngEncodeTest, BadInputIsAnErrorNotAnException) {
  std::vector<uint8_t> png;
  std::string error;
  EXPECT_FALSE(EncodePng(cv::Mat(), 1, &png, &error));
  EXPECT_EQ(error, "empty image");
  EXPECT_FALSE(EncodePng(CameraImage(CV_8UC1), 10, &png, &error));
  EXPECT_EQ(error, "PNG compression level must be 0..9");
}

}  // namespace
}  // namespace kincal::capture
