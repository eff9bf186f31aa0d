#include "vision/stereo_images.h"

#include <gtest/gtest.h>

#include <atomic>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>

#include "data/error.h"

namespace kincal {
namespace {

std::string TempDir() {
  const std::string dir =
      (std::filesystem::temp_directory_path() /
       ("kincal_stereo_images_" +
        std::to_string(::testing::UnitTest::GetInstance()->random_seed())))
          .string();
  std::filesystem::create_directories(dir);
  return dir;
}

CameraIntrinsics Camera(int width, int height) {
  CameraIntrinsics c;
  c.name = "left";
  c.width = width;
  c.height = height;
  return c;
}

TEST(ReadCameraImage, ReadsAGrayImageOfTheCamerasSize) {
  const std::string path = TempDir() + "/a.png";
  cv::Mat img(24, 32, CV_8UC1, cv::Scalar(7));
  img.at<uchar>(3, 5) = 200;
  ASSERT_TRUE(cv::imwrite(path, img));
  const cv::Mat read = ReadCameraImage(path, Camera(32, 24));
  ASSERT_EQ(read.type(), CV_8UC1);
  EXPECT_EQ(read.at<uchar>(3, 5), 200);
  EXPECT_EQ(read.at<uchar>(0, 0), 7);
}

TEST(ReadCameraImage, WrongSizeOrMissingFileIsBadInput) {
  const std::string path = TempDir() + "/b.png";
  ASSERT_TRUE(cv::imwrite(path, cv::Mat(24, 32, CV_8UC1, cv::Scalar(0))));
  try {
    ReadCameraImage(path, Camera(64, 48));
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("32x24"), std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("64x48"), std::string::npos)
        << e.what();
  }
  EXPECT_THROW(ReadCameraImage(TempDir() + "/missing.png", Camera(32, 24)),
               InputError);
}

TEST(ForBothCameras, RunsCameraZeroAndOne) {
  std::atomic<int> seen{0};
  ForBothCameras([&](int c) { seen |= 1 << c; });
  EXPECT_EQ(seen.load(), 3);
}

TEST(ForBothCameras, PassesOnAnError) {
  EXPECT_THROW(ForBothCameras([](int c) {
                 if (c == 1) throw InputError("camera 1 failed");
               }),
               InputError);
}

}  // namespace
}  // namespace kincal
