#include "capture/async_recorder.h"

#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>
#include <yaml-cpp/yaml.h>

#include <chrono>
#include <cmath>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <thread>

#include "data/atomic_file.h"
#include "data/glob.h"
#include "tests/testing/paths.h"

namespace kincal::capture {
namespace {

using ::kincal::testing::Exists;
using ::kincal::testing::MakeTempDir;

// A left/right set: random gray images whose first pixel is i.
FrameSet Pair(int i, int width = 64, int height = 48) {
  FrameSet p;
  p.frames.resize(2);
  for (int c = 0; c < 2; ++c) {
    Frame& f = p.frames[c];
    f.image = cv::Mat(height, width, CV_8UC1);
    cv::randu(f.image, 0, 256);
    f.image.at<uint8_t>(0, 0) = static_cast<uint8_t>(i);
    f.timestamp_s = i / 30.0 + 1e-4 * c;
    f.sequence = i;
  }
  p.index = i;
  return p;
}

// A deep copy (the images' pixels too).
FrameSet Copy(const FrameSet& set) {
  FrameSet copy = set;
  for (Frame& f : copy.frames) f.image = f.image.clone();
  return copy;
}

SessionInfo Info() {
  SessionInfo info;
  info.cameras = {{"left", "fake:l", "", ""}, {"right", "fake:r", "", ""}};
  info.pairing = "timestamp";
  info.time_base = "host_monotonic";
  info.live = true;
  return info;
}

// frames.csv (or the journal) rows: frame, t_left, t_right, seq_left, ...
std::vector<std::vector<std::string>> Rows(const std::string& path) {
  std::vector<std::vector<std::string>> rows;
  std::istringstream in(ReadFile(path));
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#' || line.rfind("frame,", 0) == 0) {
      continue;
    }
    std::vector<std::string> cells;
    std::stringstream ss(line);
    std::string cell;
    while (std::getline(ss, cell, ',')) cells.push_back(cell);
    if (!line.empty() && line.back() == ',') cells.push_back("");
    rows.push_back(cells);
  }
  return rows;
}

// Every row names frame r; its two images exist and decode to the pair
// whose sequence the row records; no other images.
void ExpectConsistentSession(const std::string& dir, const std::string& csv) {
  const auto rows = Rows(dir + "/" + csv);
  int64_t last_seq = -1;
  for (size_t r = 0; r < rows.size(); ++r) {
    ASSERT_EQ(rows[r][0], std::to_string(r));
    const int seq = std::stoi(rows[r][3]);
    EXPECT_GT(seq, last_seq);  // accepted pairs keep their order
    last_seq = seq;
    const std::string name = SessionRecorder::FrameFileName(r);
    const cv::Mat l = cv::imread(dir + "/left/" + name, cv::IMREAD_UNCHANGED);
    const cv::Mat rr = cv::imread(dir + "/right/" + name, cv::IMREAD_UNCHANGED);
    ASSERT_FALSE(l.empty()) << name;
    ASSERT_FALSE(rr.empty()) << name;
    EXPECT_EQ(l.at<uint8_t>(0, 0), seq % 256);
    EXPECT_EQ(rr.at<uint8_t>(0, 0), seq % 256);
  }
  EXPECT_EQ(GlobSorted(dir + "/left/*.png").size(), rows.size());
  EXPECT_EQ(GlobSorted(dir + "/right/*.png").size(), rows.size());
}

