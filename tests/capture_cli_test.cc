// End to end: replay two folders of small synthetic PNGs through
// build/bin/kincal capture into a session, check the session layout, and
// that `kincal track` reads it directly; bad input exits 2 writing nothing.

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "data/atomic_file.h"
#include "data/glob.h"
#include "tests/testing/paths.h"
#include "tests/testing/run.h"

namespace kincal {
namespace {

using testing::RunKincal;
using testing::RunResult;

using testing::Exists;

constexpr int kFrames = 5;
constexpr int kWidth = 40;
constexpr int kHeight = 30;

// Left frame i is uniformly 10*i+1, right frame i 10*i+6, written in a
// shuffled order under names that sort into frame order.
std::string MakeInputs() {
  const std::string dir = testing::MakeTempDir("capture_cli_in");
  for (int i : {3, 0, 4, 1, 2}) {
    char name[64];
    std::snprintf(name, sizeof(name), "/cam_l_%02d.png", i);
    cv::imwrite(dir + name,
                cv::Mat(kHeight, kWidth, CV_8UC1, cv::Scalar(10 * i + 1)));
    std::snprintf(name, sizeof(name), "/cam_r_%02d.png", i);
    cv::imwrite(dir + name,
                cv::Mat(kHeight, kWidth, CV_8UC1, cv::Scalar(10 * i + 6)));
  }
  return dir;
}

TEST(CaptureCli, ReplaysFoldersIntoASessionThatTrackReads) {
  const std::string in = MakeInputs();
  const std::string work = testing::MakeTempDir("capture_cli");
  const std::string out = work + "/session";
  const RunResult r = RunKincal("capture --left 'folder:" + in +
                                "/cam_l_*.png' --right 'folder:" + in +
                                "/cam_r_*.png' --out " + out + " --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["frames"], kFrames);
  EXPECT_EQ(j["pairing"], "lockstep");
  EXPECT_EQ(j["stop_reason"], "end_of_stream");
  EXPECT_EQ(j["complete"], true);
  EXPECT_NE(j["command"].get<std::string>().find("kincal capture"),
            std::string::npos);

  // left/*.png and right/*.png sort into the same frame order and pair.
  const auto left = GlobSorted(out + "/left/*.png");
  const auto right = GlobSorted(out + "/right/*.png");
  ASSERT_EQ(left.size(), static_cast<size_t>(kFrames));
  ASSERT_EQ(right.size(), static_cast<size_t>(kFrames));
  for (int i = 0; i < kFrames; ++i) {
    const cv::Mat l = cv::imread(left[i], cv::IMREAD_UNCHANGED);
    const cv::Mat rr = cv::imread(right[i], cv::IMREAD_UNCHANGED);
    ASSERT_FALSE(l.empty());
    ASSERT_FALSE(rr.empty());
    EXPECT_EQ(l.at<uint8_t>(5, 5), 10 * i + 1) << left[i];
    EXPECT_EQ(rr.at<uint8_t>(5, 5), 10 * i + 6) << right[i];
    EXPECT_EQ(left[i].substr(left[i].size() - 10),
              right[i].substr(right[i].size() - 10));
  }

  // frames.csv: provenance, header, one row per pair in order.
  std::istringstream csv(ReadFile(out + "/frames.csv"));
  std::string line;
  std::getline(csv, line);
  EXPECT_EQ(line.rfind("# kincal capture", 0), 0u) << line;
  std::getline(csv, line);
  EXPECT_EQ(line.rfind("frame,t_left,t_right", 0), 0u) << line;
  int rows = 0;
  while (std::getline(csv, line)) {
    EXPECT_EQ(line.rfind(std::to_string(rows) + ",", 0), 0u) << line;
    ++rows;
  }
  EXPECT_EQ(rows, kFrames);
  const std::string yaml = ReadFile(out + "/session.yaml");
  EXPECT_NE(yaml.find("status: complete"), std::string::npos) << yaml;
  EXPECT_NE(yaml.find("cam_l_*.png"), std::string::npos);
  EXPECT_FALSE(Exists(out + "/frames.csv.part"));

  // `kincal track` reads the session directly (no tags in these images:
  // every frame is read and paired, none has a tip).
  const std::string rig = work + "/rig.yaml";
  std::ostringstream rig_text;
  rig_text << "kincal_rig: 1\ncameras:\n";
  for (const char* name : {"left", "right"}) {
    rig_text << "  - name: " << name << "\n    width: " << kWidth
             << "\n    height: " << kHeight
             << "\n    fx: 50.0\n    fy: 50.0\n    cx: 19.5\n    cy: 14.5\n"
                "    distortion: []\n"
                "    cam_from_rig: {R: [1,0,0, 0,1,0, 0,0,1], t: ["
             << (name[0] == 'l' ? 0 : -100) << ", 0, 0]}\n";
  }
  WriteFileAtomic(rig, rig_text.str());
  const std::string target = work + "/target.yaml";
  WriteFileAtomic(target,
                  "kincal_target: 1\nfamily: tag36h11\ntags:\n"
                  "  - {id: 0, size: 30.0, tool_from_tag: {R: [1,0,0, 0,1,0, "
                  "0,0,1], t: [0, 0, 0]}}\ntip_in_tool: [0, 0, 150]\n");
  const RunResult t =
      RunKincal("track --rig " + rig + " --target " + target + " --left '" +
                out + "/left/*.png' --right '" + out + "/right/*.png' --out " +
                work + "/points.csv --quiet --json");
  ASSERT_EQ(t.exit_code, 0) << t.err;
  const auto tj = nlohmann::json::parse(t.out);
  EXPECT_EQ(tj["frames"], kFrames);
  EXPECT_EQ(tj["found"], 0);
}

TEST(CaptureCli, FramesLimitStopsEarly) {
  const std::string in = MakeInputs();
  const std::string work = testing::MakeTempDir("capture_cli_n");
  const RunResult r = RunKincal(
      "capture --left 'folder:" + in + "/cam_l_*.png' --right 'folder:" + in +
      "/cam_r_*.png' --out " + work + "/s --frames 3 --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(nlohmann::json::parse(r.out)["stop_reason"], "frames");
  EXPECT_EQ(GlobSorted(work + "/s/left/*.png").size(), 3u);
  EXPECT_EQ(GlobSorted(work + "/s/right/*.png").size(), 3u);
}

TEST(CaptureCli, UnequalReplayLengthsRecordOnlyPairs) {
  const std::string in = MakeInputs();
  ASSERT_EQ(std::remove((in + "/cam_r_04.png").c_str()), 0);
  const std::string work = testing::MakeTempDir("capture_cli_len");
  const RunResult r = RunKincal("capture --left 'folder:" + in +
                                "/cam_l_*.png' --right 'folder:" + in +
                                "/cam_r_*.png' --out " + work + "/s --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["frames"], kFrames - 1);
  EXPECT_EQ(j["length_mismatch"], true);
  EXPECT_NE(r.err.find("different lengths"), std::string::npos);
  EXPECT_EQ(GlobSorted(work + "/s/left/*.png").size(),
            GlobSorted(work + "/s/right/*.png").size());
}

// Bad input: exit 2, a clear message, and no session folder.
void ExpectBadInput(const std::string& args, const std::string& message) {
  const std::string work = testing::MakeTempDir("capture_cli_bad");
  const RunResult r = RunKincal("capture " + args + " --out " + work + "/s");
  EXPECT_EQ(r.exit_code, 2) << args << "\n" << r.err;
  EXPECT_NE(r.err.find(message), std::string::npos) << r.err;
  EXPECT_TRUE(r.out.empty()) << r.out;
  EXPECT_FALSE(Exists(work + "/s")) << args;
}

TEST(CaptureCli, BadInputExits2AndWritesNothing) {
  const std::string in = MakeInputs();
  const std::string l = "'folder:" + in + "/cam_l_*.png'";
  const std::string r = "'folder:" + in + "/cam_r_*.png'";
  ExpectBadInput("--left usb:/dev/video0 --right " + r, "unknown scheme 'usb'");
  ExpectBadInput("--left " + l + " --right 'v4l2:/dev/video0?fps=fast'",
                 "fps=fast");
  ExpectBadInput("--left " + l + " --right 'v4l2:/dev/video0?widht=640'",
                 "unknown setting 'widht'");
  ExpectBadInput("--left " + l + " --right 'folder:/nonexistent/*.png'",
                 "no file matches");
  ExpectBadInput("--left " + l + " --right " + l, "same source");
  ExpectBadInput("--left " + l + " --right v4l2:/dev/video0",
                 "cannot pair a camera with a recording");
  ExpectBadInput("--left " + l, "required");
}

TEST(CaptureCli, NeverOverwritesASession) {
  const std::string in = MakeInputs();
  const std::string work = testing::MakeTempDir("capture_cli_over");
  const std::string args = "capture --left 'folder:" + in +
                           "/cam_l_*.png' --right 'folder:" + in +
                           "/cam_r_*.png' --out " + work + "/s --frames 2";
  ASSERT_EQ(RunKincal(args).exit_code, 0);
  const std::string before = ReadFile(work + "/s/frames.csv");
  const RunResult again = RunKincal(args);
  EXPECT_EQ(again.exit_code, 2);
  EXPECT_NE(again.err.find("not empty"), std::string::npos) << again.err;
  EXPECT_EQ(ReadFile(work + "/s/frames.csv"), before);
}

TEST(CaptureCli, MissingCameraFailsWithExit1AndNoSession) {
  const std::string work = testing::MakeTempDir("capture_cli_cam");
  const RunResult r = RunKincal(
      "capture --left v4l2:/dev/video97 --right v4l2:/dev/video98 --out " +
      work + "/s --frames 1");
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find("/dev/video97"), std::string::npos) << r.err;
  EXPECT_FALSE(Exists(work + "/s"));
}

TEST(CaptureCli, ListPrintsCameraArrays) {
  const std::string work = testing::MakeTempDir("capture_cli_list");
  const RunResult r = RunKincal("capture --list --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_TRUE(j["v4l2"].is_array());
  EXPECT_TRUE(j["aravis"].is_array());
  for (const auto& cam : j["v4l2"]) {
    EXPECT_EQ(cam["uri"].get<std::string>().rfind("v4l2:", 0), 0u);
  }
}

}  // namespace
}  // namespace kincal
