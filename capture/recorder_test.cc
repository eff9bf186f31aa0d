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

// A set of `cameras` frames with distinct random-looking content per frame
// and camera: camera 0 gray, the others BGR; camera c's frame i at
// 100 + i / 30 + 0.0005 c s, sequence 7 + 2 c + i.
FrameSet Set(int i, int cameras = 2) {
  FrameSet set;
  set.frames.resize(cameras);
  for (int c = 0; c < cameras; ++c) {
    Frame& f = set.frames[c];
    f.image = cv::Mat(24, 32, c == 0 ? CV_8UC1 : CV_8UC3);
    cv::randu(f.image, 0, 256);
    f.image.at<uint8_t>(0, 0) = static_cast<uint8_t>(i);
    f.timestamp_s = 100.0 + 0.0005 * c + i / 30.0;
    f.sequence = 7 + 2 * c + i;
  }
  set.index = i;
  return set;
}
FrameSet Pair(int i) { return Set(i, 2); }

SessionInfo Info() {
  SessionInfo info;
  info.cameras = {{"left", "folder:/x/left*.png", "left cam", ""},
                  {"right", "folder:/x/right*.png", "right cam", ""}};
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
  std::vector<FrameSet> pairs;
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
    EXPECT_EQ(cv::norm(l, pairs[i].frames[0].image, cv::NORM_INF), 0);
    EXPECT_EQ(cv::norm(r, pairs[i].frames[1].image, cv::NORM_INF), 0);
  }
  EXPECT_TRUE(GlobSorted(dir + "/*/*.part").empty());
  EXPECT_FALSE(Exists(dir + "/frames.csv.part"));

  // frames.csv: provenance comment, header (version 2's, byte for byte),
  // one row per pair.
  const std::string csv = ReadFile(dir + "/frames.csv");
  EXPECT_EQ(csv.rfind("# kincal capture --test\n"
                      "frame,t_left,t_right,seq_left,seq_right,j1,j2\n"
                      "0,100.000000,100.000500,7,9,0,-20.25\n",
                      0),
            0u)
      << csv;
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
  EXPECT_EQ(y["pairing"]["dropped"]["right"].as<int>(), 0);
  EXPECT_EQ(y["joints"][1].as<std::string>(), "j2");
  EXPECT_EQ(y["stop_reason"].as<std::string>(), "end_of_stream");
  EXPECT_EQ(y["settings"]["frames"].as<std::string>(), "3");
  EXPECT_EQ(y["started_utc"].as<std::string>().size(), 20u);
}

TEST(RecorderTest, ThreeCamerasGetAFolderAndTwoColumnsEach) {
  SetCommandLine("kincal capture --three");
  const std::string dir = MakeTempDir("rec3") + "/s";
  SessionInfo info = Info();
  info.cameras.push_back({"top", "folder:/x/top*.png", "top cam", ""});
  info.joint_names = {"j1"};
  SessionRecorder rec;
  ASSERT_TRUE(rec.Open(dir, info).ok());
  std::vector<FrameSet> sets;
  for (int i = 0; i < 2; ++i) {
    sets.push_back(Set(i, 3));
    ASSERT_TRUE(rec.Write(sets.back(), {0.5 * i}).ok());
  }
  // A set without the third camera's frame is refused and writes nothing.
  EXPECT_EQ(rec.Write(Pair(2), {1.0}).kind(), Status::Kind::kUnsupported);
  SessionSummary summary;
  summary.dropped = {0, 2, 5};
  ASSERT_TRUE(rec.Finalize(summary).ok());

  const char* names[] = {"left", "right", "top"};
  for (int c = 0; c < 3; ++c) {
    const auto files = GlobSorted(dir + "/" + names[c] + "/*");
    ASSERT_EQ(files.size(), 2u) << names[c];
    EXPECT_EQ(files[1], dir + "/" + names[c] + "/000001.png");
    const cv::Mat image = cv::imread(files[1], cv::IMREAD_UNCHANGED);
    EXPECT_EQ(cv::norm(image, sets[1].frames[c].image, cv::NORM_INF), 0);
  }
  EXPECT_EQ(ReadFile(dir + "/frames.csv"),
            "# kincal capture --three\n"
            "frame,t_left,t_right,t_top,seq_left,seq_right,seq_top,j1\n"
            "0,100.000000,100.000500,100.001000,7,9,11,0\n"
            "1,100.033333,100.033833,100.034333,8,10,12,0.5\n");
  const YAML::Node y = YAML::LoadFile(dir + "/session.yaml");
  EXPECT_EQ(y["sources"]["top"]["uri"].as<std::string>(), "folder:/x/top*.png");
  EXPECT_EQ(y["images"]["top"].as<std::string>(), "top/*.png");
  EXPECT_EQ(y["pairing"]["dropped"]["top"].as<int>(), 5);
  EXPECT_EQ(y["pairing"]["dropped"]["right"].as<int>(), 2);
}

TEST(RecorderTest, OneCameraAndCameraNamesAreChecked) {
  SessionInfo info = Info();
  info.cameras.resize(1);
  const std::string dir = MakeTempDir("rec1") + "/s";
  SessionRecorder rec;
  ASSERT_TRUE(rec.Open(dir, info).ok());
  ASSERT_TRUE(rec.Write(Set(0, 1)).ok());
  ASSERT_TRUE(rec.Finalize(SessionSummary()).ok());
  EXPECT_EQ(TokenizeCsv(ReadFile(dir + "/frames.csv"), "f")[0].fields.size(),
            3u);  // frame, t_left, seq_left
  EXPECT_EQ(GlobSorted(dir + "/left/*.png").size(), 1u);

  for (const std::vector<std::string>& names :
       std::vector<std::vector<std::string>>{
           {}, {"a", "a"}, {"a", "b/c"}, {".."}}) {
    SessionInfo bad = Info();
    bad.cameras.clear();
    for (const std::string& n : names) bad.cameras.push_back({n, "", "", ""});
    SessionRecorder r;
    const std::string d = MakeTempDir("rec_names") + "/s";
    EXPECT_EQ(r.Open(d, bad).kind(), Status::Kind::kUnsupported)
        << names.size();
    EXPECT_FALSE(Exists(d));
  }
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
