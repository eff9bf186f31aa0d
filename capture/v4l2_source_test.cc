// Tests of the V4L2 source (capture/v4l2_source.cc) that need no camera.
#include <gtest/gtest.h>

#include "capture/frame_source.h"
#include "data/error.h"

namespace kincal::capture {
namespace {

TEST(V4l2SourceTest, MissingDeviceIsNotFound) {
  auto source = MakeFrameSource("v4l2:/dev/video97");
  EXPECT_TRUE(source->IsLive());
  const Status s = source->Open();
  EXPECT_EQ(s.kind(), Status::Kind::kNotFound) << s.ToString();
  EXPECT_NE(s.message().find("/dev/video97"), std::string::npos);
  Frame frame;
  EXPECT_FALSE(source->Grab(&frame).ok());  // not open: a status, no crash
  EXPECT_TRUE(source->Close().ok());
}

TEST(V4l2SourceTest, NonVideoDeviceIsUnsupported) {
  auto source = MakeFrameSource("v4l2:/dev/null");
  const Status s = source->Open();
  EXPECT_EQ(s.kind(), Status::Kind::kUnsupported) << s.ToString();
  EXPECT_NE(s.message().find("not a V4L2 device"), std::string::npos);
}

TEST(V4l2SourceTest, ListingWithoutCamerasIsEmptyNotAnError) {
  // This machine has no /dev/video*; on one with cameras each entry must
  // still be a valid URI.
  for (const CameraInfo& c : ListV4l2Devices()) {
    EXPECT_NO_THROW(ParseSourceUri(c.uri)) << c.uri;
  }
}

TEST(V4l2SourceTest, UnknownPixelFormatIsRefusedBeforeOpening) {
  try {
    MakeFrameSource("v4l2:/dev/video0?format=XYZW");
    FAIL() << "format=XYZW accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("expected GREY, YUYV, MJPG"),
              std::string::npos)
        << e.what();
  }
}

TEST(V4l2SourceTest, DescribeNamesTheDevice) {
  auto source = MakeFrameSource("v4l2:/dev/video97?width=320&height=240");
  EXPECT_NE(source->Describe().find("/dev/video97"), std::string::npos)
      << source->Describe();
  EXPECT_EQ(source->time_base(), TimeBase::kHostMonotonic);
}

}  // namespace
}  // namespace kincal::capture
