#include "capture/recorder.h"

#include <gtest/gtest.h>
#include <unistd.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cstdio>
#include <opencv2/imgcodecs.hpp>

#include "data/atomic_file.h"
#include "data/csv.h"
#include "data/glob.h"
#include "data/provenance.h"
#include "tests/testing/paths.h"

namespace kincal::capture {
namespace {

using ::kincal::testing::Exists;
using ::kincal::testing::MakeTempDir;

// A pair with distinct random-looking content per frame and side.
StereoFrame Pair(int i) {
  StereoFrame p;
  p.left.image = cv::Mat(24, 32, CV_8UC1);
  cv::randu(p.left.image, 0, 256);
  p.left.image.at<uint8_t>(0, 0) = static_cast<uint8_t>(i);
  p.right.image = cv::Mat(24, 32, CV_8UC3);
  cv::randu(p.right.image, 0, 256);
  p.left.timestamp_s = 100.0 + i / 30.0;
  p.right.timestamp_s = 100.0005 + i / 30.0;
  p.left.sequence = 7 + i;
  p.right.sequence = 9 + i;
  p.index = i;
  return p;
}

SessionInfo Info() {
  SessionInfo info;
  info.left_uri = "folder:/x/left*.png";
  info.right_uri = "folder:/x/right*.png";
  info.left_description = "left cam";
  info.right_description = "right cam";
  info.pairing = "lockstep";
  info.time_base = "media";
  info.settings["frames"] = "3";
  return info;
}

TEST(RecorderTest, WritesASessionThatTrackReadsAndIsLossless) {
  SetCommandLine("kincal capture --test");
  const std::string dir = MakeTempDir("rec") + "/session/a";  // parents made
  SessionInfo info = Info();
  info.joint_names = {"j1", "j2"};
  SessionRecorder rec;
  ASSERT_TRUE(rec.Open(dir, info).ok());
  EXPECT_TRUE(Exists(dir + "/session.yaml"));  // written at start
  EXPECT_EQ(YAML::LoadFile(dir + "/session.yaml")["status"].as<std::string>(),
            "recording");
  std::vector<StereoFrame> pairs;
  for (int i = 0; i < 3; ++i) {
    pairs.push_back(Pair(i));
    ASSERT_TRUE(rec.Write(pairs.back(), {1.5 * i, -20.25}).ok());
  }
  EXPECT_EQ(rec.frames(), 3);
  SessionSummary summary;
  summary.stop_reason = "end_of_stream";
  summary.seconds = 0.5;
  ASSERT_TRUE(rec.Finalize(summary).ok());

  // Images: same names on both sides, sorted = frame order, bit-exact.
  const auto left = GlobSorted(dir + "/left/*.png");
  const auto right = GlobSorted(dir + "/right/*.png");
  ASSERT_EQ(left.size(), 3u);
  ASSERT_EQ(right.size(), 3u);
  EXPECT_EQ(left[0], dir + "/left/000000.png");
  EXPECT_EQ(right[2], dir + "/right/000002.png");
  for (int i = 0; i < 3; ++i) {
    const cv::Mat l = cv::imread(left[i], cv::IMREAD_UNCHANGED);
    const cv::Mat r = cv::imread(right[i], cv::IMREAD_UNCHANGED);
    ASSERT_EQ(l.type(), CV_8UC1);
    ASSERT_EQ(r.type(), CV_8UC3);
    EXPECT_EQ(cv::norm(l, pairs[i].left.image, cv::NORM_INF), 0);
    EXPECT_EQ(cv::norm(r, pairs[i].right.image, cv::NORM_INF), 0);
  }
  EXPECT_TRUE(GlobSorted(dir + "/*/*.part").empty());
  EXPECT_FALSE(Exists(dir + "/frames.csv.part"));

  // frames.csv: provenance comment, header, one row per pair.
  const std::string csv = ReadFile(dir + "/frames.csv");
  EXPECT_EQ(csv.rfind("# kincal capture --test\n", 0), 0u);
  const auto lines = TokenizeCsv(csv, "frames.csv");
  ASSERT_EQ(lines.size(), 4u);
  const std::vector<std::string> header = {
      "frame", "t_left", "t_right", "seq_left", "seq_right", "j1", "j2"};
  for (size_t c = 0; c < header.size(); ++c) {
    EXPECT_EQ(lines[0].fields[c].text, header[c]);
  }
  EXPECT_EQ(lines[3].fields[0].text, "2");
  EXPECT_EQ(lines[3].fields[1].text, "100.066667");
  EXPECT_EQ(lines[3].fields[2].text, "100.067167");
  EXPECT_EQ(lines[3].fields[3].text, "9");
  EXPECT_EQ(lines[3].fields[4].text, "11");
  EXPECT_EQ(lines[3].fields[5].text, "3");
  EXPECT_EQ(lines[3].fields[6].text, "-20.25");

  // session.yaml: how it was made and how it ended.
  const YAML::Node y = YAML::LoadFile(dir + "/session.yaml");
  EXPECT_EQ(y["kincal_session"].as<int>(), 1);
  EXPECT_EQ(y["status"].as<std::string>(), "complete");
  EXPECT_EQ(y["frames"].as<int>(), 3);
  EXPECT_EQ(y["command"].as<std::string>(), "kincal capture --test");
  EXPECT_EQ(y["sources"]["left"]["uri"].as<std::string>(),
            "folder:/x/left*.png");
  EXPECT_EQ(y["pairing"]["mode"].as<std::string>(), "lockstep");
  EXPECT_EQ(y["joints"][1].as<std::string>(), "j2");
  EXPECT_EQ(y["stop_reason"].as<std::string>(), "end_of_stream");
  EXPECT_EQ(y["settings"]["frames"].as<std::string>(), "3");
  EXPECT_EQ(y["started_utc"].as<std::string>().size(), 20u);
}

TEST(RecorderTest, RefusesANonEmptyFolder) {
  const std::string dir = MakeTempDir("rec_full");
  ASSERT_TRUE(WriteBytes(dir + "/keep.txt", "x", 1).ok());
  SessionRecorder rec;
  const Status s = rec.Open(dir, Info());
  EXPECT_EQ(s.kind(), Status::Kind::kIoError);
  EXPECT_NE(s.message().find("not empty"), std::string::npos);
  EXPECT_FALSE(Exists(dir + "/left"));
}

TEST(RecorderTest, DiskFullIsAnIoErrorStatus) {
  // /dev/full fails every write with ENOSPC, as a full disk does.
  const char data[4096] = {};
  const Status s = WriteBytes("/dev/full", data, sizeof(data));
  EXPECT_EQ(s.kind(), Status::Kind::kIoError);
  EXPECT_NE(s.message().find("No space left on device"), std::string::npos)
      << s.message();
}

TEST(RecorderTest, CannotCreateTheSessionFolder) {
  const std::string base = MakeTempDir("rec_nodir");
  ASSERT_TRUE(WriteBytes(base + "/file", "x", 1).ok());
  SessionRecorder rec;
  const Status s = rec.Open(base + "/file/session", Info());
  EXPECT_EQ(s.kind(), Status::Kind::kIoError);
  EXPECT_NE(s.message().find("file"), std::string::npos);
}

TEST(RecorderTest, WriteFailureMidSessionLeavesNoHalfPair) {
  const std::string dir = MakeTempDir("rec_mid") + "/s";
  SessionRecorder rec;
  ASSERT_TRUE(rec.Open(dir, Info()).ok());
  ASSERT_TRUE(rec.Write(Pair(0)).ok());
  // The right folder disappears (unmounted, deleted): the next right image
  // cannot be written; the left image of that pair must not stay.
  ASSERT_EQ(
      std::system(
          ("rm -rf '" + dir + "/right' && touch '" + dir + "/right'").c_str()),
      0);
  const Status s = rec.Write(Pair(1));
  EXPECT_EQ(s.kind(), Status::Kind::kIoError);
  EXPECT_EQ(rec.frames(), 1);
  EXPECT_EQ(GlobSorted(dir + "/left/*.png").size(), 1u);
  EXPECT_TRUE(GlobSorted(dir + "/left/*.part").empty());
  SessionSummary summary;
  summary.complete = false;
  summary.stop_reason = "write failed";
  ASSERT_TRUE(rec.Finalize(summary).ok());
  EXPECT_EQ(YAML::LoadFile(dir + "/session.yaml")["status"].as<std::string>(),
            "failed");
  EXPECT_EQ(TokenizeCsv(ReadFile(dir + "/frames.csv"), "f").size(), 2u);
}

TEST(RecorderTest, JointCountAndNamesAreChecked) {
  SessionInfo info = Info();
  info.joint_names = {"j1", "t_left"};
  SessionRecorder bad;
  EXPECT_EQ(bad.Open(MakeTempDir("rec_j") + "/s", info).kind(),
            Status::Kind::kUnsupported);
  info.joint_names = {"j1"};
  SessionRecorder rec;
  ASSERT_TRUE(rec.Open(MakeTempDir("rec_j2") + "/s", info).ok());
  EXPECT_EQ(rec.Write(Pair(0), {}).kind(), Status::Kind::kUnsupported);
  EXPECT_TRUE(rec.Write(Pair(0), {3.0}).ok());
}

TEST(RecorderTest, FileNamesSortInFrameOrder) {
  EXPECT_EQ(SessionRecorder::FrameFileName(0), "000000.png");
  EXPECT_EQ(SessionRecorder::FrameFileName(42), "000042.png");
  EXPECT_LT(SessionRecorder::FrameFileName(9999),
            SessionRecorder::FrameFileName(10000));
  EXPECT_EQ(SessionRecorder::FrameFileName(SessionRecorder::kMaxFrames - 1),
            "999999.png");
}

}  // namespace
}  // namespace kincal::capture
