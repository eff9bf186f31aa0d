#include "vision/tool_pose.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "synth/render.h"
#include "vision/triangulate.h"

namespace kincal {
namespace {

double RotationErrorDeg(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  return Eigen::AngleAxisd(a.transpose() * b).angle() * 180.0 / M_PI;
}

TEST(Triangulate, ExactOnDistortedRig) {
  const Rig rig = ExampleStereoRig(640, 512);
  for (const Eigen::Vector3d& p :
       {Eigen::Vector3d(50, -30, 420), Eigen::Vector3d(80, 60, 520),
        Eigen::Vector3d(20, 10, 380)}) {
    std::vector<PixelObservation> obs;
    for (int c = 0; c < 2; ++c) {
      obs.push_back({c, Project(rig.cameras[c].intrinsics,
                                rig.cameras[c].cam_from_rig * p)});
    }
    TriangulationOptions linear;
    linear.refine = false;
    const TriangulatedPoint a = TriangulatePoint(rig, obs, linear);
    const TriangulatedPoint b = TriangulatePoint(rig, obs);
    ASSERT_TRUE(a.ok);
    ASSERT_TRUE(b.ok);
    EXPECT_LT((a.p_in_rig - p).norm(), 1e-6);
    EXPECT_LT((b.p_in_rig - p).norm(), 1e-9);
    EXPECT_LT(b.rms_px, 1e-9);
    // With noise, the refined point reprojects no worse than the linear one.
    obs[0].px += Eigen::Vector2d(0.3, -0.2);
    obs[1].px += Eigen::Vector2d(-0.1, 0.25);
    EXPECT_LE(TriangulatePoint(rig, obs).rms_px,
              TriangulatePoint(rig, obs, linear).rms_px + 1e-12);
  }
  EXPECT_FALSE(TriangulatePoint(rig, {{0, {1, 2}}}).ok);
}

TEST(Triangulate, MatchesCornersById) {
  TagDetection a, b, c;
  a.id = 1;
  b.id = 2;
  c.id = 1;
  a.corners[2] = {10, 20};
  c.corners[2] = {30, 40};
  const auto m = MatchTagCorners({a, b}, {c});
  ASSERT_EQ(m.size(), 4u);
  EXPECT_EQ(m[2].tag_id, 1);
  EXPECT_EQ(m[2].corner, 2);
  EXPECT_EQ(m[2].px0, Eigen::Vector2d(10, 20));
  EXPECT_EQ(m[2].px1, Eigen::Vector2d(30, 40));
  // A duplicated id is ambiguous.
  EXPECT_TRUE(MatchTagCorners({a, a}, {c}).empty());
}

// The example tool at ExampleToolPose(pose) rendered by `rig` (blur
// 0.6 px, noise drawn from `seed`), and each view's detections.
struct RenderedDetections {
  StereoFrameTruth frame;
  std::vector<std::vector<TagDetection>> dets;
};
RenderedDetections RenderAndDetect(const Rig& rig, const Target& target,
                                   int pose, uint64_t seed) {
  RenderOptions o;
  o.blur_sigma_px = 0.6;
  StereoRenderer renderer(rig, target, o);
  std::mt19937_64 rng(seed);
  RenderedDetections out;
  out.frame = renderer.Render(ExampleToolPose(pose), &rng);
  AprilTagDetector detector;
  for (const auto& v : out.frame.views) {
    out.dets.push_back(detector.Detect(v.image));
  }
  return out;
}

struct PoseErrors {
  double rot_deg = 0, trans_mm = 0, tip_mm = 0, rms_px = 0;
};

// Rendered stereo frames of the example tool: pose and tip against truth.
TEST(ToolPose, RenderedFramesRecoverPoseAndTip) {
  const Rig rig = ExampleStereoRig(640, 512);
  const Target target = ExampleTarget();
  RenderOptions o;
  o.blur_sigma_px = 0.6;
  o.noise_sigma = 1.0;
  StereoRenderer renderer(rig, target, o);
  AprilTagDetector detector;
  std::mt19937_64 rng(11);
  double worst_tip = 0, worst_rot = 0, sum_tip2 = 0;
  const int n = 4;
  for (int i = 0; i < n; ++i) {
    const StereoFrameTruth frame = renderer.Render(ExampleToolPose(i), &rng);
    std::vector<std::vector<TagDetection>> dets;
    for (const auto& v : frame.views) dets.push_back(detector.Detect(v.image));
    const ToolPoseResult r = EstimateToolPose(rig, target, dets);
    ASSERT_TRUE(r.found) << r.why_not;
    EXPECT_EQ(r.tags_used, 8);
    EXPECT_LT(r.rms_px, 0.2);
    const double tip = (r.tip_in_rig - frame.tip_in_rig).norm();
    const double rot =
        RotationErrorDeg(r.rig_from_tool.R, frame.rig_from_tool.R);
    worst_tip = std::max(worst_tip, tip);
    worst_rot = std::max(worst_rot, rot);
    sum_tip2 += tip * tip;
    EXPECT_LT((r.rig_from_tool.t - frame.rig_from_tool.t).norm(), 0.3);
  }
  std::printf("tool pose: tip RMS %.4f mm, worst %.4f mm, worst rot %.4f deg\n",
              std::sqrt(sum_tip2 / n), worst_tip, worst_rot);
  EXPECT_LT(worst_tip, 0.1);
  EXPECT_LT(worst_rot, 0.05);
}

// One tag observation moved by 6 px is rejected and does not spoil the pose;
// with the left camera only, PnP + fit still find the tool.
TEST(ToolPose, RejectsOutlierTagAndWorksWithOneCamera) {
  const Rig rig = ExampleStereoRig(640, 512);
  const Target target = ExampleTarget();
  RenderedDetections rendered = RenderAndDetect(rig, target, 2, 2);
  const StereoFrameTruth& frame = rendered.frame;
  std::vector<std::vector<TagDetection>>& dets = rendered.dets;
  ASSERT_FALSE(dets[1].empty());
  // A tag whose detection itself is off (libapriltag's corners too).
  for (auto& c : dets[1][0].corners) c += Eigen::Vector2d(6, -2);
  for (auto& c : dets[1][0].detector_corners) c += Eigen::Vector2d(6, -2);
  const ToolPoseResult r = EstimateToolPose(rig, target, dets);
  ASSERT_TRUE(r.found);
  EXPECT_EQ(r.tags_used, static_cast<int>(dets[0].size() + dets[1].size()) - 1);
  bool rejected = false;
  for (const auto& t : r.tags) {
    if (t.camera == 1 && t.tag_id == dets[1][0].id) rejected = !t.used;
  }
  EXPECT_TRUE(rejected);
  EXPECT_LT((r.tip_in_rig - frame.tip_in_rig).norm(), 0.3);

  const ToolPoseResult left = EstimateToolPose(rig, target, {dets[0], {}});
  ASSERT_TRUE(left.found);
  EXPECT_EQ(left.tags_used, static_cast<int>(dets[0].size()));
  // One camera: depth is weakly fixed, a few mm at most here.
  EXPECT_LT((left.tip_in_rig - frame.tip_in_rig).norm(), 3.0);

  const ToolPoseResult none = EstimateToolPose(rig, target, {{}, {}});
  EXPECT_FALSE(none.found);
  EXPECT_FALSE(none.why_not.empty());
}

// A refined corner that went wrong (e.g. an edge window reaching a
// neighbouring tag) while libapriltag's corner is fine: the per-corner check
// against the pose puts libapriltag's corner back; one that is off in both
// is left out, and the tag keeps its other corners.
TEST(ToolPose, PerCornerCheckFallsBackOrDrops) {
  const Rig rig = ExampleStereoRig(640, 512);
  const Target target = ExampleTarget();
  RenderedDetections rendered = RenderAndDetect(rig, target, 3, 4);
  std::vector<std::vector<TagDetection>>& dets = rendered.dets;
  ASSERT_GE(dets[0].size(), 2u);
  const ToolPoseResult clean = EstimateToolPose(rig, target, dets);
  ASSERT_TRUE(clean.found);
  TagDetection& a = dets[0][0];
  a.refined[1] = true;
  a.corners[1] = a.detector_corners[1] + Eigen::Vector2d(1.5, 0.8);
  TagDetection& b = dets[0][1];
  b.corners[2] += Eigen::Vector2d(-2.0, 1.0);
  b.detector_corners[2] = b.corners[2];
  const ToolPoseResult r = EstimateToolPose(rig, target, dets);
  ASSERT_TRUE(r.found);
  EXPECT_EQ(r.tags_used, clean.tags_used);
  for (const auto& t : r.tags) {
    if (t.camera != 0) continue;
    if (t.tag_id == a.id) {
      EXPECT_TRUE(t.corner_used[1]);
      EXPECT_LT((t.corners_px[1] - a.detector_corners[1]).norm(), 1e-12);
    }
    if (t.tag_id == b.id) {
      EXPECT_FALSE(t.corner_used[2]);
    }
  }
  EXPECT_LT(r.rms_px, 0.1);
  EXPECT_LT((r.tip_in_rig - clean.tip_in_rig).norm(), 0.05);
}

// Corners the detector marks unusable take no part, though they fit the
// pose here: one such corner leaves the tag with three, two leave the tag
// out ("corners").
TEST(ToolPose, UnusableCornersTakeNoPart) {
  const Rig rig = ExampleStereoRig(640, 512);
  const Target target = ExampleTarget();
  RenderedDetections rendered = RenderAndDetect(rig, target, 3, 4);
  std::vector<std::vector<TagDetection>>& dets = rendered.dets;
  ASSERT_GE(dets[0].size(), 3u);
  const ToolPoseResult clean = EstimateToolPose(rig, target, dets);
  ASSERT_TRUE(clean.found);
  TagDetection& a = dets[0][0];
  a.usable[3] = false;
  TagDetection& b = dets[0][1];
  b.usable[0] = b.usable[1] = false;
  const ToolPoseResult r = EstimateToolPose(rig, target, dets);
  ASSERT_TRUE(r.found);
  EXPECT_EQ(r.tags_used, clean.tags_used - 1);
  bool saw_a = false, saw_b = false;
  for (const auto& t : r.tags) {
    if (t.camera != 0) continue;
    if (t.tag_id == a.id) {
      saw_a = true;
      EXPECT_TRUE(t.used);
      EXPECT_FALSE(t.corner_used[3]);
    }
    if (t.tag_id == b.id) {
      saw_b = true;
      EXPECT_FALSE(t.used);
      EXPECT_EQ(t.left_out, "corners");
    }
  }
  EXPECT_TRUE(saw_a && saw_b);
  EXPECT_LT(r.rms_px, 0.1);
  EXPECT_LT((r.tip_in_rig - clean.tip_in_rig).norm(), 0.05);
}

// A tag the edge refinement could not refine (libapriltag's corners, here
// moved 1 px as libapriltag's are on a few per cent of corners) is left out
// while the refined tags determine the pose; alone in its camera it stays.
TEST(ToolPose, UnrefinedTagLeftOutWhileOthersDetermineThePose) {
  const Rig rig = ExampleStereoRig(640, 512);
  const Target target = ExampleTarget();
  RenderedDetections rendered = RenderAndDetect(rig, target, 3, 4);
  std::vector<std::vector<TagDetection>>& dets = rendered.dets;
  ASSERT_GE(dets[0].size(), 3u);
  const ToolPoseResult clean = EstimateToolPose(rig, target, dets);
  ASSERT_TRUE(clean.found);
  TagDetection& a = dets[0][0];
  a.refined = {false, false, false, false};
  a.sides = {};
  for (auto& c : a.corners) c += Eigen::Vector2d(0.7, -0.7);
  a.detector_corners = a.corners;
  const ToolPoseResult r = EstimateToolPose(rig, target, dets);
  ASSERT_TRUE(r.found);
  EXPECT_EQ(r.tags_used, clean.tags_used - 1);
  for (const auto& t : r.tags) {
    if (t.camera == 0 && t.tag_id == a.id) {
      EXPECT_EQ(t.left_out, "unrefined");
    }
  }
  EXPECT_LT((r.tip_in_rig - clean.tip_in_rig).norm(), 0.05);
  // Every tag unrefined (a detector without refinement): all are used.
  for (auto& c : a.corners) c -= Eigen::Vector2d(0.7, -0.7);
  for (auto& cam : dets) {
    for (TagDetection& d : cam) {
      d.refined = {false, false, false, false};
      d.sides = {};
    }
  }
  EXPECT_EQ(EstimateToolPose(rig, target, dets).tags_used, clean.tags_used);
}

// track's gate: enough tags, a tight fit, and two cameras where the rig
// has them (one camera of a stereo rig gives a weak depth).
TEST(ToolPose, TrackGateNeedsTagsFitAndTwoCameras) {
  ToolPoseResult r;
  r.found = true;
  r.tags_used = 2;
  r.rms_px = 0.3;
  TagObservationResult a, b;
  a.used = b.used = true;
  a.camera = 0;
  b.camera = 1;
  r.tags = {a, b};
  EXPECT_TRUE(PassesTrackGate(r, 2, 2, 0.5));
  EXPECT_FALSE(PassesTrackGate(r, 2, 3, 0.5));  // too few tags
  EXPECT_FALSE(PassesTrackGate(r, 2, 2, 0.2));  // fit too loose
  r.tags[1].camera = 0;                         // one camera of two
  EXPECT_FALSE(PassesTrackGate(r, 2, 2, 0.5));
  EXPECT_TRUE(PassesTrackGate(r, 1, 2, 0.5));  // a one-camera rig
  r.tags[1].camera = 1;
  r.tags[1].used = false;  // seen by camera 1 but left out of the fit
  EXPECT_FALSE(PassesTrackGate(r, 2, 2, 0.5));
  r.tags[1].used = true;
  r.found = false;
  EXPECT_FALSE(PassesTrackGate(r, 2, 2, 0.5));
}

}  // namespace
}  // namespace kincal
