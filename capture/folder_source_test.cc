// Tests of the image-folder source (capture/folder_source.cc).
#include <gtest/gtest.h>

#include <cstdio>
#include <opencv2/imgcodecs.hpp>

#include "capture/frame_source.h"
#include "data/error.h"
#include "tests/testing/paths.h"

namespace kincal::capture {
namespace {

using ::kincal::testing::MakeTempDir;

// Writes n small gray PNGs whose pixel value encodes their index.
std::string WriteImages(const std::string& dir, const std::string& prefix,
                        const std::vector<int>& indices) {
  for (int i : indices) {
    char name[64];
    std::snprintf(name, sizeof(name), "%s%03d.png", prefix.c_str(), i);
    cv::imwrite(dir + "/" + name, cv::Mat(8, 12, CV_8UC1, cv::Scalar(10 * i)));
  }
  return dir;
}

TEST(FolderSourceTest, ReplaysImagesSortedByNameThenEnds) {
  const std::string dir = MakeTempDir("folder_src");
  WriteImages(dir, "left", {3, 0, 2, 1});
  WriteImages(dir, "right", {0});
  auto source = MakeFrameSource("folder:" + dir + "/left*.png?fps=10");
  EXPECT_FALSE(source->IsLive());
  EXPECT_EQ(source->time_base(), TimeBase::kMedia);
  ASSERT_TRUE(source->Open().ok());
  for (int i = 0; i < 4; ++i) {
    Frame f;
    ASSERT_TRUE(source->Grab(&f).ok());
    EXPECT_EQ(f.sequence, i);
    EXPECT_DOUBLE_EQ(f.timestamp_s, i / 10.0);
    ASSERT_EQ(f.image.type(), CV_8UC1);
    EXPECT_EQ(f.image.at<uint8_t>(0, 0), 10 * i);  // left000 before left001
  }
  Frame f;
  EXPECT_EQ(source->Grab(&f).kind(), Status::Kind::kEndOfStream);
  EXPECT_NE(source->Describe().find("4 images"), std::string::npos);
}

TEST(FolderSourceTest, DeclaredMosaicIsReportedAndColourImagesRefused) {
  const std::string dir = MakeTempDir("folder_mosaic");
  WriteImages(dir, "raw", {0, 1});
  auto source = MakeFrameSource("folder:" + dir + "/raw*.png?mosaic=BGGR");
  EXPECT_EQ(source->mosaic(), "BGGR");
  ASSERT_TRUE(source->Open().ok());
  Frame f;
  ASSERT_TRUE(source->Grab(&f).ok());
  EXPECT_EQ(f.image.type(), CV_8UC1);
  EXPECT_NE(source->Describe().find("raw BGGR mosaics"), std::string::npos);

  cv::imwrite(dir + "/colour000.png",
              cv::Mat(8, 12, CV_8UC3, cv::Scalar(1, 2, 3)));
  auto colour = MakeFrameSource("folder:" + dir + "/colour*.png?mosaic=RGGB");
  ASSERT_TRUE(colour->Open().ok());
  const Status s = colour->Grab(&f);
  EXPECT_EQ(s.kind(), Status::Kind::kIoError);
  EXPECT_NE(s.message().find("a raw mosaic is one gray channel"),
            std::string::npos);
}

TEST(FolderSourceTest, FolderPathTakesAllImagesAndEmptyGlobIsNotFound) {
  const std::string dir = MakeTempDir("folder_all");
  WriteImages(dir, "a", {0, 1});
  {
    FILE* f = std::fopen((dir + "/notes.txt").c_str(), "w");
    ASSERT_NE(f, nullptr);
    std::fputs("not an image", f);
    std::fclose(f);
  }
  auto all = MakeFrameSource("folder:" + dir);
  ASSERT_TRUE(all->Open().ok());
  int n = 0;
  Frame frame;
  while (all->Grab(&frame).ok()) ++n;
  EXPECT_EQ(n, 2);

  auto none = MakeFrameSource("folder:" + dir + "/zzz*.png");
  const Status s = none->Open();
  EXPECT_EQ(s.kind(), Status::Kind::kNotFound);
  EXPECT_NE(s.message().find("no file matches"), std::string::npos);
}

TEST(FolderSourceTest, UnreadableImageIsIoError) {
  const std::string dir = MakeTempDir("folder_bad");
  FILE* f = std::fopen((dir + "/000.png").c_str(), "w");
  ASSERT_NE(f, nullptr);
  std::fputs("truncated", f);
  std::fclose(f);
  auto source = MakeFrameSource("folder:" + dir + "/*.png");
  ASSERT_TRUE(source->Open().ok());
  Frame frame;
  EXPECT_EQ(source->Grab(&frame).kind(), Status::Kind::kIoError);
}

}  // namespace
}  // namespace kincal::capture
