#include "capture/frame_source.h"

#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include "data/error.h"
#include "tests/testing/paths.h"

namespace kincal::capture {
namespace {

using ::kincal::testing::MakeTempDir;

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
  EXPECT_NE(
      ParseError("v4l2:/dev/video0?format=RGB3").find("GREY, YUYV or MJPG"),
      std::string::npos);
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
