#include "capture/stereo_grabber.h"

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

// Collects (left sequence, right sequence) of every pair until a non-ok.
std::vector<std::pair<int64_t, int64_t>> Drain(StereoGrabber* g, Status* last) {
  std::vector<std::pair<int64_t, int64_t>> out;
  StereoFrame p;
  while ((*last = g->Grab(&p)).ok()) {
    EXPECT_EQ(p.index, static_cast<int64_t>(out.size()));
    out.push_back({p.left.sequence, p.right.sequence});
  }
  return out;
}

TEST(StereoGrabberTest, ReplayPairsInLockStep) {
  ScriptedSource left(ScriptedSource::Times({0, 1, 2}), false);
  ScriptedSource right(ScriptedSource::Times({5, 6, 7}), false);  // any times
  StereoGrabber g(&left, &right);
  EXPECT_EQ(g.pairing(), StereoGrabber::Pairing::kLockStep);
  ASSERT_TRUE(g.Open().ok());
  Status last;
  const auto pairs = Drain(&g, &last);
  EXPECT_EQ(last.kind(), Status::Kind::kEndOfStream);
  ASSERT_EQ(pairs.size(), 3u);
  EXPECT_EQ(pairs[2], std::make_pair(int64_t{2}, int64_t{2}));
  EXPECT_FALSE(g.length_mismatch());
  EXPECT_EQ(g.dropped_left() + g.dropped_right(), 0);
}

TEST(StereoGrabberTest, LockStepReportsUnequalLengths) {
  ScriptedSource left(ScriptedSource::Times({0, 1}), false);
  ScriptedSource right(ScriptedSource::Times({0, 1, 2}), false);
  StereoGrabber g(&left, &right);
  ASSERT_TRUE(g.Open().ok());
  Status last;
  EXPECT_EQ(Drain(&g, &last).size(), 2u);
  EXPECT_TRUE(g.length_mismatch());
  EXPECT_EQ(g.dropped_right(), 1);

  ScriptedSource l2(ScriptedSource::Times({0, 1, 2}), false);
  ScriptedSource r2(ScriptedSource::Times({0}), false);
  StereoGrabber g2(&l2, &r2);
  ASSERT_TRUE(g2.Open().ok());
  EXPECT_EQ(Drain(&g2, &last).size(), 1u);
  EXPECT_TRUE(g2.length_mismatch());
  EXPECT_EQ(g2.dropped_left(), 1);
}

TEST(StereoGrabberTest, LiveCamerasPairByNearestTimestampAndCountDrops) {
  // 30 fps; right started 8 ms late and lost its frame near t = 0.1;
  // left lost its frame near 0.2.
  ScriptedSource left(ScriptedSource::Times({0.000, 0.033, 0.067, 0.100, 0.133,
                                             0.167, 0.233, 0.267}),
                      true);
  ScriptedSource right(
      ScriptedSource::Times({0.041, 0.075, 0.141, 0.175, 0.208, 0.241, 0.275}),
      true);
  StereoGrabberOptions options;
  options.tolerance_s = 0.010;
  StereoGrabber g(&left, &right, options);
  EXPECT_EQ(g.pairing(), StereoGrabber::Pairing::kNearestTimestamp);
  ASSERT_TRUE(g.Open().ok());
  Status last;
  const auto pairs = Drain(&g, &last);
  EXPECT_EQ(last.kind(), Status::Kind::kEndOfStream);
  // left seq: 0 1 2 3 4 5 6 7 at 0 .033 .067 .100 .133 .167 .233 .267
  // right seq: 0 1 2 3 4 5 6 at .041 .075 .141 .175 .208 .241 .275
  const std::vector<std::pair<int64_t, int64_t>> expected = {
      {1, 0}, {2, 1}, {4, 2}, {5, 3}, {6, 5}, {7, 6}};
  EXPECT_EQ(pairs, expected);
  EXPECT_EQ(g.dropped_left(), 2);   // t = 0 (before right started), 0.100
  EXPECT_EQ(g.dropped_right(), 1);  // 0.208 (its left frame was lost)
}

TEST(StereoGrabberTest, TimeoutKeepsThePendingFrameOfTheOtherSide) {
  ScriptedSource left(ScriptedSource::Times({1.0, 2.0}), true);
  ScriptedSource right({{0, Status::Error(Status::Kind::kTimeout, "no frame")},
                        {1.001, Status::Ok()},
                        {2.001, Status::Ok()}},
                       true);
  StereoGrabber g(&left, &right);
  ASSERT_TRUE(g.Open().ok());
  StereoFrame p;
  EXPECT_EQ(g.Grab(&p).kind(), Status::Kind::kTimeout);
  ASSERT_TRUE(g.Grab(&p).ok());
  EXPECT_DOUBLE_EQ(p.left.timestamp_s, 1.0);  // left frame was not lost
  EXPECT_EQ(p.index, 0);
  ASSERT_TRUE(g.Grab(&p).ok());
  EXPECT_DOUBLE_EQ(p.right.timestamp_s, 2.001);
  EXPECT_EQ(g.dropped_left() + g.dropped_right(), 0);
}

TEST(StereoGrabberTest, GivesUpWhenCamerasNeverAgree) {
  std::vector<double> tl, tr;
  for (int i = 0; i < 50; ++i) {
    tl.push_back(i * 0.020);         // 50 fps
    tr.push_back(0.5 + i * 0.0307);  // starts 0.5 s later, another rate
  }
  ScriptedSource left(ScriptedSource::Times(tl), true);
  ScriptedSource right(ScriptedSource::Times(tr), true);
  StereoGrabberOptions options;
  options.tolerance_s = 1e-4;
  options.max_consecutive_drops = 20;
  StereoGrabber g(&left, &right, options);
  ASSERT_TRUE(g.Open().ok());
  StereoFrame p;
  const Status s = g.Grab(&p);
  EXPECT_EQ(s.kind(), Status::Kind::kIoError);
  EXPECT_NE(s.message().find("same frame rate"), std::string::npos);
  EXPECT_EQ(g.dropped_left() + g.dropped_right(), 20);
}

TEST(StereoGrabberTest, RefusesToPairACameraWithAReplayByTime) {
  ScriptedSource live(ScriptedSource::Times({0}), true);
  ScriptedSource replay(ScriptedSource::Times({0}), false);
  StereoGrabber g(&live, &replay);
  const Status s = g.Open();
  EXPECT_EQ(s.kind(), Status::Kind::kUnsupported);
  EXPECT_FALSE(live.opened);
}

TEST(StereoGrabberTest, RightOpenFailureClosesLeft) {
  ScriptedSource left(ScriptedSource::Times({0}), true);
  ScriptedSource right({}, true, Status::Error(Status::Kind::kBusy, "in use"));
  StereoGrabber g(&left, &right);
  const Status s = g.Open();
  EXPECT_EQ(s.kind(), Status::Kind::kBusy);
  EXPECT_TRUE(left.opened);
  EXPECT_TRUE(left.closed);
  StereoFrame p;
  EXPECT_FALSE(g.Grab(&p).ok());
}

}  // namespace
}  // namespace kincal::capture
