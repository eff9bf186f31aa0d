// A tag's refined corners must not make the tag look smaller or larger than
// it is. A shift of every side towards the tag's centre (a tag-scale bias)
// averages out in no pose fit: on a stand rig it trades against the
// baseline and becomes link-length error (BH-7 stereo render: a -0.008 px
// mean inward shift of the corners put the bundle's robot at 0.084 mm at
// fresh poses; with the corners unbiased, 0.052). Single tags are rendered
// at random tilts with several blurs (Gaussian and disk PSFs) and sizes,
// noise-free so that only the bias is measured, and the corners' mean shift
// along the direction from the tag's centre is held to a few thousandths
// of a pixel.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

#include "synth/render.h"
#include "vision/apriltag_detector.h"
#include "vision/bayer.h"

namespace kincal {
namespace {

struct ScaleBias {
  double mean_radial_px = 0;  // mean corner shift away from the centre
  double rms_px = 0;
  int corners = 0;
};

// Tag `size_mm` at `distance_mm` in front of a distortion-free 640x512
// camera (f = 900 px), tilted up to ~29 deg, 30 views. With `raw`, the
// images are raw mosaics balanced to gray before detection.
ScaleBias MeasureScaleBias(double size_mm, double distance_mm,
                           const RenderOptions& options,
                           const AprilTagOptions& detector_options = {},
                           BayerPattern raw = BayerPattern::kNone) {
  Camera cam;
  cam.intrinsics.name = "c";
  cam.intrinsics.width = 640;
  cam.intrinsics.height = 512;
  cam.intrinsics.fx = cam.intrinsics.fy = 900;
  cam.intrinsics.cx = 319.5;
  cam.intrinsics.cy = 255.5;
  cam.intrinsics.distortion = {0, 0, 0, 0, 0};
  Target target;
  TargetTag tag;
  tag.id = 3;
  tag.size_mm = size_mm;
  target.tags.push_back(tag);
  const ViewRenderer renderer(cam);
  AprilTagDetector detector(detector_options);
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-1, 1);
  ScaleBias out;
  double sum_radial = 0, sum_sq = 0;
  for (int view = 0; view < 30; ++view) {
    Rigid3 pose;
    const Eigen::Vector3d axis(u(rng), u(rng), 0.2 * u(rng));
    pose.R = Eigen::AngleAxisd(0.5 * std::abs(u(rng)), axis.normalized())
                 .toRotationMatrix();
    pose.t = Eigen::Vector3d(30 * u(rng), 30 * u(rng), distance_mm);
    const cv::Mat image = BalanceBayerMosaic(
        renderer.Render(TargetPlanes(target, pose), {}, options, &rng), raw);
    const TagTruth truth = ProjectTargetCorners(cam, target, pose)[0];
    const Eigen::Vector2d centre = (truth.corners[0] + truth.corners[1] +
                                    truth.corners[2] + truth.corners[3]) /
                                   4;
    for (const TagDetection& d : detector.Detect(image)) {
      for (int k = 0; k < 4; ++k) {
        if (!d.usable[k]) continue;
        const Eigen::Vector2d e = d.corners[k] - truth.corners[k];
        sum_radial += e.dot((truth.corners[k] - centre).normalized());
        sum_sq += e.squaredNorm();
        ++out.corners;
      }
    }
  }
  if (out.corners > 0) {
    out.mean_radial_px = sum_radial / out.corners;
    out.rms_px = std::sqrt(sum_sq / out.corners);
  }
  return out;
}

TEST(CornerScale, RefinedCornersKeepTheTagsSizeUnderBlur) {
  struct Case {
    const char* name;
    double distance_mm;  // 40 mm tag: 600 -> ~59 px, 1000 -> ~35 px
    double blur_sigma_px;
    double defocus_px;
    double max_bias_px;
  };
  // Measured before this check (main at ebecb7e), mean radial px: -0.0046,
  // -0.0079, -0.0245, -0.0105, +0.0033. After: -0.0025, -0.0006, -0.0168,
  // -0.0015, +0.0061. Wide blur on small cells (35 px, sigma 1.5 px: 4.4
  // px cells) and a disk PSF the Gaussian model does not have remain the
  // limits, bounded more loosely.
  const Case cases[] = {
      {"35 px, sharp (area rule)", 1000, 0.5, 0, 0.004},
      {"35 px, Gaussian 1.0 px", 1000, 1.0, 0, 0.004},
      {"35 px, Gaussian 1.5 px", 1000, 1.5, 0, 0.02},
      {"59 px, Gaussian 1.5 px", 600, 1.5, 0, 0.004},
      {"35 px, disk 1.5 px", 1000, 0, 1.5, 0.01},
  };
  for (const Case& c : cases) {
    RenderOptions options;
    options.blur_sigma_px = c.blur_sigma_px;
    options.defocus_px = c.defocus_px;
    const ScaleBias b = MeasureScaleBias(40, c.distance_mm, options);
    std::printf("%-28s corners %3d  rms %.4f px  mean radial %+.4f px\n",
                c.name, b.corners, b.rms_px, b.mean_radial_px);
    ASSERT_GE(b.corners, 100) << c.name;
    EXPECT_LT(std::abs(b.mean_radial_px), c.max_bias_px) << c.name;
  }
}

// A colour camera's demosaiced image (RGGB mosaic, channel gains for gray
// paper 0.55 / 1 / 0.75, OpenCV's bilinear Bayer to gray) blurs its four
// pixel phases differently. The refinement finds this from the image and
// fits the bilinear demosaic's kernels (vision/demosaic_model.h) at pixel
// centres; a blur per phase (fit_demosaic off, the refinement before the
// model) is off by more on small tags, and read through interpolation
// with one blur (the phase check off), the corners scatter about twice as
// much, and the tag's size with them.
TEST(CornerScale, DemosaicedBayerCornersAsGoodAsGray) {
  RenderOptions gray;
  gray.blur_sigma_px = 0.5;
  gray.noise_sigma = 1.5;
  RenderOptions bayer = gray;
  bayer.bayer = true;
  AprilTagOptions one_blur;
  one_blur.demosaiced_ratio = 1e9;
  AprilTagOptions per_phase;
  per_phase.fit_demosaic = false;
  for (const double distance_mm : {600.0, 1000.0}) {
    const ScaleBias g = MeasureScaleBias(40, distance_mm, gray);
    const ScaleBias b = MeasureScaleBias(40, distance_mm, bayer);
    const ScaleBias phase = MeasureScaleBias(40, distance_mm, bayer, per_phase);
    const ScaleBias old = MeasureScaleBias(40, distance_mm, bayer, one_blur);
    std::printf(
        "%4.0f mm: gray rms %.4f radial %+.4f | Bayer rms %.4f radial %+.4f "
        "| blur per phase rms %.4f radial %+.4f | one blur: rms %.4f radial "
        "%+.4f px\n",
        distance_mm, g.rms_px, g.mean_radial_px, b.rms_px, b.mean_radial_px,
        phase.rms_px, phase.mean_radial_px, old.rms_px, old.mean_radial_px);
    // Measured (noise 1.5, blur 0.5): 59 px tags gray 0.0170, Bayer 0.0139,
    // blur per phase 0.0180, one blur 0.0250 px; 35 px tags 0.0214,
    // 0.0238, 0.0304, 0.0479 px.
    ASSERT_GE(b.corners, 100);
    EXPECT_LT(b.rms_px, 1.15 * g.rms_px) << distance_mm << " mm";
    EXPECT_LT(b.rms_px, 0.9 * phase.rms_px) << distance_mm << " mm";
    EXPECT_LT(b.rms_px, 0.85 * old.rms_px) << distance_mm << " mm";
    EXPECT_LT(std::abs(b.mean_radial_px), 0.006) << distance_mm << " mm";
  }
}

// Demosaics the bilinear model does not describe (OpenCV's VNG and
// edge-aware, to colour then to gray): the model must not make them worse
// than the blur per phase (it is taken only where it fits the image's
// profiles better).
TEST(CornerScale, OtherDemosaicsNoWorseThanBlurPerPhase) {
  RenderOptions bayer;
  bayer.blur_sigma_px = 0.5;
  bayer.noise_sigma = 1.5;
  bayer.bayer = true;
  AprilTagOptions per_phase;
  per_phase.fit_demosaic = false;
  for (const auto d :
       {RenderOptions::Demosaic::kVng, RenderOptions::Demosaic::kEdgeAware}) {
    bayer.demosaic = d;
    const ScaleBias b = MeasureScaleBias(40, 1000, bayer);
    const ScaleBias phase = MeasureScaleBias(40, 1000, bayer, per_phase);
    std::printf(
        "%s, 35 px: rms %.4f radial %+.4f | blur per phase rms %.4f "
        "radial %+.4f px\n",
        d == RenderOptions::Demosaic::kVng ? "VNG" : "edge-aware", b.rms_px,
        b.mean_radial_px, phase.rms_px, phase.mean_radial_px);
    ASSERT_GE(b.corners, 100);
    EXPECT_LT(b.rms_px, 1.02 * phase.rms_px);
  }
}

// The same colour sensor read raw (the mosaic a camera delivers in its
// BayerRG8 format): each phase balanced to gray from the image, no
// demosaic. Its corners follow the gray render's up to the noise of the
// dimmer red and blue photosites (balanced, their noise is 1.8x and 1.3x
// green's; a demosaic averages it down, so the demosaiced image, refined
// with the demosaic's model, is as good or better), and the unbalanced
// mosaic read as gray is far worse. Measured (noise 1.5, blur 0.5): 59 px
// tags gray 0.0170, raw 0.0224, demosaiced 0.0139, unbalanced 0.0480 px;
// 35 px tags 0.0214, 0.0247, 0.0238, 0.1094 px.
TEST(CornerScale, RawBayerCornersAsGoodAsGray) {
  RenderOptions gray;
  gray.blur_sigma_px = 0.5;
  gray.noise_sigma = 1.5;
  RenderOptions demosaiced = gray;
  demosaiced.bayer = true;
  RenderOptions raw = demosaiced;
  raw.bayer_raw = true;
  for (const double distance_mm : {600.0, 1000.0}) {
    const ScaleBias g = MeasureScaleBias(40, distance_mm, gray);
    const ScaleBias d = MeasureScaleBias(40, distance_mm, demosaiced);
    const ScaleBias r =
        MeasureScaleBias(40, distance_mm, raw, {}, BayerPattern::kRggb);
    const ScaleBias unbalanced = MeasureScaleBias(40, distance_mm, raw);
    std::printf(
        "%4.0f mm: gray rms %.4f radial %+.4f | raw, balanced rms %.4f "
        "radial %+.4f | demosaiced rms %.4f | raw read as gray rms %.4f (%d "
        "corners) px\n",
        distance_mm, g.rms_px, g.mean_radial_px, r.rms_px, r.mean_radial_px,
        d.rms_px, unbalanced.rms_px, unbalanced.corners);
    ASSERT_GE(r.corners, 100);
    EXPECT_LT(r.rms_px, 1.4 * g.rms_px) << distance_mm << " mm";
    EXPECT_LT(r.rms_px, 0.5 * unbalanced.rms_px) << distance_mm << " mm";
    EXPECT_LT(std::abs(r.mean_radial_px), 0.006) << distance_mm << " mm";
  }
}

}  // namespace
}  // namespace kincal
