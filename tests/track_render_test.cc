// The tracker on renders it was not tuned on (issue 9, item 3). For each
// scene, the tip from our corners (edge refinement with its per-corner
// checks + the tool pose fit) is compared with what plain libapriltag corners
// give, both through the same pose fit and through the issue's reference
// (corners triangulated in both cameras + a rigid fit). The renders vary
// what the refinement assumes: box and disk and motion PSFs instead of a
// Gaussian, vignetting and a light gradient (no uniform black/white level),
// JPEG blocks, steep obliquity, neighbouring tags within a cell, and a
// family whose layout is not tag36h11's.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

#include "bundle/testing/synthetic.h"
#include "synth/render.h"
#include "tests/testing/holder_views.h"
#include "vision/apriltag_detector.h"
#include "vision/tool_pose.h"
#include "vision/triangulate.h"

namespace kincal {
namespace {

struct Scene {
  std::string name;
  RenderOptions render;
  std::string family = "tag36h11";
  double max_tilt_deg = 35;
  double tag_mm = 22;
};

struct Errors {
  std::vector<double> ours, plain_pose, plain_tri;
  int frames = 0, gated = 0;
};

Errors RunScene(const Scene& scene, int frames, uint64_t seed) {
  const Rig rig = ExampleStereoRig(640, 512);
  const Target target = ThreeTagHolder(scene.tag_mm, scene.family);
  StereoRenderer renderer(rig, target, scene.render);
  AprilTagOptions ours;
  ours.family = scene.family;
  AprilTagOptions plain = ours;
  plain.refinement = CornerRefinement::kNone;
  AprilTagDetector d_ours(ours), d_plain(plain);
  std::mt19937_64 rng(seed);
  Errors e;
  for (int f = 0; f < frames; ++f) {
    const StereoFrameTruth truth =
        renderer.Render(RandomPose(&rng, scene.max_tilt_deg), &rng);
    std::vector<std::vector<TagDetection>> a(2), b(2);
    for (int c = 0; c < 2; ++c) {
      a[c] = d_ours.Detect(truth.views[c].image);
      b[c] = d_plain.Detect(truth.views[c].image);
    }
    const ToolPoseResult ra = EstimateToolPose(rig, target, a);
    const ToolPoseResult rb = EstimateToolPose(rig, target, b);
    Eigen::Vector3d tri = Eigen::Vector3d::Zero();
    const bool ok_tri = TriangulatedRigidTip(rig, target, b, &tri);
    // Compare on frames where all three give a tip.
    if (!ra.found || !rb.found || !ok_tri) continue;
    ++e.frames;
    // The quality gate of `track --out-obs` (>= 2 tags, <= 0.5 px).
    if (ra.tags_used < 2 || ra.rms_px > 0.5) ++e.gated;
    e.ours.push_back((ra.tip_in_rig - truth.tip_in_rig).norm());
    e.plain_pose.push_back((rb.tip_in_rig - truth.tip_in_rig).norm());
    e.plain_tri.push_back((tri - truth.tip_in_rig).norm());
  }
  return e;
}

std::vector<Scene> Scenes() {
  std::vector<Scene> s;
  Scene issue;
  issue.name = "three tags, outer two turned 35 deg, blur + noise";
  issue.render.blur_sigma_px = 0.7;
  issue.render.noise_sigma = 2.0;
  s.push_back(issue);
  Scene oblique;
  oblique.name = "up to 70 deg oblique";
  oblique.max_tilt_deg = 70;
  oblique.render.blur_sigma_px = 0.5;
  oblique.render.noise_sigma = 1.5;
  s.push_back(oblique);
  Scene motion;
  motion.name = "motion blur 3 px";
  motion.render.motion_px = 3.0;
  motion.render.motion_angle_deg = 30;
  motion.render.noise_sigma = 1.5;
  s.push_back(motion);
  Scene defocus;
  defocus.name = "defocus disk 1.5 px, vignetting, light gradient";
  defocus.render.defocus_px = 1.5;
  defocus.render.vignetting = 0.5;
  defocus.render.light_gradient = 0.4;
  defocus.render.noise_sigma = 1.5;
  s.push_back(defocus);
  Scene jpeg;
  jpeg.name = "JPEG quality 70";
  jpeg.render.blur_sigma_px = 0.6;
  jpeg.render.noise_sigma = 1.0;
  jpeg.render.jpeg_quality = 70;
  s.push_back(jpeg);
  Scene t41;
  t41.name = "tagStandard41h12";
  t41.family = "tagStandard41h12";
  t41.render.blur_sigma_px = 0.6;
  t41.render.noise_sigma = 1.5;
  s.push_back(t41);
  return s;
}

TEST(TrackOnWidenedRenders, NeverWorseThanPlainLibapriltagCorners) {
  int i = 0;
  for (const Scene& scene : Scenes()) {
    const Errors e = RunScene(scene, 14, 1000 + 17 * i++);
    std::printf(
        "%-50s frames %2d gated %2d | tip RMS ours %.4f mm, plain corners + "
        "pose fit %.4f mm, plain corners + triangulation + rigid fit %.4f mm "
        "| worst ours %.4f\n",
        scene.name.c_str(), e.frames, e.gated, Rms(e.ours), Rms(e.plain_pose),
        Rms(e.plain_tri),
        e.ours.empty() ? 0.0 : *std::max_element(e.ours.begin(), e.ours.end()));
    ASSERT_GE(e.frames, 8) << scene.name;
    EXPECT_LE(Rms(e.ours), Rms(e.plain_tri)) << scene.name;
    EXPECT_LE(Rms(e.ours), 1.05 * Rms(e.plain_pose)) << scene.name;
  }
}

// Renders under real light (issue 21): the tracker's tips on every frame
// against the truth, and the reference (plain libapriltag corners,
// triangulation, rigid fit) on every frame it gives a tip.
struct LightErrors {
  int frames = 0, good = 0;
  std::vector<double> good_tips, plain_tri;
};

LightErrors RunLightScene(const RenderOptions& render, int frames,
                          uint64_t seed) {
  const Rig rig = ExampleStereoRig(640, 512);
  const Target target = ThreeTagHolder(22);
  StereoRenderer renderer(rig, target, render);
  AprilTagOptions ours;
  AprilTagOptions plain = ours;
  plain.refinement = CornerRefinement::kNone;
  AprilTagDetector d_ours(ours), d_plain(plain);
  std::mt19937_64 rng(seed);
  LightErrors e;
  for (int f = 0; f < frames; ++f) {
    const StereoFrameTruth truth = renderer.Render(RandomPose(&rng, 35), &rng);
    std::vector<std::vector<TagDetection>> a(2), b(2);
    for (int c = 0; c < 2; ++c) {
      a[c] = d_ours.Detect(truth.views[c].image);
      b[c] = d_plain.Detect(truth.views[c].image);
    }
    ++e.frames;
    const ToolPoseResult r = EstimateToolPose(rig, target, a);
    // The quality gate of `track` (>= 2 tags, <= 0.5 px, both cameras).
    if (PassesTrackGate(r, rig.cameras.size(), 2, 0.5)) {
      ++e.good;
      e.good_tips.push_back((r.tip_in_rig - truth.tip_in_rig).norm());
    }
    Eigen::Vector3d tri;
    if (TriangulatedRigidTip(rig, target, b, &tri)) {
      e.plain_tri.push_back((tri - truth.tip_in_rig).norm());
    }
  }
  return e;
}

// A distant light 50 deg off the view axis: the tag turned towards it is
// bright, the one turned away gets 0.15 + 0.85 cos(85 deg) of it (4.4x
// dimmer, its paper at ~50 of 255), the middle one between.
RenderOptions SideLight() {
  RenderOptions o;
  o.blur_sigma_px = 0.6;
  o.noise_sigma = 1.5;
  o.light_in_rig =
      Eigen::Vector3d(std::sin(50 * M_PI / 180), 0, std::cos(50 * M_PI / 180));
  o.ambient = 0.15;
  return o;
}

TEST(TrackUnderRealLight, ABadlyLitTagCostsThatTagNotTheFrame) {
  struct LightScene {
    std::string name;
    RenderOptions render;
  };
  std::vector<LightScene> scenes;
  scenes.push_back({"side light, tags 1.4-4.4x apart", SideLight()});
  LightScene shadow{"side light + a shadow edge across the middle tag",
                    SideLight()};
  shadow.render.shadow_tag = 1;
  shadow.render.shadow_angle_deg = 30;
  shadow.render.shadow_offset = 0.1;
  scenes.push_back(shadow);
  LightScene bayer{"side light, Bayer sensor (demosaiced)", SideLight()};
  bayer.render.bayer = true;
  scenes.push_back(bayer);
  std::vector<double> rms;
  for (const LightScene& scene : scenes) {
    const LightErrors e = RunLightScene(scene.render, 24, 77);
    const double worst =
        e.good_tips.empty()
            ? 0.0
            : *std::max_element(e.good_tips.begin(), e.good_tips.end());
    rms.push_back(Rms(e.good_tips));
    std::printf(
        "%-50s frames %2d good %2d | tip RMS of good tips %.4f mm (worst "
        "%.4f), plain corners + triangulation + rigid fit %.4f mm on %zu\n",
        scene.name.c_str(), e.frames, e.good, Rms(e.good_tips), worst,
        Rms(e.plain_tri), e.plain_tri.size());
    EXPECT_GE(e.good, 0.95 * e.frames) << scene.name;
    EXPECT_LE(Rms(e.good_tips), Rms(e.plain_tri)) << scene.name;
    // No tip written as a measurement far off: within 5 sigma, sigma the
    // good tips' own RMS.
    EXPECT_LE(worst, 5 * Rms(e.good_tips)) << scene.name;
  }
  // Same poses: the colour sensor against gray, within issue 21's 1.3x.
  std::printf("Bayer / gray tip RMS: %.2f\n", rms[2] / rms[0]);
  EXPECT_LE(rms[2], 1.3 * rms[0]);
}

}  // namespace
}  // namespace kincal
