// bin/kincal is the front end without image libraries; bin/kincal-vision has
// every command (app/front_end.h). These tests hold the split: the front end
// loads no image codec / video / camera library, and the two binaries are one
// program to the user (same --help, same exit codes, image commands run).

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "tests/testing/paths.h"
#include "tests/testing/run.h"

namespace kincal {
namespace {

using testing::KincalBinary;
using testing::RunKincal;
using testing::RunShell;

const std::string& VisionBinary() {
  static const std::string path = KincalBinary() + "-vision";
  return path;
}

// Text with every occurrence of `from` replaced by `to`.
std::string Replace(std::string text, const std::string& from,
                    const std::string& to) {
  for (size_t at = text.find(from); at != std::string::npos;
       at = text.find(from, at + to.size())) {
    text.replace(at, from.size(), to);
  }
  return text;
}

// The libraries that make start-up slow (OpenCV's image codecs and video I/O
// and what they load: GDAL, GStreamer, ...; the camera SDKs).
const std::vector<std::string> kImageLibraries = {"libopencv_imgcodecs",
                                                  "libopencv_videoio",
                                                  "libopencv_highgui",
                                                  "libgdal",
                                                  "libgst",
                                                  "libaravis",
                                                  "libv4l2"};

TEST(StartupCli, FrontEndLoadsNoImageLibrary) {
  const testing::RunResult front = RunShell("ldd " + KincalBinary());
  ASSERT_EQ(front.exit_code, 0) << front.err;
  for (const std::string& lib : kImageLibraries) {
    EXPECT_EQ(front.out.find(lib), std::string::npos)
        << "bin/kincal loads " << lib
        << ": a command that reads or writes images belongs in "
           "KINCAL_IMAGE_COMMANDS (app/CMakeLists.txt)\n"
        << front.out;
  }
  // The check can fail: kincal-vision does load them.
  const testing::RunResult vision = RunShell("ldd " + VisionBinary());
  ASSERT_EQ(vision.exit_code, 0) << vision.err;
  EXPECT_NE(vision.out.find("libopencv_imgcodecs"), std::string::npos);
}

TEST(StartupCli, OneHelpForBothBinaries) {
  const testing::RunResult front = RunKincal("--help");
  const testing::RunResult vision = RunShell(VisionBinary() + " --help");
  ASSERT_EQ(front.exit_code, 0);
  ASSERT_EQ(vision.exit_code, 0);
  EXPECT_EQ(front.out, Replace(vision.out, VisionBinary(), KincalBinary()));
  for (const std::string command :
       {"camcal", "track", "capture", "bundle", "simulate", "calibrate"}) {
    const testing::RunResult a = RunKincal(command + " --help");
    const testing::RunResult b =
        RunShell(VisionBinary() + " " + command + " --help");
    EXPECT_EQ(a.exit_code, 0) << command;
    EXPECT_NE(a.out.find("--"), std::string::npos) << command << ": no options";
    EXPECT_EQ(a.out, Replace(b.out, VisionBinary(), KincalBinary())) << command;
  }
}

TEST(StartupCli, ImageCommandsKeepTheirErrorsAndExitCodes) {
  const testing::RunResult r = RunKincal("track --target t.yaml --out p.csv");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("--rig is required"), std::string::npos) << r.err;
  const testing::RunResult bad = RunKincal("bundle --no-such-option");
  EXPECT_EQ(bad.exit_code, 2);
  const testing::RunResult version = RunKincal("--version");
  EXPECT_EQ(version.exit_code, 0);
  EXPECT_NE(version.out.find("kincal "), std::string::npos) << version.out;
}

TEST(StartupCli, MissingVisionBinaryIsAClearFailure) {
  const testing::RunResult r =
      RunShell("KINCAL_VISION=/nonexistent/kincal-vision " + KincalBinary() +
               " camcal --help");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("/nonexistent/kincal-vision"), std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("incomplete installation"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace kincal
