#include "synth/render.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "data/atomic_file.h"
#include "data/error.h"
#include "tests/testing/paths.h"
#include "vision/apriltag_detector.h"

namespace kincal {
namespace {

// Mean over matched corners of |detected - truth|^2, per corner (px^2).
struct CornerStats {
  double sum_sq = 0;
  double worst = 0;
  int n = 0;
  int tags_expected = 0;
  int tags_found = 0;
  double Rms() const { return n ? std::sqrt(sum_sq / n) : 0; }
};

void Accumulate(const std::vector<TagDetection>& dets,
                const std::vector<TagTruth>& truth, CornerStats* s) {
  for (const TagTruth& t : truth) {
    if (!t.visible) continue;
    ++s->tags_expected;
    for (const TagDetection& d : dets) {
      if (d.id != t.id) continue;
      ++s->tags_found;
      for (int k = 0; k < 4; ++k) {
        const double e = (d.corners[k] - t.corners[k]).norm();
        s->sum_sq += e * e;
        s->worst = std::max(s->worst, e);
        ++s->n;
      }
    }
  }
}

// A fronto-parallel tag through an undistorted camera: detection ids and
// corner order agree with the tag frame (corner 0 = bottom-left ...).
TEST(Render, CornerOrderMatchesTagFrame) {
  Camera cam;
  cam.intrinsics = {"c", 320, 240, 500, 500, 159.5, 119.5, {}};
  Target target;
  TargetTag tag;
  tag.id = 11;
  tag.size_mm = 40;
  target.tags.push_back(tag);
  Rigid3 rig_from_tool;
  rig_from_tool.t = Eigen::Vector3d(3, -2, 300);
  ViewRenderer renderer(cam);
  RenderOptions o;
  std::mt19937_64 rng(1);
  const cv::Mat image =
      renderer.Render(TargetPlanes(target, rig_from_tool), {}, o, &rng);
  const auto truth = ProjectTargetCorners(cam, target, rig_from_tool);
  ASSERT_TRUE(truth[0].visible);
  // Upright: corner 0 bottom-left, 2 top-right.
  EXPECT_LT(truth[0].corners[0].x(), truth[0].corners[2].x());
  EXPECT_GT(truth[0].corners[0].y(), truth[0].corners[2].y());
  AprilTagDetector detector;
  const auto dets = detector.Detect(image);
  ASSERT_EQ(dets.size(), 1u);
  EXPECT_EQ(dets[0].id, 11);
  for (int k = 0; k < 4; ++k) {
    EXPECT_LT((dets[0].corners[k] - truth[0].corners[k]).norm(), 0.05)
        << "corner " << k << " " << dets[0].corners[k].transpose() << " vs "
        << truth[0].corners[k].transpose();
  }
  // The white border: pixels just outside the black square are bright.
  const Eigen::Vector2d out = truth[0].corners[3] - Eigen::Vector2d(3, 3);
  EXPECT_GT(
      image.at<uint8_t>(static_cast<int>(out.y()), static_cast<int>(out.x())),
      200);
}

// Clean renders of the example rig (distorted cameras, slanted tags):
// detected corners within 0.1 px RMS of the truth.
TEST(Render, CleanRenderCornerRmsBelowTenthPixel) {
  const Rig rig = ExampleStereoRig(640, 512);
  const Target target = ExampleTarget();
  RenderOptions o;
  o.blur_sigma_px = 0.5;  // a sharp lens
  StereoRenderer renderer(rig, target, o);
  AprilTagDetector detector;
  AprilTagOptions none_options;
  none_options.refinement = CornerRefinement::kNone;
  AprilTagDetector raw(none_options);
  CornerStats edges, libapriltag;
  std::mt19937_64 rng(3);
  for (int i = 0; i < 3; ++i) {
    const StereoFrameTruth frame = renderer.Render(ExampleToolPose(i), &rng);
    for (const ViewTruth& v : frame.views) {
      Accumulate(detector.Detect(v.image), v.tags, &edges);
      Accumulate(raw.Detect(v.image), v.tags, &libapriltag);
    }
  }
  std::printf("corner RMS: edges %.4f px (worst %.4f), libapriltag %.4f px\n",
              edges.Rms(), edges.worst, libapriltag.Rms());
  EXPECT_EQ(edges.tags_found, edges.tags_expected);
  EXPECT_GE(edges.tags_expected, 20);
  EXPECT_LE(edges.Rms(), 0.1);
  EXPECT_LE(edges.worst, 0.3);
}

// With noise, blur and exposure changes, every tag is still found and the
// corners stay well below a pixel.
TEST(Render, NoisyRenderStillDetected) {
  const Rig rig = ExampleStereoRig(640, 512);
  const Target target = ExampleTarget();
  RenderOptions o;
  o.blur_sigma_px = 0.9;
  o.noise_sigma = 3.0;
  o.exposure_jitter = 0.15;
  o.draw_needle = true;
  o.needle_base_in_tool = Eigen::Vector3d(0, 35, 10);
  StereoRenderer renderer(rig, target, o);
  AprilTagDetector detector;
  CornerStats s;
  std::mt19937_64 rng(5);
  const StereoFrameTruth frame = renderer.Render(ExampleToolPose(1), &rng);
  for (const ViewTruth& v : frame.views) {
    Accumulate(detector.Detect(v.image), v.tags, &s);
    // The needle tip is drawn: bright pixels near its projection.
    const cv::Point tip(static_cast<int>(std::lround(v.tip_px.x())),
                        static_cast<int>(std::lround(v.tip_px.y())));
    const cv::Point inward(static_cast<int>(std::lround(v.tip_px.x() + 0.0)),
                           tip.y - 3);
    EXPECT_GT(v.image.at<uint8_t>(inward), 140) << "needle not drawn";
  }
  EXPECT_EQ(s.tags_found, s.tags_expected);
  EXPECT_LT(s.Rms(), 0.25);
}

// Mean gray level inside tag `t`'s quad shrunk towards its centre by
// `shrink` (0..1), and whether that part is mostly white paper is not
// asked: the ratio of two tags' means compares their light.
double MeanInQuad(const cv::Mat& image, const TagTruth& t, double shrink) {
  Eigen::Vector2d c = Eigen::Vector2d::Zero();
  for (const auto& p : t.corners) c += p / 4;
  std::vector<cv::Point> poly;
  for (const auto& p : t.corners) {
    const Eigen::Vector2d q = c + shrink * (p - c);
    poly.emplace_back(static_cast<int>(q.x()), static_cast<int>(q.y()));
  }
  cv::Mat mask(image.size(), CV_8UC1, cv::Scalar(0));
  cv::fillConvexPoly(mask, poly, cv::Scalar(255));
  return cv::mean(image, mask)[0];
}

// A distant light: a tag turned away from it is dimmer by the Lambert
// factor, and the tag gains and a shadow edge change only the lit tag.
TEST(Render, LightOnTagsFollowsLambertAndShadow) {
  const Target target = ExampleTarget();  // two faces folded by +-20 deg
  RenderOptions o;
  o.light_in_rig = Eigen::Vector3d(1, 0, 1);  // 45 deg from the view axis
  o.ambient = 0.1;
  std::vector<TexturedPlane> planes = TargetPlanes(target, ExampleToolPose(0));
  LightTags(o, target, &planes);
  const Eigen::Vector3d l = o.light_in_rig.normalized();
  for (size_t i = 0; i < planes.size(); ++i) {
    const double cos = std::max(0.0, planes[i].rig_from_plane.R.col(2).dot(l));
    EXPECT_NEAR(planes[i].light.gain, 0.1 + 0.9 * cos, 1e-12);
  }
  o.tag_gain = {2.0};
  o.shadow_tag = 1;
  o.shadow_gain = 0.3;
  std::vector<TexturedPlane> lit = TargetPlanes(target, ExampleToolPose(0));
  LightTags(o, target, &lit);
  EXPECT_NEAR(lit[0].light.gain, 2.0 * planes[0].light.gain, 1e-12);
  EXPECT_EQ(lit[1].light.shadow_gain, 0.3);
  EXPECT_EQ(lit[2].light.shadow_gain, 1.0);

  // In the image: the shadowed half of tag 1 is darker than its lit half.
  const Rig rig = ExampleStereoRig(640, 512);
  RenderOptions shadow;
  shadow.shadow_tag = 1;
  shadow.shadow_gain = 0.3;
  shadow.shadow_angle_deg = 0;  // the +x half of the tag is in shadow
  StereoRenderer renderer(rig, target, shadow);
  std::mt19937_64 rng(1);
  const StereoFrameTruth f = renderer.Render(ExampleToolPose(0), &rng);
  RenderOptions even;
  StereoRenderer plain(rig, target, even);
  const StereoFrameTruth g = plain.Render(ExampleToolPose(0), &rng);
  const TagTruth& t = f.views[0].tags[1];
  EXPECT_LT(MeanInQuad(f.views[0].image, t, 0.9),
            0.9 * MeanInQuad(g.views[0].image, t, 0.9));
  EXPECT_NEAR(MeanInQuad(f.views[0].image, f.views[0].tags[0], 0.9),
              MeanInQuad(g.views[0].image, g.views[0].tags[0], 0.9), 0.5);
}

// A demosaiced Bayer render's checks: flat gray paper at OpenCV's gray
// weights of the channel gains, every tag found, corners within 0.15 px.
void ExpectFlatGrayAndTagsFound(const StereoFrameTruth& f,
                                const RenderOptions& o) {
  const cv::Mat& im = f.views[0].image;
  const double want =
      o.background * (0.299 * o.bayer_gains[0] + 0.587 * o.bayer_gains[1] +
                      0.114 * o.bayer_gains[2]);
  EXPECT_NEAR(im.at<uint8_t>(5, 5), want, 1.5);
  EXPECT_NEAR(im.at<uint8_t>(6, 6), want, 1.5);
  AprilTagDetector detector;
  CornerStats s;
  for (const ViewTruth& v : f.views)
    Accumulate(detector.Detect(v.image), v.tags, &s);
  EXPECT_EQ(s.tags_found, s.tags_expected);
  EXPECT_LT(s.Rms(), 0.15);
}

// A colour sensor: the demosaiced gray of a flat gray scene is flat, at
// OpenCV's gray weights of the channel gains; tags are still found.
TEST(Render, BayerSensorDemosaicsToGray) {
  const Rig rig = ExampleStereoRig(640, 512);
  RenderOptions o;
  o.bayer = true;
  o.blur_sigma_px = 0.6;
  StereoRenderer renderer(rig, ExampleTarget(), o);
  std::mt19937_64 rng(2);
  ExpectFlatGrayAndTagsFound(renderer.Render(ExampleToolPose(0), &rng), o);
}

// The other demosaics (VNG, edge-aware, to colour then to gray): flat gray
// paper at the same gray weights, the tags found, and images that differ
// from the bilinear one (each driver's demosaic is its own).
TEST(Render, BayerSensorOtherDemosaics) {
  const Rig rig = ExampleStereoRig(640, 512);
  RenderOptions o;
  o.bayer = true;
  o.blur_sigma_px = 0.6;
  std::mt19937_64 rng0(2);
  const cv::Mat bilinear = StereoRenderer(rig, ExampleTarget(), o)
                               .Render(ExampleToolPose(0), &rng0)
                               .views[0]
                               .image;
  for (const auto d :
       {RenderOptions::Demosaic::kVng, RenderOptions::Demosaic::kEdgeAware}) {
    o.demosaic = d;
    StereoRenderer renderer(rig, ExampleTarget(), o);
    std::mt19937_64 rng(2);
    const StereoFrameTruth f = renderer.Render(ExampleToolPose(0), &rng);
    ExpectFlatGrayAndTagsFound(f, o);
    EXPECT_GT(cv::norm(f.views[0].image, bilinear, cv::NORM_L1), 1000.0);
  }
}

// The raw mosaic (bayer_raw): each photosite of flat gray paper carries its
// channel's gain (RGGB: R at even x and y, B at odd x and y).
TEST(Render, BayerRawWritesTheMosaic) {
  const Rig rig = ExampleStereoRig(320, 256);
  RenderOptions o;
  o.bayer = true;
  o.bayer_raw = true;
  StereoRenderer renderer(rig, ExampleTarget(), o);
  std::mt19937_64 rng(2);
  const StereoFrameTruth f = renderer.Render(ExampleToolPose(0), &rng);
  const cv::Mat& im = f.views[0].image;
  EXPECT_NEAR(im.at<uint8_t>(4, 4), o.background * o.bayer_gains[0], 0.6);
  EXPECT_NEAR(im.at<uint8_t>(4, 5), o.background * o.bayer_gains[1], 0.6);
  EXPECT_NEAR(im.at<uint8_t>(5, 4), o.background * o.bayer_gains[1], 0.6);
  EXPECT_NEAR(im.at<uint8_t>(5, 5), o.background * o.bayer_gains[2], 0.6);
  RenderOptions raw_alone;
  raw_alone.bayer_raw = true;
  EXPECT_THROW(raw_alone.Check(), InputError);
}

TEST(Render, SameSeedSameImages) {
  const Rig rig = ExampleStereoRig(320, 256);
  RenderOptions o;
  o.noise_sigma = 2;
  StereoRenderer renderer(rig, ExampleTarget(), o);
  std::mt19937_64 a(9), b(9);
  const auto fa = renderer.Render(ExampleToolPose(0), &a);
  const auto fb = renderer.Render(ExampleToolPose(0), &b);
  EXPECT_EQ(cv::norm(fa.views[0].image, fb.views[0].image, cv::NORM_INF), 0);
}

TEST(Render, AprilGridAllTagsDetected) {
  Camera cam;
  cam.intrinsics = {"c", 640,   512,   700,
                    700, 319.5, 255.5, {-0.05, 0.01, 0, 0, 0}};
  AprilGrid grid;
  grid.cols = 5;
  grid.rows = 4;
  grid.tag_size_mm = 30;
  Rigid3 rig_from_board;
  rig_from_board.R =
      Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 0.5, 0).normalized())
          .toRotationMatrix();
  rig_from_board.t = Eigen::Vector3d(-90, -70, 450);
  for (bool squares : {false, true}) {
    grid.corner_squares = squares;
    ViewRenderer renderer(cam);
    RenderOptions o;
    o.blur_sigma_px = 0.6;
    std::mt19937_64 rng(1);
    const cv::Mat image =
        renderer.Render(grid.Planes(rig_from_board), {}, o, &rng);
    AprilTagDetector detector;
    const auto dets = detector.Detect(image);
    const std::vector<TagTruth> truth =
        ProjectTargetCorners(cam, grid.AsTarget(), rig_from_board);
    CornerStats s;
    Accumulate(dets, truth, &s);
    EXPECT_EQ(s.tags_expected, 20) << "corner squares " << squares;
    // libapriltag segments a tag touching Kalibr's corner squares with them:
    // it loses some tags (4 of 20 here) and may fit a corner of another one
    // to a corner square (tag 9 here, 5.6 px off, since the ids follow
    // Kalibr's bottom-left-first numbering); without the squares it finds
    // all, exactly.
    EXPECT_GE(s.tags_found, squares ? 12 : 20) << "corner squares " << squares;
    if (!squares) {
      EXPECT_LT(s.Rms(), 0.1);
      continue;
    }
    int accurate = 0;  // tags with all four corners within 0.1 px (15 here)
    for (const TagTruth& t : truth) {
      CornerStats one;
      Accumulate(dets, {t}, &one);
      accurate += one.tags_found == 1 && one.worst < 0.1;
    }
    EXPECT_GE(accurate, 12);
  }
}

