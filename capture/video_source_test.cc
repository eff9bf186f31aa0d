// Tests of the video-file source (capture/video_source.cc).
#include <gtest/gtest.h>

#include <cstdio>
#include <opencv2/videoio.hpp>

#include "capture/frame_source.h"
#include "data/error.h"
#include "tests/testing/paths.h"

namespace kincal::capture {
namespace {

using ::kincal::testing::MakeTempDir;

TEST(VideoSourceTest, ReplaysAVideoFileFrameByFrame) {
  const std::string path = MakeTempDir("video_src") + "/clip.avi";
  {
    cv::VideoWriter writer(path, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'),
                           25.0, cv::Size(64, 48), true);
    ASSERT_TRUE(writer.isOpened());
    for (int i = 0; i < 5; ++i) {
      writer.write(
          cv::Mat(48, 64, CV_8UC3, cv::Scalar(40 * i, 40 * i, 40 * i)));
    }
  }
  auto source = MakeFrameSource("video:" + path);
  ASSERT_TRUE(source->Open().ok()) << source->Describe();
  int n = 0;
  Frame f;
  Status s;
  while ((s = source->Grab(&f)).ok()) {
    EXPECT_EQ(f.sequence, n);
    EXPECT_NEAR(f.timestamp_s, n / 25.0, 1e-9);
    EXPECT_EQ(f.image.size(), cv::Size(64, 48));
    EXPECT_NEAR(f.image.at<cv::Vec3b>(24, 32)[0], 40 * n, 6);  // JPEG loss
    ++n;
  }
  EXPECT_EQ(s.kind(), Status::Kind::kEndOfStream);
  EXPECT_EQ(n, 5);
}

TEST(VideoSourceTest, MissingOrUndecodableFile) {
  auto missing = MakeFrameSource("video:/nonexistent/clip.mp4");
  EXPECT_EQ(missing->Open().kind(), Status::Kind::kNotFound);
  const std::string path = MakeTempDir("video_bad") + "/clip.mp4";
  FILE* f = std::fopen(path.c_str(), "w");
  ASSERT_NE(f, nullptr);
  std::fputs("this is not a video", f);
  std::fclose(f);
  auto bad = MakeFrameSource("video:" + path);
  EXPECT_EQ(bad->Open().kind(), Status::Kind::kUnsupported);
}

}  // namespace
}  // namespace kincal::capture
