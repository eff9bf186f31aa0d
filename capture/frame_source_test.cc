#include "capture/frame_source.h"

#include <gtest/gtest.h>

#include "data/error.h"

namespace kincal::capture {
namespace {

// The InputError message of parsing `uri` ("" when it parses).
std::string ParseError(const std::string& uri) {
  try {
    ParseSourceUri(uri);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(SourceUriTest, ParsesEachScheme) {
  SourceUri v = ParseSourceUri(
      "v4l2:/dev/video0?width=1280&height=1024&fps=30&format=GREY");
  EXPECT_EQ(v.scheme, "v4l2");
  EXPECT_EQ(v.path, "/dev/video0");
  EXPECT_EQ(v.GetInt("width", 0, 16, 16384), 1280);
  EXPECT_EQ(v.GetInt("height", 0, 16, 16384), 1024);
  EXPECT_DOUBLE_EQ(v.GetDouble("fps", 0, 0.1, 1000), 30.0);
  EXPECT_EQ(v.GetString("format", "YUYV"), "GREY");
  EXPECT_EQ(v.GetInt("buffers", 4, 2, 32), 4);  // default

  SourceUri a = ParseSourceUri(
      "aravis:Basler-acA1300-21234567?exposure_us=5000&gain=2.5");
  EXPECT_EQ(a.scheme, "aravis");
  EXPECT_EQ(a.path, "Basler-acA1300-21234567");
  EXPECT_DOUBLE_EQ(a.GetDouble("exposure_us", 0, 1, 1e7), 5000.0);
  EXPECT_DOUBLE_EQ(a.GetDouble("gain", 0, 0, 100), 2.5);

  SourceUri f = ParseSourceUri("folder:/data/left*.png?fps=15");
  EXPECT_EQ(f.path, "/data/left*.png");
  EXPECT_DOUBLE_EQ(f.GetDouble("fps", 30, 0.001, 1e6), 15.0);

  SourceUri m = ParseSourceUri("video:/data/run 1.mp4");
  EXPECT_EQ(m.scheme, "video");
  EXPECT_EQ(m.path, "/data/run 1.mp4");
  EXPECT_TRUE(m.params.empty());
}

TEST(SourceUriTest, QuestionMarkInAFolderGlobIsAWildcard) {
  SourceUri f = ParseSourceUri("folder:/data/img?.png");
  EXPECT_EQ(f.path, "/data/img?.png");
  EXPECT_TRUE(f.params.empty());
  SourceUri g = ParseSourceUri("folder:/data/im?/l??.png?fps=2");
  EXPECT_EQ(g.path, "/data/im?/l??.png");
  EXPECT_EQ(g.params.at("fps"), "2");
}

TEST(SourceUriTest, RejectsBadUrisWithClearMessages) {
  EXPECT_NE(ParseError("/dev/video0").find("expected scheme:path"),
            std::string::npos);
  EXPECT_NE(ParseError("usb:/dev/video0").find("unknown scheme 'usb'"),
            std::string::npos);
  EXPECT_NE(ParseError("v4l2:").find("expected a path"), std::string::npos);
  EXPECT_NE(ParseError("v4l2:video0").find("absolute device path"),
            std::string::npos);
  EXPECT_NE(ParseError("aravis:").find("camera id"), std::string::npos);
  EXPECT_NE(ParseError("v4l2:/dev/video0?widht=640&height=480")
                .find("unknown setting 'widht'"),
            std::string::npos);
  EXPECT_NE(
      ParseError("v4l2:/dev/video0?width=640").find("both width and height"),
      std::string::npos);
  EXPECT_NE(ParseError("v4l2:/dev/video0?format=RGB3")
                .find("GREY, YUYV, MJPG or an 8-bit Bayer"),
            std::string::npos);
  // bayer=raw keeps a Bayer format's mosaic: a gray or YUYV format has none.
  EXPECT_NE(ParseError("v4l2:/dev/video0?format=YUYV&bayer=raw")
                .find("bayer=raw needs a Bayer format"),
            std::string::npos);
  EXPECT_NE(ParseError("aravis:cam?format=Mono8&bayer=raw")
                .find("bayer=raw needs a Bayer format"),
            std::string::npos);
  EXPECT_NE(ParseError("aravis:cam?bayer=yes").find("expected raw"),
            std::string::npos);
  EXPECT_NE(ParseError("folder:/d?mosaic=RGB").find("RGGB, GRBG, GBRG or BGGR"),
            std::string::npos);
  EXPECT_NE(ParseError("video:/a.mp4?mosaic=RGGB").find("unknown setting"),
            std::string::npos);
  EXPECT_NO_THROW(ParseSourceUri("v4l2:/dev/video0?format=BA81&bayer=raw"));
  EXPECT_NO_THROW(ParseSourceUri("aravis:cam?format=BayerRG16&bayer=raw"));
  EXPECT_NO_THROW(ParseSourceUri("aravis:cam?bayer=raw"));  // checked at Open
  EXPECT_NE(ParseError("v4l2:/dev/video0?fps=abc").find("fps=abc"),
            std::string::npos);
  EXPECT_NE(ParseError("v4l2:/dev/video0?fps=0").find("[0.1, 1000]"),
            std::string::npos);
  EXPECT_NE(ParseError("v4l2:/dev/video0?fps").find("expected key=value"),
            std::string::npos);
  EXPECT_NE(ParseError("v4l2:/dev/video0?fps=30&fps=15").find("twice"),
            std::string::npos);
  EXPECT_NE(ParseError("aravis:cam?format=YUYV").find("Mono8"),
            std::string::npos);
  EXPECT_NE(ParseError("aravis:cam?exposure_us=-5").find("exposure_us=-5"),
            std::string::npos);
  EXPECT_NE(ParseError("video:/a.mp4?fps=3").find("unknown setting 'fps'"),
            std::string::npos);
  // The message names the URI the user typed.
  EXPECT_NE(
      ParseError("v4l2:/dev/video0?fps=abc").find("'v4l2:/dev/video0?fps=abc'"),
      std::string::npos);
  EXPECT_THROW(MakeFrameSource("nonsense"), InputError);
}

}  // namespace
}  // namespace kincal::capture