TEST(Render, SessionWritesImagesAndTruth) {
  const std::string dir = testing::MakeTempDir("render_session") + "/s";
  const Rig rig = ExampleStereoRig(320, 256);
  const std::vector<Rigid3> poses = {ExampleToolPose(0), ExampleToolPose(1)};
  EXPECT_EQ(RenderSession(rig, ExampleTarget(), poses, RenderOptions(), 7, dir),
            2);
  for (const char* f : {"left_000000.png", "right_000001.png", "truth.csv",
                        "corners.csv", "rig.yaml", "target.yaml"}) {
    EXPECT_TRUE(testing::Exists(dir + "/" + f)) << f;
  }
  const cv::Mat im = cv::imread(dir + "/left_000001.png", cv::IMREAD_UNCHANGED);
  EXPECT_EQ(im.cols, 320);
  EXPECT_EQ(im.type(), CV_8UC1);
  const std::string truth = ReadFile(dir + "/truth.csv");
  EXPECT_NE(truth.find("# seed 7"), std::string::npos);
  EXPECT_NE(truth.find("frame,r00"), std::string::npos);
}

// A camera's optics blur the light before its pixels integrate it: across a
// straight black-white edge at x_e, pixel i reads
//   v(i) = B + (W - B) integral_{i-1/2}^{i+1/2} Phi((u - x_e) / sigma) du
//        = B + (W - B) sigma (G((i + 1/2 - x_e) / sigma)
//                              - G((i - 1/2 - x_e) / sigma)),
// G(x) = x Phi(x) + phi(x). The renderer's fine optics give that within the
// 8-bit rounding; blurring the pixel-integrated image instead (a 0.5 px
// sigma sampled on pixels: taps 0.107 / 0.786 / 0.107) does not.
TEST(Render, BlursTheLightBeforeThePixelsIntegrateIt) {
  Camera cam;
  cam.intrinsics.name = "edge";
  cam.intrinsics.width = 64;
  cam.intrinsics.height = 32;
  cam.intrinsics.fx = cam.intrinsics.fy = 100;
  cam.intrinsics.cx = 31.5;
  cam.intrinsics.cy = 15.5;
  cam.intrinsics.distortion = {0, 0, 0, 0, 0};
  const ViewRenderer renderer(cam);
  TexturedPlane plane;
  plane.texture = (cv::Mat_<uint8_t>(1, 2) << 0, 255);
  plane.top_left_mm = Eigen::Vector2d(-50, -50);
  plane.size_mm = Eigen::Vector2d(100, 100);
  const double z = 100, shift_mm = 0.23;
  plane.rig_from_plane.t = Eigen::Vector3d(shift_mm, 0, z);
  const double x_e = cam.intrinsics.cx + cam.intrinsics.fx * shift_mm / z;
  const auto G = [](double x) {
    return x * 0.5 * std::erfc(-x / std::sqrt(2.0)) +
           std::exp(-0.5 * x * x) / std::sqrt(2 * M_PI);
  };
  for (const double sigma : {0.5, 0.8, 1.5}) {
    RenderOptions o;
    o.blur_sigma_px = sigma;
    std::mt19937_64 rng(1);
    double worst_fine = 0, worst_pixels = 0;
    for (const bool fine : {true, false}) {
      o.fine_optics = fine;
      const cv::Mat image = renderer.Render({plane}, {}, o, &rng);
      for (int i = 24; i < 40; ++i) {
        const double esf =
            sigma * (G((i + 0.5 - x_e) / sigma) - G((i - 0.5 - x_e) / sigma));
        const double expected = o.black + (o.white - o.black) * esf;
        const double e = std::abs(image.at<uint8_t>(16, i) - expected);
        (fine ? worst_fine : worst_pixels) =
            std::max(fine ? worst_fine : worst_pixels, e);
      }
    }
    std::printf(
        "sigma %.1f px: worst |image - optics| %.2f gray (blur on "
        "the pixels: %.2f)\n",
        sigma, worst_fine, worst_pixels);
    EXPECT_LT(worst_fine, 0.75) << sigma;
    if (sigma < 1) {
      EXPECT_GT(worst_pixels, 2.0) << sigma;
    }
  }
}

TEST(Render, RejectsBadOptions) {
  RenderOptions o;
  o.noise_sigma = -1;
  EXPECT_THROW(o.Check(), InputError);
  Camera cam;  // no size
  EXPECT_THROW(ViewRenderer r(cam), InputError);
}

}  // namespace
}  // namespace kincal
