#include "capture/frame_grabber.h"

#include <gtest/gtest.h>

#include <deque>
#include <utility>
#include <vector>

namespace kincal::capture {
namespace {

// A source that plays a script: each step is a frame at a timestamp or a
// failure status. After the script: kEndOfStream.
class ScriptedSource : public FrameSource {
 public:
  struct Step {
    double t = 0;
    Status status;
  };
  ScriptedSource(std::vector<Step> steps, bool live,
                 Status open_status = Status::Ok())
      : steps_(steps.begin(), steps.end()),
        live_(live),
        open_status_(std::move(open_status)) {}
  static std::vector<Step> Times(const std::vector<double>& ts) {
    std::vector<Step> steps;
    for (double t : ts) steps.push_back({t, Status::Ok()});
    return steps;
  }

  Status Open() override {
    if (open_status_.ok()) opened = true;
    return open_status_;
  }
  Status Grab(Frame* f) override {
    if (steps_.empty()) {
      return Status::Error(Status::Kind::kEndOfStream, "script done");
    }
    Step s = steps_.front();
    steps_.pop_front();
    if (!s.status.ok()) return s.status;
    f->timestamp_s = s.t;
    f->sequence = seq_++;
    f->image = cv::Mat(2, 2, CV_8UC1, cv::Scalar(seq_));
    return Status::Ok();
  }
  Status Close() override {
    closed = true;
    return Status::Ok();
  }
  std::string Describe() const override { return "scripted"; }
  bool IsLive() const override { return live_; }
  TimeBase time_base() const override {
    return live_ ? TimeBase::kHostMonotonic : TimeBase::kMedia;
  }

  bool opened = false;
  bool closed = false;