TEST(AsyncRecorderTest, WritesEveryPairLosslesslyInOrder) {
  const std::string dir = MakeTempDir("arec") + "/s";
  SessionInfo info = Info();
  info.joint_names = {"j1", "j2"};
  SessionRecorder rec;
  ASSERT_TRUE(rec.Open(dir, info).ok());
  std::vector<FrameSet> sent;
  {
    AsyncRecorderOptions options;
    options.writer_threads = 3;  // out-of-order completion
    AsyncRecorder writer(&rec, options);
    for (int i = 0; i < 20; ++i) {
      sent.push_back(Pair(i));
      FrameSet copy = Copy(sent.back());
      const double j2 = i % 3 == 0 ? NAN : 0.5 * i;  // NaN = no reading
      ASSERT_TRUE(writer.Submit(std::move(copy), {1.0 * i, j2}));
    }
    EXPECT_TRUE(writer.Stop().ok());
    EXPECT_EQ(writer.dropped_sets(), 0);
  }
  EXPECT_EQ(rec.frames(), 20);
  SessionSummary summary;
  summary.stop_reason = "frames";
  ASSERT_TRUE(rec.Finalize(summary).ok());
  ExpectConsistentSession(dir, "frames.csv");
  const auto rows = Rows(dir + "/frames.csv");
  EXPECT_EQ(rows[3][5], "3");
  EXPECT_EQ(rows[3][6], "");  // no reading
  EXPECT_EQ(rows[4][6], "2");
  for (int i : {0, 7, 19}) {
    const std::string name = SessionRecorder::FrameFileName(i);
    const cv::Mat l = cv::imread(dir + "/left/" + name, cv::IMREAD_UNCHANGED);
    EXPECT_EQ(cv::norm(l, sent[i].frames[0].image, cv::NORM_INF), 0.0);
  }
}

// A disk slower than the cameras: the queue fills, new pairs are dropped
// and counted, Submit never waits, and what was accepted is all written.
TEST(AsyncRecorderTest, ThrottledWriterCountsDropsAndNeverBlocks) {
  const std::string dir = MakeTempDir("arec_slow") + "/s";
  SessionRecorder rec;
  ASSERT_TRUE(rec.Open(dir, Info()).ok());
  AsyncRecorderOptions options;
  options.queue_sets = 3;
  options.writer_threads = 1;
  options.writer_delay_s = 0.2;  // 5 pairs/s at most
  AsyncRecorder writer(&rec, options);
  int accepted = 0;
  double longest_submit_s = 0;
  for (int i = 0; i < 60; ++i) {  // 60 pairs at ~200 pairs/s
    const auto t0 = std::chrono::steady_clock::now();
    accepted += writer.Submit(Pair(i));
    longest_submit_s = std::max(
        longest_submit_s,
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0)
            .count());
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  ASSERT_TRUE(writer.Stop().ok());
  EXPECT_GT(writer.dropped_sets(), 40);
  EXPECT_EQ(accepted + writer.dropped_sets(), 60);
  EXPECT_EQ(writer.submitted(), 60);
  EXPECT_EQ(rec.frames(), accepted);
  EXPECT_LE(writer.max_queue_depth(), 3);
  EXPECT_LT(longest_submit_s, 0.1);  // never waited for a writer (0.2 s)
  SessionSummary summary;
  summary.dropped_sets = writer.dropped_sets();
  ASSERT_TRUE(rec.Finalize(summary).ok());
  ExpectConsistentSession(dir, "frames.csv");
  EXPECT_EQ(YAML::LoadFile(dir + "/session.yaml")["pairing"]["dropped_pairs"]
                .as<int>(),
            writer.dropped_sets());
}

TEST(AsyncRecorderTest, ReplayWaitsInsteadOfDropping) {
  const std::string dir = MakeTempDir("arec_replay") + "/s";
  SessionRecorder rec;
  ASSERT_TRUE(rec.Open(dir, Info()).ok());
  AsyncRecorderOptions options;
  options.queue_sets = 2;
  options.writer_threads = 1;
  options.writer_delay_s = 0.01;
  options.drop_when_full = false;
  AsyncRecorder writer(&rec, options);
  for (int i = 0; i < 15; ++i) ASSERT_TRUE(writer.Submit(Pair(i)));
  ASSERT_TRUE(writer.Stop().ok());
  EXPECT_EQ(writer.dropped_sets(), 0);
  EXPECT_EQ(rec.frames(), 15);
}

