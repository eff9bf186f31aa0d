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