 private:
  std::deque<Step> steps_;
  bool live_;
  Status open_status_;
  int64_t seq_ = 0;
};

// Collects the sequence numbers of every set (one per source) until a
// non-ok status.
std::vector<std::vector<int64_t>> DrainSets(FrameGrabber* g, Status* last) {
  std::vector<std::vector<int64_t>> out;
  FrameSet set;
  while ((*last = g->Grab(&set)).ok()) {
    EXPECT_EQ(set.index, static_cast<int64_t>(out.size()));
    EXPECT_EQ(set.frames.size(), g->cameras());
    std::vector<int64_t> seqs;
    for (const Frame& f : set.frames) seqs.push_back(f.sequence);
    out.push_back(seqs);
  }
  return out;
}

// The same for two sources, as (first, second) pairs.
std::vector<std::pair<int64_t, int64_t>> Drain(FrameGrabber* g, Status* last) {
  std::vector<std::pair<int64_t, int64_t>> out;
  for (const auto& seqs : DrainSets(g, last)) out.push_back({seqs[0], seqs[1]});
  return out;
}

TEST(FrameGrabberTest, ReplayPairsInLockStep) {
  ScriptedSource left(ScriptedSource::Times({0, 1, 2}), false);
  ScriptedSource right(ScriptedSource::Times({5, 6, 7}), false);  // any times
  FrameGrabber g({&left, &right});
  EXPECT_EQ(g.pairing(), FrameGrabber::Pairing::kLockStep);
  ASSERT_TRUE(g.Open().ok());
  Status last;
  const auto pairs = Drain(&g, &last);
  EXPECT_EQ(last.kind(), Status::Kind::kEndOfStream);
  ASSERT_EQ(pairs.size(), 3u);
  EXPECT_EQ(pairs[2], std::make_pair(int64_t{2}, int64_t{2}));
  EXPECT_FALSE(g.length_mismatch());
  EXPECT_EQ(g.dropped(0) + g.dropped(1), 0);
}

TEST(FrameGrabberTest, LockStepReportsUnequalLengths) {
  ScriptedSource left(ScriptedSource::Times({0, 1}), false);
  ScriptedSource right(ScriptedSource::Times({0, 1, 2}), false);
  FrameGrabber g({&left, &right});
  ASSERT_TRUE(g.Open().ok());
  Status last;
  EXPECT_EQ(Drain(&g, &last).size(), 2u);
  EXPECT_TRUE(g.length_mismatch());
  EXPECT_EQ(g.dropped(1), 1);

  ScriptedSource l2(ScriptedSource::Times({0, 1, 2}), false);
  ScriptedSource r2(ScriptedSource::Times({0}), false);
  FrameGrabber g2({&l2, &r2});
  ASSERT_TRUE(g2.Open().ok());
  EXPECT_EQ(Drain(&g2, &last).size(), 1u);
  EXPECT_TRUE(g2.length_mismatch());
  EXPECT_EQ(g2.dropped(0), 1);
}

TEST(FrameGrabberTest, LiveCamerasPairByNearestTimestampAndCountDrops) {
  // 30 fps; right started 8 ms late and lost its frame near t = 0.1;
  // left lost its frame near 0.2.
  ScriptedSource left(ScriptedSource::Times({0.000, 0.033, 0.067, 0.100, 0.133,
                                             0.167, 0.233, 0.267}),
                      true);
  ScriptedSource right(
      ScriptedSource::Times({0.041, 0.075, 0.141, 0.175, 0.208, 0.241, 0.275}),
      true);
  FrameGrabberOptions options;
  options.tolerance_s = 0.010;
  FrameGrabber g({&left, &right}, options);
  EXPECT_EQ(g.pairing(), FrameGrabber::Pairing::kNearestTimestamp);
  ASSERT_TRUE(g.Open().ok());
  Status last;
  const auto pairs = Drain(&g, &last);
  EXPECT_EQ(last.kind(), Status::Kind::kEndOfStream);
  // left seq: 0 1 2 3 4 5 6 7 at 0 .033 .067 .100 .133 .167 .233 .267
  // right seq: 0 1 2 3 4 5 6 at .041 .075 .141 .175 .208 .241 .275
  const std::vector<std::pair<int64_t, int64_t>> expected = {
      {1, 0}, {2, 1}, {4, 2}, {5, 3}, {6, 5}, {7, 6}};
  EXPECT_EQ(pairs, expected);
  EXPECT_EQ(g.dropped(0), 2);  // t = 0 (before right started), 0.100
  EXPECT_EQ(g.dropped(1), 1);  // 0.208 (its left frame was lost)
}

TEST(FrameGrabberTest, TimeoutKeepsThePendingFrameOfTheOtherSide) {
  ScriptedSource left(ScriptedSource::Times({1.0, 2.0}), true);
  ScriptedSource right({{0, Status::Error(Status::Kind::kTimeout, "no frame")},
                        {1.001, Status::Ok()},
                        {2.001, Status::Ok()}},
                       true);
  FrameGrabber g({&left, &right});
  ASSERT_TRUE(g.Open().ok());
  FrameSet p;
  EXPECT_EQ(g.Grab(&p).kind(), Status::Kind::kTimeout);
  ASSERT_TRUE(g.Grab(&p).ok());
  EXPECT_DOUBLE_EQ(p.frames[0].timestamp_s, 1.0);  // left frame was not lost
  EXPECT_EQ(p.index, 0);
  ASSERT_TRUE(g.Grab(&p).ok());
  EXPECT_DOUBLE_EQ(p.frames[1].timestamp_s, 2.001);
  EXPECT_EQ(g.dropped(0) + g.dropped(1), 0);
}

TEST(FrameGrabberTest, GivesUpWhenCamerasNeverAgree) {
  std::vector<double> tl, tr;
  for (int i = 0; i < 50; ++i) {
    tl.push_back(i * 0.020);         // 50 fps
    tr.push_back(0.5 + i * 0.0307);  // starts 0.5 s later, another rate
  }
  ScriptedSource left(ScriptedSource::Times(tl), true);
  ScriptedSource right(ScriptedSource::Times(tr), true);
  FrameGrabberOptions options;
  options.tolerance_s = 1e-4;
  options.max_consecutive_drops = 20;
  FrameGrabber g({&left, &right}, options);
  ASSERT_TRUE(g.Open().ok());
  FrameSet p;
  const Status s = g.Grab(&p);
  EXPECT_EQ(s.kind(), Status::Kind::kIoError);
  EXPECT_NE(s.message().find("same frame rate"), std::string::npos);
  EXPECT_EQ(g.dropped(0) + g.dropped(1), 20);
}

TEST(FrameGrabberTest, RefusesToPairACameraWithAReplayByTime) {
  ScriptedSource live(ScriptedSource::Times({0}), true);
  ScriptedSource replay(ScriptedSource::Times({0}), false);
  FrameGrabber g({&live, &replay});
  const Status s = g.Open();
  EXPECT_EQ(s.kind(), Status::Kind::kUnsupported);
  EXPECT_FALSE(live.opened);
}

TEST(FrameGrabberTest, RightOpenFailureClosesLeft) {
  ScriptedSource left(ScriptedSource::Times({0}), true);
  ScriptedSource right({}, true, Status::Error(Status::Kind::kBusy, "in use"));
  FrameGrabber g({&left, &right});
  const Status s = g.Open();
  EXPECT_EQ(s.kind(), Status::Kind::kBusy);
  EXPECT_TRUE(left.opened);
  EXPECT_TRUE(left.closed);
  FrameSet p;
  EXPECT_FALSE(g.Grab(&p).ok());
}

TEST(FrameGrabberTest, OneCameraMakesEveryFrameASet) {
  for (bool live : {false, true}) {
    ScriptedSource only(ScriptedSource::Times({0.0, 0.033, 0.9, 5.0}), live);
    FrameGrabber g({&only});
    EXPECT_EQ(g.pairing(), live ? FrameGrabber::Pairing::kNearestTimestamp
                                : FrameGrabber::Pairing::kLockStep);
    ASSERT_TRUE(g.Open().ok());
    Status last;
    const auto sets = DrainSets(&g, &last);
    EXPECT_EQ(last.kind(), Status::Kind::kEndOfStream);
    const std::vector<std::vector<int64_t>> expected = {{0}, {1}, {2}, {3}};
    EXPECT_EQ(sets, expected) << live;
    EXPECT_EQ(g.dropped(0), 0);
    EXPECT_FALSE(g.length_mismatch());
  }
}

TEST(FrameGrabberTest, ThreeReplaysInLockStepCountTheLongerOnes) {
  ScriptedSource a(ScriptedSource::Times({0, 1, 2, 3}), false);
  ScriptedSource b(ScriptedSource::Times({0, 1}), false);
  ScriptedSource c(ScriptedSource::Times({0, 1, 2}), false);
  FrameGrabber g({&a, &b, &c});
  ASSERT_TRUE(g.Open().ok());
  Status last;
  const auto sets = DrainSets(&g, &last);
  EXPECT_EQ(last.kind(), Status::Kind::kEndOfStream);
  const std::vector<std::vector<int64_t>> expected = {{0, 0, 0}, {1, 1, 1}};
  EXPECT_EQ(sets, expected);
  EXPECT_TRUE(g.length_mismatch());
  // a's third frame was grabbed before b ended; c still had one.
  EXPECT_EQ(g.dropped(), (std::vector<int64_t>{1, 0, 1}));

  ScriptedSource d(ScriptedSource::Times({0, 1}), false);
  ScriptedSource e(ScriptedSource::Times({0, 1}), false);
  ScriptedSource f(ScriptedSource::Times({0, 1}), false);
  FrameGrabber equal({&d, &e, &f});
  ASSERT_TRUE(equal.Open().ok());
  EXPECT_EQ(DrainSets(&equal, &last).size(), 2u);
  EXPECT_FALSE(equal.length_mismatch());
  EXPECT_EQ(equal.dropped(), (std::vector<int64_t>{0, 0, 0}));
}

TEST(FrameGrabberTest, ThreeLiveCamerasGroupByTimeWithinTheTolerance) {
  // 30 fps. b runs 4 ms late and lost its frame near 0.100; c runs 3 ms
  // early, started late (first frame near 0.067) and lost its frame near
  // 0.200; a lost its frame near 0.267.
  ScriptedSource a(ScriptedSource::Times({0.000, 0.033, 0.067, 0.100, 0.133,
                                          0.167, 0.200, 0.233, 0.300}),
                   true);
  ScriptedSource b(ScriptedSource::Times({0.004, 0.037, 0.071, 0.137, 0.171,
                                          0.204, 0.237, 0.271, 0.304}),
                   true);
  ScriptedSource c(
      ScriptedSource::Times({0.064, 0.097, 0.130, 0.164, 0.230, 0.264, 0.297}),
      true);
  FrameGrabberOptions options;
  options.tolerance_s = 0.010;
  FrameGrabber g({&a, &b, &c}, options);
  ASSERT_TRUE(g.Open().ok());
  Status last;
  const auto sets = DrainSets(&g, &last);
  EXPECT_EQ(last.kind(), Status::Kind::kEndOfStream);
  // a seq 0..8 at 0 .033 .067 .100 .133 .167 .200 .233 .300
  // b seq 0..8 at .004 .037 .071 .137 .171 .204 .237 .271 .304
  // c seq 0..6 at .064 .097 .130 .164 .230 .264 .297
  const std::vector<std::vector<int64_t>> expected = {
      {2, 2, 0}, {4, 3, 2}, {5, 4, 3}, {7, 6, 4}, {8, 8, 6}};
  EXPECT_EQ(sets, expected);
  // a: 0, .033 (before c started), .100 (b lost it), .200 (c lost it);
  // b: .004, .037, .204, .271; c: .097, .264.
  EXPECT_EQ(g.dropped(), (std::vector<int64_t>{4, 4, 2}));
}

TEST(FrameGrabberTest, ASetSpansAtMostTheTolerance) {
  // Each neighbour pair is 6 ms apart, but the set spans 12 ms.
  ScriptedSource a(ScriptedSource::Times({0.000, 1.000}), true);
  ScriptedSource b(ScriptedSource::Times({0.006, 1.006}), true);
  ScriptedSource c(ScriptedSource::Times({0.012, 1.009}), true);
  FrameGrabberOptions options;
  options.tolerance_s = 0.010;
  FrameGrabber g({&a, &b, &c}, options);
  ASSERT_TRUE(g.Open().ok());
  Status last;
  const auto sets = DrainSets(&g, &last);
  const std::vector<std::vector<int64_t>> expected = {{1, 1, 1}};
  EXPECT_EQ(sets, expected);
  EXPECT_EQ(g.dropped(), (std::vector<int64_t>{1, 1, 1}));
}

TEST(FrameGrabberTest, ThirdOpenFailureClosesTheFirstTwo) {
  ScriptedSource a(ScriptedSource::Times({0}), true);
  ScriptedSource b(ScriptedSource::Times({0}), true);
  ScriptedSource c({}, true, Status::Error(Status::Kind::kBusy, "in use"));
  FrameGrabber g({&a, &b, &c});
  EXPECT_EQ(g.Open().kind(), Status::Kind::kBusy);
  EXPECT_TRUE(a.closed);
  EXPECT_TRUE(b.closed);
}

TEST(FrameGrabberTest, NoSourceIsRefused) {
  FrameGrabber g({});
  EXPECT_EQ(g.Open().kind(), Status::Kind::kUnsupported);
}

}  // namespace
}  // namespace kincal::capture