// A backlog switches the writers to PNG level 0 (stored): still lossless.
TEST(AsyncRecorderTest, BacklogIsWrittenFastAndStillLossless) {
  const std::string dir = MakeTempDir("arec_adaptive") + "/s";
  SessionRecorder::Options ro;
  ro.png_compression = 6;
  SessionRecorder rec(ro);
  ASSERT_TRUE(rec.Open(dir, Info()).ok());
  AsyncRecorderOptions options;
  options.queue_sets = 8;
  options.writer_threads = 1;
  options.writer_delay_s = 0.01;
  options.drop_when_full = false;
  std::vector<FrameSet> sent;
  {
    AsyncRecorder writer(&rec, options);
    for (int i = 0; i < 16; ++i) {
      sent.push_back(Pair(i, 320, 240));
      FrameSet copy = Copy(sent.back());
      ASSERT_TRUE(writer.Submit(std::move(copy)));
    }
    ASSERT_TRUE(writer.Stop().ok());
    EXPECT_GT(writer.fast_sets(), 0);
    EXPECT_LT(writer.fast_sets(), 16);
  }
  for (int i = 0; i < 16; ++i) {
    const std::string name = SessionRecorder::FrameFileName(i);
    const cv::Mat r = cv::imread(dir + "/right/" + name, cv::IMREAD_UNCHANGED);
    EXPECT_EQ(cv::norm(r, sent[i].frames[1].image, cv::NORM_INF), 0.0) << i;
  }
}

TEST(AsyncRecorderTest, WriteFailureKeepsTheCommittedFramesAndNoHalfPair) {
  const std::string dir = MakeTempDir("arec_fail") + "/s";
  SessionRecorder rec;
  ASSERT_TRUE(rec.Open(dir, Info()).ok());
  AsyncRecorderOptions options;
  options.writer_threads = 2;
  AsyncRecorder writer(&rec, options);
  for (int i = 0; i < 5; ++i) ASSERT_TRUE(writer.Submit(Pair(i)));
  while (rec.frames() < 5) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  ASSERT_EQ(
      std::system(
          ("rm -rf '" + dir + "/right' && touch '" + dir + "/right'").c_str()),
      0);
  for (int i = 5; i < 12; ++i) writer.Submit(Pair(i));
  const Status s = writer.Stop();
  EXPECT_EQ(s.kind(), Status::Kind::kIoError) << s.ToString();
  EXPECT_FALSE(writer.Submit(Pair(99)));
  EXPECT_EQ(rec.frames(), 5);
  EXPECT_EQ(GlobSorted(dir + "/left/*.png").size(), 5u);
  EXPECT_TRUE(GlobSorted(dir + "/left/*.part").empty());
  SessionSummary summary;
  summary.complete = false;
  ASSERT_TRUE(rec.Finalize(summary).ok());
  EXPECT_EQ(Rows(dir + "/frames.csv").size(), 5u);
}

// kill -9 in the middle of a recording: the journal lists only frames whose
// two images are complete, in order, without gaps.
TEST(AsyncRecorderTest, ReadableAfterKill9) {
  const std::string dir = MakeTempDir("arec_kill") + "/s";
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    SessionRecorder rec;
    if (!rec.Open(dir, Info()).ok()) ::_exit(3);
    AsyncRecorderOptions options;
    options.writer_threads = 2;
    options.drop_when_full = false;
    AsyncRecorder writer(&rec, options);
    for (int i = 0;; ++i) writer.Submit(Pair(i, 640, 512));
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(700));
  ASSERT_EQ(::kill(child, SIGKILL), 0);
  int status = 0;
  ::waitpid(child, &status, 0);
  ASSERT_TRUE(WIFSIGNALED(status));
  ASSERT_TRUE(Exists(dir + "/frames.csv.part"));
  const auto rows = Rows(dir + "/frames.csv.part");
  EXPECT_GT(rows.size(), 2u);
  // Images beyond the journal may exist (written, not yet committed); every
  // journal row must have both, complete.
  for (size_t r = 0; r < rows.size(); ++r) {
    ASSERT_EQ(rows[r][0], std::to_string(r));
    const std::string name = SessionRecorder::FrameFileName(r);
    EXPECT_FALSE(cv::imread(dir + "/left/" + name).empty()) << name;
    EXPECT_FALSE(cv::imread(dir + "/right/" + name).empty()) << name;
  }
}

}  // namespace
}  // namespace kincal::capture
