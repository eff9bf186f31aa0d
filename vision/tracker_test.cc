#include "vision/tracker.h"

#include <gtest/gtest.h>

#include "synth/render.h"

namespace kincal {
namespace {

// A smooth motion of the example tool, rendered in the left camera.
std::vector<cv::Mat> Sequence(int n) {
  const Rig rig = ExampleStereoRig(640, 512);
  const Target target = ExampleTarget();
  ViewRenderer renderer(rig.cameras[0]);
  RenderOptions o;
  o.blur_sigma_px = 0.6;
  o.noise_sigma = 1.0;
  std::mt19937_64 rng(4);
  std::vector<cv::Mat> frames;
  for (int i = 0; i < n; ++i) {
    Rigid3 pose = ExampleToolPose(0);
    pose.t += Eigen::Vector3d(-4.0 * i, 2.0 * i, 0);
    pose.R = pose.R * Eigen::AngleAxisd(0.02 * i, Eigen::Vector3d::UnitZ())
                          .toRotationMatrix();
    frames.push_back(renderer.Render(TargetPlanes(target, pose), {}, o, &rng));
  }
  return frames;
}

TEST(Tracker, RegionsFindWhatTheFullFrameFinds) {
  const std::vector<cv::Mat> frames = Sequence(6);
  TrackerOptions o;
  TagTracker tracker(o);
  AprilTagDetector full;
  for (size_t i = 0; i < frames.size(); ++i) {
    const auto tracked = tracker.Track(frames[i]);
    const auto reference = full.Detect(frames[i]);
    ASSERT_EQ(tracked.size(), reference.size()) << "frame " << i;
    ASSERT_EQ(tracked.size(), 4u);
    for (size_t t = 0; t < tracked.size(); ++t) {
      EXPECT_EQ(tracked[t].id, reference[t].id);
      // The refinement's sample points follow libapriltag's start corners,
      // which differ a little between a region and the full frame: up to
      // 0.03 px here (the area rule before the pattern model: 0.02).
      for (int k = 0; k < 4; ++k) {
        EXPECT_LT((tracked[t].corners[k] - reference[t].corners[k]).norm(),
                  0.05);
      }
    }
    if (i > 0) {
      ASSERT_FALSE(tracker.last_regions().empty());
      // Tags close together: one merged region, far smaller than the frame.
      EXPECT_LT(tracker.last_regions()[0].area(), 640 * 512 / 4);
    }
  }
  EXPECT_EQ(tracker.full_searches(), 1);
}

TEST(Tracker, SearchesTheFullFrameWhenLost) {
  std::vector<cv::Mat> frames = Sequence(3);
  TagTracker tracker;
  EXPECT_EQ(tracker.Track(frames[0]).size(), 4u);
  // Tool gone: tracking finds nothing and falls back to a full search.
  const cv::Mat empty(512, 640, CV_8UC1, cv::Scalar(90));
  EXPECT_TRUE(tracker.Track(empty).empty());
  EXPECT_EQ(tracker.full_searches(), 2);
  // Back again: found by a full search, then tracked.
  EXPECT_EQ(tracker.Track(frames[2]).size(), 4u);
  EXPECT_EQ(tracker.full_searches(), 3);
  EXPECT_EQ(tracker.Track(frames[2]).size(), 4u);
  EXPECT_EQ(tracker.full_searches(), 3);
}

TEST(Tracker, DisabledMeansFullFrameEveryTime) {
  std::vector<cv::Mat> frames = Sequence(2);
  TrackerOptions o;
  o.enabled = false;
  TagTracker tracker(o);
  tracker.Track(frames[0]);
  tracker.Track(frames[1]);
  EXPECT_EQ(tracker.full_searches(), 2);
}

}  // namespace
}  // namespace kincal
