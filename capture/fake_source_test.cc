// Tests of the synthetic live camera (capture/fake_source.cc).

#include <gtest/gtest.h>

#include <cmath>

#include "capture/frame_source.h"

namespace kincal::capture {
namespace {

TEST(FakeSourceTest, FramesOnTheFpsGridWithTheRequestedSize) {
  auto source = MakeFrameSource("fake:a?width=96&height=64&fps=100");
  EXPECT_TRUE(source->IsLive());
  EXPECT_EQ(source->time_base(), TimeBase::kHostMonotonic);
  ASSERT_TRUE(source->Open().ok());
  std::vector<Frame> frames(3);
  for (Frame& f : frames) ASSERT_TRUE(source->Grab(&f).ok());
  for (size_t i = 0; i < frames.size(); ++i) {
    EXPECT_EQ(frames[i].sequence, static_cast<int64_t>(i));
    EXPECT_EQ(frames[i].image.size(), cv::Size(96, 64));
    EXPECT_EQ(frames[i].image.type(), CV_8UC1);
    // Exact multiples of 1/fps (two fake cameras pair like triggered ones).
    const double ticks = frames[i].timestamp_s * 100;
    EXPECT_NEAR(ticks, std::round(ticks), 1e-6);
  }
  EXPECT_NEAR(frames[1].timestamp_s - frames[0].timestamp_s, 0.01, 1e-9);
  EXPECT_NEAR(frames[2].timestamp_s - frames[1].timestamp_s, 0.01, 1e-9);
  // Paced in real time: a frame is not delivered before its time.
  EXPECT_GE(MonotonicSeconds(), frames[2].timestamp_s);
  EXPECT_TRUE(source->Close().ok());
}

TEST(FakeSourceTest, TheBrightBarMovesWithTheFrameNumber) {
  auto source = MakeFrameSource("fake:bar?width=64&height=32&fps=200");
  ASSERT_TRUE(source->Open().ok());
  Frame first, second;
  ASSERT_TRUE(source->Grab(&first).ok());
  ASSERT_TRUE(source->Grab(&second).ok());
  // Frame k has an 8 px bar of 230 starting at column 8 k.
  EXPECT_EQ(first.image.at<uint8_t>(10, 3), 230);
  EXPECT_EQ(second.image.at<uint8_t>(10, 11), 230);
  EXPECT_NE(second.image.at<uint8_t>(10, 3), 230);
}

TEST(FakeSourceTest, MosaicFramesScaleEachPhotositeByItsFilter) {
  auto gray = MakeFrameSource("fake:m?width=64&height=32&fps=200");
  auto raw = MakeFrameSource("fake:m?width=64&height=32&fps=200&mosaic=GRBG");
  EXPECT_EQ(gray->mosaic(), "");
  EXPECT_EQ(raw->mosaic(), "GRBG");
  ASSERT_TRUE(gray->Open().ok());
  ASSERT_TRUE(raw->Open().ok());
  Frame g, r;
  ASSERT_TRUE(gray->Grab(&g).ok());
  ASSERT_TRUE(raw->Grab(&r).ok());
  ASSERT_EQ(r.image.type(), CV_8UC1);
  // GRBG: green at (0, 0) and (1, 1), red at (0, 1), blue at (1, 0).
  for (int y = 20; y < 24; y += 2) {
    for (int x = 20; x < 24; x += 2) {
      EXPECT_EQ(r.image.at<uint8_t>(y, x), g.image.at<uint8_t>(y, x));
      EXPECT_NEAR(r.image.at<uint8_t>(y, x + 1),
                  0.55 * g.image.at<uint8_t>(y, x + 1), 0.51);
      EXPECT_NEAR(r.image.at<uint8_t>(y + 1, x),
                  0.75 * g.image.at<uint8_t>(y + 1, x), 0.51);
    }
  }
  EXPECT_NE(raw->Describe().find("raw GRBG"), std::string::npos);
}

TEST(FakeSourceTest, GrabBeforeOpenIsAnIoError) {
  auto source = MakeFrameSource("fake:closed");
  Frame frame;
  const Status s = source->Grab(&frame);
  EXPECT_EQ(s.kind(), Status::Kind::kIoError);
  EXPECT_NE(s.message().find("not open"), std::string::npos);
  EXPECT_NE(source->Describe().find("640x480"), std::string::npos)
      << source->Describe();
}

}  // namespace
}  // namespace kincal::capture
