// Runs the Aravis source against Aravis' built-in simulated camera
// ("Fake_1"): the real Aravis stream, buffer and pixel-format code paths,
// without hardware. Skipped when kincal was built without Aravis.

#include <gtest/gtest.h>
#include <time.h>

#include "capture/frame_source.h"

namespace kincal::capture {
namespace {

double MonotonicNow() {
  timespec ts{};
  ::clock_gettime(CLOCK_MONOTONIC, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

TEST(AravisSourceTest, StreamsFromTheSimulatedCamera) {
  if (!HaveAravis()) GTEST_SKIP() << "built without Aravis";
  auto source = MakeFrameSource(
      "aravis:Fake_1?fps=50&exposure_us=2000&gain=1&format=Mono8");
  const Status open = source->Open();
  ASSERT_TRUE(open.ok()) << open.ToString();
  EXPECT_NE(source->Describe().find("Mono8"), std::string::npos);
  Frame previous;
  for (int i = 0; i < 3; ++i) {
    Frame f;
    const Status s = source->Grab(&f);
    ASSERT_TRUE(s.ok()) << s.ToString();
    EXPECT_EQ(f.image.type(), CV_8UC1);
    EXPECT_GT(f.image.cols, 0);
    // Host receive time, moved to CLOCK_MONOTONIC: just now.
    EXPECT_NEAR(f.timestamp_s, MonotonicNow(), 1.0);
    if (i > 0) {
      EXPECT_GT(f.sequence, previous.sequence);
      EXPECT_GT(f.timestamp_s, previous.timestamp_s);
    }
    previous = f;
  }
  EXPECT_TRUE(source->Close().ok());
}

TEST(AravisSourceTest, Mono16FromTheSimulatedCameraBecomes8Bit) {
  if (!HaveAravis()) GTEST_SKIP() << "built without Aravis";
  auto source = MakeFrameSource("aravis:Fake_1?format=Mono16");
  ASSERT_TRUE(source->Open().ok());
  Frame f;
  const Status s = source->Grab(&f);
  ASSERT_TRUE(s.ok()) << s.ToString();
  EXPECT_EQ(f.image.type(), CV_8UC1);
}

TEST(AravisSourceTest, BayerFromTheSimulatedCameraKeptRawWhenAsked) {
  if (!HaveAravis()) GTEST_SKIP() << "built without Aravis";
  auto demosaiced = MakeFrameSource("aravis:Fake_1?format=BayerGR8");
  const Status open = demosaiced->Open();
  if (!open.ok()) GTEST_SKIP() << "simulated camera: " << open.ToString();
  Frame f;
  ASSERT_TRUE(demosaiced->Grab(&f).ok());
  EXPECT_EQ(f.image.type(), CV_8UC3);
  EXPECT_EQ(demosaiced->mosaic(), "");
  ASSERT_TRUE(demosaiced->Close().ok());

  auto raw = MakeFrameSource("aravis:Fake_1?format=BayerGR8&bayer=raw");
  ASSERT_TRUE(raw->Open().ok());
  ASSERT_TRUE(raw->Grab(&f).ok());
  EXPECT_EQ(f.image.type(), CV_8UC1);
  EXPECT_EQ(raw->mosaic(), "GRBG");
  EXPECT_NE(raw->Describe().find("raw mosaic"), std::string::npos);
}

TEST(AravisSourceTest, UnknownCameraIsNotFound) {
  if (!HaveAravis()) GTEST_SKIP() << "built without Aravis";
  auto source = MakeFrameSource("aravis:NoSuchVendor-0000");
  const Status s = source->Open();
  EXPECT_EQ(s.kind(), Status::Kind::kNotFound) << s.ToString();
  EXPECT_NE(s.message().find("NoSuchVendor-0000"), std::string::npos);
  std::vector<CameraInfo> cameras;
  EXPECT_TRUE(ListAravisCameras(&cameras).ok());
  for (const CameraInfo& c : cameras) EXPECT_NO_THROW(ParseSourceUri(c.uri));
}

}  // namespace
}  // namespace kincal::capture
