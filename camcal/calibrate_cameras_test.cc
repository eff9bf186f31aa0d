#include "camcal/calibrate_cameras.h"

#include <gtest/gtest.h>

#include <fstream>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <random>
#include <sstream>

#include "camcal/board_warp.h"
#include "data/error.h"
#include "tests/testing/paths.h"

namespace kincal {
namespace {

// ---------------------------------------------------------------- synthetic

std::vector<Eigen::Vector3d> Board(int cols, int rows, double square) {
  std::vector<Eigen::Vector3d> pts;
  for (int j = 0; j < rows; ++j) {
    for (int i = 0; i < cols; ++i) pts.emplace_back(i * square, j * square, 0);
  }
  return pts;
}

struct Synthetic {
  CalibrationProblem problem;
  Rig truth;
};

// A stereo rig (baseline 120 mm) looking at a 10x7 board (30 mm squares) from
// random poses, pixel noise sigma `noise_px`, seeded; the board deflected by
// `warp` (camcal/board_warp.h, mm; the problem's target points stay flat).
Synthetic MakeSynthetic(int num_cameras, int num_views, double noise_px,
                        uint64_t seed, std::array<double, 2> warp = {0, 0}) {
  Synthetic s;
  for (int c = 0; c < num_cameras; ++c) {
    Camera cam;
    cam.intrinsics = {c == 0   ? "left"
                      : c == 1 ? "right"
                               : "c" + std::to_string(c),
                      1280,
                      1024,
                      1800.0 + 10 * c,
                      1795.0 + 10 * c,
                      641.0 - 5 * c,
                      509.0 + 3 * c,
                      {-0.12, 0.09, 0.0007, -0.0004, 0.0}};
    if (c == 1) {
      cam.cam_from_rig.R =
          Eigen::AngleAxisd(-0.08, Eigen::Vector3d::UnitY()).toRotationMatrix();
      cam.cam_from_rig.t = Eigen::Vector3d(-120, 0.8, 1.5);
    }
    if (c == 2) {
      // Centre at (200, -1, 5) in rig, turned 0.16 rad towards -x (the
      // board's side).
      cam.cam_from_rig.R =
          Eigen::AngleAxisd(0.16, Eigen::Vector3d::UnitY()).toRotationMatrix();
      cam.cam_from_rig.t = -(cam.cam_from_rig.R * Eigen::Vector3d(200, -1, 5));
    }
    s.truth.cameras.push_back(cam);
    s.problem.cameras.push_back(cam.intrinsics);
  }
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> angle(-0.5, 0.5);
  std::uniform_real_distribution<double> shift(-80, 80);
  std::uniform_real_distribution<double> depth(600, 1100);
  std::normal_distribution<double> noise(0.0, noise_px);
  const std::vector<Eigen::Vector3d> board = Board(10, 7, 30.0);
  const BoardExtent extent = BoardExtent::Of(board);
  while (static_cast<int>(s.problem.views.size()) < num_views) {
    Rigid3 rig_from_target;
    rig_from_target.R =
        (Eigen::AngleAxisd(angle(rng), Eigen::Vector3d::UnitX()) *
         Eigen::AngleAxisd(angle(rng), Eigen::Vector3d::UnitY()) *
         Eigen::AngleAxisd(angle(rng) * 0.5, Eigen::Vector3d::UnitZ()))
            .toRotationMatrix();
    // Board centre at (shift, shift, depth) in the middle of the two cameras.
    const Eigen::Vector3d centre(135, 90, 0);
    rig_from_target.t =
        Eigen::Vector3d(60 + shift(rng), shift(rng), depth(rng)) -
        rig_from_target.R * centre;
    CalibrationView view;
    view.label = "view" + std::to_string(s.problem.views.size());
    bool all_inside = true;
    for (const Camera& cam : s.truth.cameras) {
      TargetObservation obs;
      for (const Eigen::Vector3d& p : board) {
        const Eigen::Vector2d px = Project(
            cam.intrinsics,
            cam.cam_from_rig *
                (rig_from_target * WarpedPoint(p, extent, warp.data())));
        all_inside = all_inside && px.x() > 0 && px.y() > 0 &&
                     px.x() < cam.intrinsics.width - 1 &&
                     px.y() < cam.intrinsics.height - 1;
        obs.p_in_target.push_back(p);
        obs.pixels.push_back(px + Eigen::Vector2d(noise(rng), noise(rng)));
      }
      view.observations.push_back(obs);
    }
    if (all_inside) s.problem.views.push_back(view);
  }
  return s;
}

TEST(CalibrateCameras, SyntheticStereoRecoversRigWithinSigma) {
  const double noise_px = 0.3;
  const Synthetic syn = MakeSynthetic(2, 16, noise_px, 7);
  const CalibrationSummary sum = CalibrateCameras(syn.problem);
  EXPECT_TRUE(sum.converged) << sum.termination;
  ASSERT_EQ(sum.cameras.size(), 2u);
  // Residual per coordinate ~ the noise.
  EXPECT_NEAR(sum.residual_sigma_px, noise_px, 0.05);
  for (int c = 0; c < 2; ++c) {
    const CameraCalibrationSummary& cs = sum.cameras[c];
    const auto est = cs.intrinsics.ToArray();
    const auto truth = syn.truth.cameras[c].intrinsics.ToArray();
    ASSERT_EQ(cs.sigma.size(), static_cast<size_t>(kNumIntrinsics));
    for (int i = 0; i < kK1 + 5; ++i) {
      EXPECT_GT(cs.sigma[i], 0) << "camera " << c << " parameter " << i;
      EXPECT_LT(std::abs(est[i] - truth[i]), 4 * cs.sigma[i])
          << "camera " << c << " parameter " << i << ": " << est[i] << " vs "
          << truth[i] << " sigma " << cs.sigma[i];
    }
    EXPECT_EQ(cs.sigma[kK4], 0.0);  // not in the model
    EXPECT_EQ(cs.num_views, 16);
    // 4-sigma rejection takes hardly any Gaussian corner (< 1 %).
    EXPECT_EQ(cs.num_points + cs.rejected_corners, 16 * 70);
    EXPECT_LE(cs.rejected_corners, 16 * 70 / 100);
    // Held-out reprojection: noise plus a little for the fitted pose.
    EXPECT_GT(cs.holdout_rms_px, 0.9 * noise_px * std::sqrt(2.0) * 0.9);
    EXPECT_LT(cs.holdout_rms_px, 1.3 * noise_px * std::sqrt(2.0));
    EXPECT_LT(cs.half_diff_rms_px, 3.0);
    EXPECT_EQ(cs.outliers, 0);
  }
  const Rigid3& est = sum.rig.cameras[1].cam_from_rig;
  const Rigid3& truth = syn.truth.cameras[1].cam_from_rig;
  EXPECT_LT(std::abs(sum.baseline - syn.truth.BaselineMm()),
            4 * sum.baseline_sigma);
  EXPECT_GT(sum.baseline_sigma, 0);
  for (int i = 0; i < 3; ++i) {
    EXPECT_LT(std::abs(est.t[i] - truth.t[i]),
              4 * sum.extrinsic_translation_sigma[i]);
  }
  const double angle_deg =
      Eigen::AngleAxisd(est.R * truth.R.transpose()).angle() * 180 / M_PI;
  EXPECT_LT(angle_deg, 4 * sum.extrinsic_rotation_sigma_deg[0] +
                           4 * sum.extrinsic_rotation_sigma_deg[1] +
                           4 * sum.extrinsic_rotation_sigma_deg[2]);
}

// The projection of a point at infinity seen at `pixel` of `camera` (the
// truth), fixed relative to the targets, through a solved calibration:
// Project(intrinsics, cam_from_rig * mean_i(rig_from_target_i * d_i)) with
// rotations only, as projection_uncertainty.h defines it.
Eigen::Vector2d ProjectThroughSolvedTargets(
    const Synthetic& syn, const std::vector<Rigid3>& truth_poses,
    const CalibrationSummary& sum, int camera, const Eigen::Vector2d& pixel) {
  const Camera& truth = syn.truth.cameras[camera];
  const Eigen::Vector3d dir = Unproject(truth.intrinsics, pixel);
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (size_t v = 0; v < truth_poses.size(); ++v) {
    const Eigen::Vector3d in_target =
        (truth.cam_from_rig.R * truth_poses[v].R).transpose() * dir;
    mean += sum.rig_from_target[v].R * in_target;
  }
  const Camera& solved = sum.rig.cameras[camera];
  return Project(solved.intrinsics,
                 solved.cam_from_rig.R * (mean / truth_poses.size()));
}

// Monte Carlo: the spread of that projection over noise draws matches the
// predicted worst-direction sigma (which fails if the covariance's layout,
// the rotation scaling or the view-pose terms are wrong).
// Three cameras, the third sharing views only with the second: it is
// connected through the chain and its pose recovered; with no view shared
// with any other camera it is unconnected, named, and nothing is solved.
TEST(CalibrateCameras, ThreeCamerasConnectThroughAChainOfSharedViews) {
  Synthetic syn = MakeSynthetic(3, 18, 0.3, 11);
  for (size_t v = 0; v < syn.problem.views.size(); ++v) {
    std::vector<TargetObservation>& obs = syn.problem.views[v].observations;
    if (v < 9) {
      obs[2] = TargetObservation();  // camera 2 not in the first half
    } else {
      obs[0] = TargetObservation();  // camera 0 not in the second half
    }
  }
  EXPECT_TRUE(UnconnectedCameras(syn.problem).empty());
  CalibrationOptions options;
  options.cross_validate = false;
  const CalibrationSummary sum = CalibrateCameras(syn.problem, options);
  EXPECT_TRUE(sum.converged) << sum.termination;
  ASSERT_EQ(sum.rig.cameras.size(), 3u);
  EXPECT_EQ(sum.rig.cameras[2].intrinsics.name, "c2");
  // Camera 1 within 4 sigma of its reported extrinsics; camera 2, placed
  // through camera 1, within twice that (its errors add camera 1's).
  ASSERT_EQ(sum.extrinsic_rotation_sigma_deg.size(), 3u);
  double sigma_deg = 0, sigma_mm = 0;
  for (int i = 0; i < 3; ++i) {
    sigma_deg = std::max(sigma_deg, sum.extrinsic_rotation_sigma_deg[i]);
    sigma_mm = std::max(sigma_mm, sum.extrinsic_translation_sigma[i]);
  }
  for (int c = 1; c < 3; ++c) {
    const Rigid3& est = sum.rig.cameras[c].cam_from_rig;
    const Rigid3& truth = syn.truth.cameras[c].cam_from_rig;
    const double t_err = (est.t - truth.t).norm();
    const double r_err =
        Eigen::AngleAxisd(est.R * truth.R.transpose()).angle() * 180 / M_PI;
    std::printf(
        "camera %d: %.3f mm, %.4f deg (camera 1 sigma %.3f mm, "
        "%.4f deg)\n",
        c, t_err, r_err, sigma_mm, sigma_deg);
    EXPECT_LT(t_err, 4 * c * std::sqrt(3.0) * sigma_mm) << "camera " << c;
    EXPECT_LT(r_err, 4 * c * std::sqrt(3.0) * sigma_deg) << "camera " << c;
  }

  for (size_t v = 9; v < syn.problem.views.size(); ++v) {
    syn.problem.views[v].observations[1] = TargetObservation();
  }
  EXPECT_EQ(UnconnectedCameras(syn.problem), (std::vector<int>{2}));
  try {
    CalibrateCameras(syn.problem, options);
    FAIL() << "an unconnected camera was solved";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("camera 'c2' never sees"),
              std::string::npos)
        << e.what();
  }
}

TEST(CalibrateCameras, ProjectionUncertaintyMatchesMonteCarlo) {
  const double noise_px = 0.5;
  const int views = 8, trials = 30;
  const Synthetic base = MakeSynthetic(2, views, 0.0, 11);
  // The true view poses: a noise-free solve recovers them exactly.
  CalibrationOptions fast;
  fast.cross_validate = false;
  fast.compute_covariance = false;
  fast.loss = CalibrationOptions::Loss::kTrivial;
  fast.reject_sigma = 0;  // plain least squares, as the prediction
  fast.board_warp = false;
  const std::vector<Rigid3> truth_poses =
      CalibrateCameras(base.problem, fast).rig_from_target;
  std::mt19937_64 rng(5);
  std::normal_distribution<double> noise(0.0, noise_px);
  auto noisy = [&]() {
    CalibrationProblem p = base.problem;
    for (CalibrationView& view : p.views) {
      for (TargetObservation& obs : view.observations) {
        for (Eigen::Vector2d& px : obs.pixels) {
          px += Eigen::Vector2d(noise(rng), noise(rng));
        }
      }
    }
    return p;
  };
  CalibrationOptions predict = fast;
  predict.compute_covariance = true;
  const CalibrationSummary predicted = CalibrateCameras(noisy(), predict);
  struct Sample {
    int camera;
    Eigen::Vector2d pixel;
    double sigma;
  };
  const ProjectionUncertaintyMap& left =
      predicted.cameras[0].projection_uncertainty;
  const ProjectionUncertaintyMap& right =
      predicted.cameras[1].projection_uncertainty;
  const std::vector<Sample> samples = {
      {0, left.centre_pixel, left.centre_px},
      {0, left.corner_pixels[0], left.corner_px[0]},
      {1, right.corner_pixels[3], right.corner_px[3]}};
  std::vector<std::vector<Eigen::Vector2d>> q(samples.size());
  for (int k = 0; k < trials; ++k) {
    const CalibrationSummary sum = CalibrateCameras(noisy(), fast);
    for (size_t s = 0; s < samples.size(); ++s) {
      q[s].push_back(ProjectThroughSolvedTargets(
          base, truth_poses, sum, samples[s].camera, samples[s].pixel));
    }
  }
  for (size_t s = 0; s < samples.size(); ++s) {
    Eigen::Vector2d mean = Eigen::Vector2d::Zero();
    for (const Eigen::Vector2d& x : q[s]) mean += x / trials;
    Eigen::Matrix2d cov = Eigen::Matrix2d::Zero();
    for (const Eigen::Vector2d& x : q[s]) {
      cov += (x - mean) * (x - mean).transpose() / (trials - 1);
    }
    const double empirical = WorstDirectionSigma(cov);
    EXPECT_GT(samples[s].sigma, 0.02) << s;
    EXPECT_NEAR(empirical / samples[s].sigma, 1.0, 0.3)
        << "sample " << s << ": predicted " << samples[s].sigma
        << " px, Monte Carlo " << empirical << " px";
  }
}

TEST(CalibrateCameras, RobustLossResistsOutliers) {
  Synthetic syn = MakeSynthetic(1, 10, 0.2, 11);
  // Corrupt 1% of the corners by 30 px.
  std::mt19937_64 rng(3);
  int corrupted = 0;
  for (CalibrationView& v : syn.problem.views) {
    for (Eigen::Vector2d& px : v.observations[0].pixels) {
      if (rng() % 100 == 0) {
        px += Eigen::Vector2d(30, -20);
        ++corrupted;
      }
    }
  }
  ASSERT_GT(corrupted, 2);
  CalibrationOptions options;
  options.cross_validate = false;
  options.reject_sigma = 0;  // the loss alone
  options.loss = CalibrationOptions::Loss::kHuber;
  const CalibrationSummary robust = CalibrateCameras(syn.problem, options);
  options.loss = CalibrationOptions::Loss::kTrivial;
  const CalibrationSummary plain = CalibrateCameras(syn.problem, options);
  const double truth_fx = syn.truth.cameras[0].intrinsics.fx;
  EXPECT_LT(std::abs(robust.rig.cameras[0].intrinsics.fx - truth_fx),
            std::abs(plain.rig.cameras[0].intrinsics.fx - truth_fx));
  options.loss = CalibrationOptions::Loss::kCauchy;
  options.loss_scale_px = 1.0;
  const CalibrationSummary cauchy = CalibrateCameras(syn.problem, options);
  std::printf(
      "fx error: Huber 3 px %.3f, Cauchy 1 px %.3f, least squares %.3f\n",
      robust.rig.cameras[0].intrinsics.fx - truth_fx,
      cauchy.rig.cameras[0].intrinsics.fx - truth_fx,
      plain.rig.cameras[0].intrinsics.fx - truth_fx);
  // Both robust fits stay within 4 sigma of the truth; least squares does not.
  EXPECT_LT(std::abs(robust.rig.cameras[0].intrinsics.fx - truth_fx),
            4 * robust.cameras[0].sigma[kFx]);
  EXPECT_LT(std::abs(cauchy.rig.cameras[0].intrinsics.fx - truth_fx),
            4 * cauchy.cameras[0].sigma[kFx]);
  EXPECT_GT(std::abs(plain.rig.cameras[0].intrinsics.fx - truth_fx),
            10 * std::abs(robust.rig.cameras[0].intrinsics.fx - truth_fx));
  EXPECT_GE(robust.cameras[0].outliers, corrupted);
}

// The default (least squares with 4-sigma outlier rejection) finds every
// corrupted corner (and maybe a Gaussian one, as on clean data) and lands
// where the clean data does.
TEST(CalibrateCameras, OutlierRejectionFindsTheCorruptedCorners) {
  Synthetic syn = MakeSynthetic(1, 10, 0.2, 11);
  CalibrationOptions options;
  options.cross_validate = false;
  const CalibrationSummary clean = CalibrateCameras(syn.problem, options);
  const int points =
      clean.cameras[0].num_points + clean.cameras[0].rejected_corners;
  EXPECT_LE(clean.cameras[0].rejected_corners, points / 100);
  std::mt19937_64 rng(3);
  int corrupted = 0;
  std::vector<Eigen::Vector2d> corrupted_pixels;
  for (CalibrationView& v : syn.problem.views) {
    for (Eigen::Vector2d& px : v.observations[0].pixels) {
      if (rng() % 100 == 0) {
        px += Eigen::Vector2d(30, -20);
        corrupted_pixels.push_back(px);
        ++corrupted;
      }
    }
  }
  ASSERT_GT(corrupted, 2);
  const CalibrationSummary sum = CalibrateCameras(syn.problem, options);
  // No corrupted corner is left among the inliers.
  int corrupted_kept = 0;
  for (const CalibrationView& view : sum.inlier_views) {
    for (const Eigen::Vector2d& px : view.observations[0].pixels) {
      for (const Eigen::Vector2d& bad : corrupted_pixels) {
        corrupted_kept += (px - bad).norm() < 1e-12;
      }
    }
  }
  EXPECT_EQ(corrupted_kept, 0);
  EXPECT_GE(sum.cameras[0].rejected_corners, corrupted);
  EXPECT_LE(sum.cameras[0].rejected_corners, corrupted + points / 100);
  EXPECT_EQ(sum.cameras[0].rejected_views, 0);
  EXPECT_GE(sum.rejection_rounds, 1);
  EXPECT_NEAR(sum.rejection_sigma_px, 0.2, 0.03);
  // The corrupted corners are gone: the clean data's solution within a
  // fraction of sigma.
  EXPECT_NEAR(sum.rig.cameras[0].intrinsics.fx,
              clean.rig.cameras[0].intrinsics.fx,
              0.5 * sum.cameras[0].sigma[kFx]);
  EXPECT_LT(std::abs(sum.rig.cameras[0].intrinsics.fx -
                     syn.truth.cameras[0].intrinsics.fx),
            3 * sum.cameras[0].sigma[kFx]);
  // Without rejection least squares is pulled far off.
  options.reject_sigma = 0;
  const CalibrationSummary plain = CalibrateCameras(syn.problem, options);
  EXPECT_GT(std::abs(plain.rig.cameras[0].intrinsics.fx -
                     syn.truth.cameras[0].intrinsics.fx),
            10 * sum.cameras[0].sigma[kFx]);
}

// A board found in the wrong place (most of its corners far off) is dropped
// whole rather than corner by corner.
TEST(CalibrateCameras, OutlierRejectionDropsAMisdetectedView) {
  Synthetic syn = MakeSynthetic(1, 10, 0.2, 11);
  CalibrationOptions options;
  options.cross_validate = false;
  const CalibrationSummary clean = CalibrateCameras(syn.problem, options);
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> shift(-15, 15);
  for (Eigen::Vector2d& px : syn.problem.views[4].observations[0].pixels) {
    px += Eigen::Vector2d(shift(rng), shift(rng));
  }
  const CalibrationSummary sum = CalibrateCameras(syn.problem, options);
  EXPECT_EQ(sum.cameras[0].rejected_views, 1);
  EXPECT_TRUE(std::isnan(sum.cameras[0].view_rms_px[4]));
  EXPECT_EQ(sum.cameras[0].num_views, clean.cameras[0].num_views - 1);
  EXPECT_TRUE(sum.inlier_views[4].observations[0].empty());
  EXPECT_LT(std::abs(sum.rig.cameras[0].intrinsics.fx -
                     syn.truth.cameras[0].intrinsics.fx),
            3 * sum.cameras[0].sigma[kFx]);
}

// A deflected board (1.5 mm / -1 mm over 270 x 180 mm): with board_warp the
// deflection is recovered and the residuals are the noise; without it the
// flat model leaves a larger RMS.
TEST(CalibrateCameras, BoardWarpRecoversTheDeflection) {
  const Synthetic syn = MakeSynthetic(2, 12, 0.2, 21, {1.5, -1.0});
  CalibrationOptions options;
  options.cross_validate = false;
  options.board_warp = true;
  const CalibrationSummary warped = CalibrateCameras(syn.problem, options);
  options.board_warp = false;
  const CalibrationSummary flat = CalibrateCameras(syn.problem, options);
  std::printf("warp %.4f %.4f mm; RMS warped %.4f flat %.4f px\n",
              warped.board_warp[0], warped.board_warp[1], warped.rms_px,
              flat.rms_px);
  EXPECT_NEAR(warped.board_warp[0], 1.5, 0.1);
  EXPECT_NEAR(warped.board_warp[1], -1.0, 0.1);
  EXPECT_EQ(flat.board_warp[0], 0.0);
  EXPECT_LT(warped.rms_px, 0.3);  // the noise's norm: 0.2 * sqrt(2)
  EXPECT_GT(flat.rms_px, 1.2 * warped.rms_px);
  for (int c = 0; c < 2; ++c) {
    EXPECT_LT(std::abs(warped.rig.cameras[c].intrinsics.fx -
                       syn.truth.cameras[c].intrinsics.fx),
              3 * warped.cameras[c].sigma[kFx]);
  }
}

TEST(CalibrateCameras, TooFewViewsIsInputError) {
  const Synthetic syn = MakeSynthetic(2, 2, 0.1, 5);
  EXPECT_THROW(CalibrateCameras(syn.problem), InputError);
  Synthetic one = MakeSynthetic(1, 6, 0.1, 5);
  one.problem.cameras.clear();
  EXPECT_THROW(CalibrateCameras(one.problem), InputError);
  CalibrationOptions bad;
  bad.num_distortion = 3;
  EXPECT_THROW(CalibrateCameras(MakeSynthetic(1, 6, 0.1, 5).problem, bad),
               InputError);
}

TEST(CalibrateCameras, SolveFailureNamesNonConvergenceAndAbsurdRms) {
  CalibrationOptions options;
  CalibrationSummary good;
  good.converged = true;
  good.rms_px = 0.4;
  EXPECT_EQ(SolveFailure(good, options), "");
  CalibrationSummary stuck = good;
  stuck.converged = false;
  stuck.termination = "NO_CONVERGENCE";
  stuck.iterations = 200;
  options.num_distortion = 8;
  const std::string a = SolveFailure(stuck, options);
  EXPECT_NE(a.find("did not converge"), std::string::npos) << a;
  EXPECT_NE(a.find("--distortion 5"), std::string::npos) << a;
  CalibrationSummary absurd = good;
  absurd.rms_px = 700;
  const std::string b = SolveFailure(absurd, options);
  EXPECT_NE(b.find("700 px"), std::string::npos) << b;
  EXPECT_NE(b.find("--target"), std::string::npos) << b;
}

TEST(ProjectionDifference, ZeroForSameModelAndRotationRemoved) {
  CameraIntrinsics a{"a", 640, 480, 800, 800, 320, 240, {-0.2, 0.1, 0, 0, 0}};
  const ProjectionDifference same = ProjectionDifferenceOf(a, a);
  EXPECT_LT(same.rms_px, 1e-9);
  EXPECT_LT(same.focus_rms_px, 1e-9);
  EXPECT_DOUBLE_EQ(same.focus_radius_px, 160.0);  // a third of 480
  // A principal point shift of 2 px is (mostly) a rotation.
  CameraIntrinsics b = a;
  b.cx += 2;
  EXPECT_LT(ProjectionDifferenceOf(a, b).rms_px, 0.2);
  // 1% focal: ~0.01 * r at radius r, not a rotation; near the centre small.
  b = a;
  b.fx *= 1.01;
  const ProjectionDifference focal = ProjectionDifferenceOf(a, b);
  EXPECT_GT(focal.max_px, 2.0);
  EXPECT_LT(focal.focus_rms_px, 1.2);
  EXPECT_GT(focal.rms_px, focal.focus_rms_px);
  EXPECT_DOUBLE_EQ(ProjectionDifferenceOf(a, b, 50).focus_radius_px, 50.0);
  EXPECT_LT(ProjectionDifferenceOf(a, b, 50).focus_rms_px, focal.focus_rms_px);
}

// ---------------------------------------------------------------- real data

// Bouguet reference intrinsics on OpenCV's calib1 data: 7 views x 35 corners.
TEST(CalibrateCamerasRealData, calib1MatchesBouguetReferenceWithinSigma) {
  KINCAL_REQUIRE_SHARED_DATA("opencv-extra-calib1");
  const std::string dir = testing::SharedDataDir() + "/opencv-extra-calib1";
  std::ifstream in(dir + "/calib1_image_points.txt");
  ASSERT_TRUE(in) << dir;
  CalibrationProblem problem;
  problem.cameras.push_back({"calib1", 640, 480, 0, 0, 0, 0, {}});
  std::string line;
  const std::vector<Eigen::Vector3d> board = Board(7, 5, 2.54);
  while (std::getline(in, line)) {
    if (line.empty()) continue;
    if (line[0] == '#') {
      problem.views.push_back({line, {TargetObservation()}});
      continue;
    }
    std::istringstream ls(line);
    double u, v;
    ASSERT_TRUE(ls >> u >> v) << line;
    TargetObservation& obs = problem.views.back().observations[0];
    obs.p_in_target.push_back(board[obs.pixels.size()]);
    obs.pixels.emplace_back(u, v);
  }
  ASSERT_EQ(problem.views.size(), 7u);
  for (const auto& v : problem.views) {
    ASSERT_EQ(v.observations[0].pixels.size(), 35u);
  }
  // Bouguet's model: k1 k2 p1 p2 (k3 = 0), least squares on all corners of
  // a flat board, no regularisation.
  CalibrationOptions options;
  options.num_distortion = 4;
  options.reject_sigma = 0;
  options.board_warp = false;
  options.lens_regularization = 0;
  const CalibrationSummary sum = CalibrateCameras(problem, options);
  ASSERT_TRUE(sum.converged) << sum.termination;
  const CameraIntrinsics& c = sum.rig.cameras[0].intrinsics;
  // calib1_reference.txt: fc, cc, kc and std_intrinsics.
  const double ref[8] = {809.94790, 806.55964, 361.99611, 214.39514,
                         -0.12821,  -0.39441,  -0.00435,  -0.00732};
  const double ref_sigma[8] = {9.483582371446595,    8.827729903480298,
                               8.536273813519113,    13.27634001543498,
                               0.03972140807068844,  0.5217584855616905,
                               0.003163017623740528, 0.002420488943287363};
  const double est[8] = {c.fx,
                         c.fy,
                         c.cx,
                         c.cy,
                         c.distortion[0],
                         c.distortion[1],
                         c.distortion[2],
                         c.distortion[3]};
  const char* names[8] = {"fx", "fy", "cx", "cy", "k1", "k2", "p1", "p2"};
  for (int i = 0; i < 8; ++i) {
    EXPECT_LT(std::abs(est[i] - ref[i]), ref_sigma[i])
        << names[i] << ": " << est[i] << " vs reference " << ref[i]
        << " (sigma " << ref_sigma[i] << ")";
    // Our sigma agrees with the reference sigma within a factor 2.
    EXPECT_GT(sum.cameras[0].sigma[i], 0.5 * ref_sigma[i]) << names[i];
    EXPECT_LT(sum.cameras[0].sigma[i], 2.0 * ref_sigma[i]) << names[i];
  }
  // Bouguet's err = [0.10179 0.09492] (std of x and y): norm RMS 0.139 px.
  EXPECT_LT(sum.rms_px, 0.145);
  std::printf(
      "calib1: fx %.5f fy %.5f cx %.5f cy %.5f k %.5f %.5f %.5f %.5f "
      "rms %.4f px, sigma fx %.3f\n",
      est[0], est[1], est[2], est[3], est[4], est[5], est[6], est[7],
      sum.rms_px, sum.cameras[0].sigma[0]);
}

TargetObservation DetectChessboard(const std::string& path, cv::Size size) {
  const cv::Mat img = cv::imread(path, cv::IMREAD_GRAYSCALE);
  EXPECT_FALSE(img.empty()) << path;
  std::vector<cv::Point2f> corners;
  TargetObservation obs;
  if (!cv::findChessboardCorners(
          img, size, corners,
          cv::CALIB_CB_ADAPTIVE_THRESH | cv::CALIB_CB_NORMALIZE_IMAGE)) {
    return obs;
  }
  cv::cornerSubPix(
      img, corners, cv::Size(11, 11), cv::Size(-1, -1),
      cv::TermCriteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 30,
                       0.01));
  const std::vector<Eigen::Vector3d> board =
      Board(size.width, size.height, 1.0);
  for (size_t i = 0; i < corners.size(); ++i) {
    obs.p_in_target.push_back(board[i]);
    obs.pixels.emplace_back(corners[i].x, corners[i].y);
  }
  return obs;
}

// OpenCV's stereo sample data: 13 pairs, 9x6 board, square = 1.
CalibrationProblem StereoLeftRightProblem() {
  const std::string dir =
      testing::SharedDataDir() + "/opencv-stereo-left-right";
  CalibrationProblem problem;
  problem.cameras.push_back({"left", 640, 480, 0, 0, 0, 0, {}});
  problem.cameras.push_back({"right", 640, 480, 0, 0, 0, 0, {}});
  for (const char* id : {"01", "02", "03", "04", "05", "06", "07", "08", "09",
                         "11", "12", "13", "14"}) {
    CalibrationView view;
    view.label = id;
    for (const char* side : {"left", "right"}) {
      view.observations.push_back(
          DetectChessboard(dir + "/" + side + id + ".jpg", cv::Size(9, 6)));
    }
    problem.views.push_back(view);
  }
  return problem;
}

// OpenCV's stereo_calib reaches RMS 0.445 px; the baseline is about 3.34
// squares.
TEST(CalibrateCamerasRealData, StereoLeftRightReachesOpenCvRms) {
  KINCAL_REQUIRE_SHARED_DATA("opencv-stereo-left-right");
  const CalibrationProblem problem = StereoLeftRightProblem();
  const CalibrationSummary sum = CalibrateCameras(problem);
  EXPECT_TRUE(sum.converged) << sum.termination;
  EXPECT_LE(sum.rms_px, 0.445);
  // OpenCV's samples/cpp/stereo_calib.cpp on the same corners, same flags.
  std::vector<std::vector<cv::Point3f>> obj;
  std::vector<std::vector<cv::Point2f>> img[2];
  for (const CalibrationView& v : problem.views) {
    if (v.observations[0].empty() || v.observations[1].empty()) continue;
    obj.emplace_back();
    for (const Eigen::Vector3d& p : v.observations[0].p_in_target) {
      obj.back().emplace_back(p.x(), p.y(), p.z());
    }
    for (int c = 0; c < 2; ++c) {
      img[c].emplace_back();
      for (const Eigen::Vector2d& px : v.observations[c].pixels) {
        img[c].back().emplace_back(px.x(), px.y());
      }
    }
  }
  cv::Mat K[2] = {cv::initCameraMatrix2D(obj, img[0], cv::Size(640, 480), 0),
                  cv::initCameraMatrix2D(obj, img[1], cv::Size(640, 480), 0)};
  cv::Mat D[2], R, T, E, F;
  const double opencv_rms = cv::stereoCalibrate(
      obj, img[0], img[1], K[0], D[0], K[1], D[1], cv::Size(640, 480), R, T, E,
      F,
      cv::CALIB_FIX_ASPECT_RATIO | cv::CALIB_ZERO_TANGENT_DIST |
          cv::CALIB_USE_INTRINSIC_GUESS | cv::CALIB_SAME_FOCAL_LENGTH |
          cv::CALIB_RATIONAL_MODEL | cv::CALIB_FIX_K3 | cv::CALIB_FIX_K4 |
          cv::CALIB_FIX_K5,
      cv::TermCriteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 100,
                       1e-5));
  EXPECT_LE(sum.rms_px, opencv_rms);
  EXPECT_NEAR(cv::norm(T), sum.baseline, 0.02);
  EXPECT_NEAR(sum.baseline, 3.34, 0.05);
  EXPECT_GT(sum.baseline_sigma, 0);
  EXPECT_LT(sum.baseline_sigma, 0.05);
  for (const CameraCalibrationSummary& cs : sum.cameras) {
    EXPECT_GT(cs.holdout_rms_px, cs.rms_px);  // held-out is harder
    EXPECT_LT(cs.holdout_rms_px, 1.0);
  }
  std::printf(
      "stereo: OpenCV stereo_calib %.4f px, baseline %.4f; kincal rms %.4f px "
      "(left %.4f, right %.4f; OpenCV init %.4f, %.4f), "
      "baseline %.4f +- %.4f, holdout %.4f / %.4f px, half diff %.3f / %.3f "
      "px, %d iterations, %.3f s\n",
      opencv_rms, cv::norm(T), sum.rms_px, sum.cameras[0].rms_px,
      sum.cameras[1].rms_px, sum.cameras[0].opencv_rms_px,
      sum.cameras[1].opencv_rms_px, sum.baseline, sum.baseline_sigma,
      sum.cameras[0].holdout_rms_px, sum.cameras[1].holdout_rms_px,
      sum.cameras[0].half_diff_rms_px, sum.cameras[1].half_diff_rms_px,
      sum.iterations, sum.seconds);
}

// The 8-coefficient (rational) model converges with the distortion
// regularisers, and without any stops at max_iterations; mrcal's lens
// regulariser alone (mrcal's OPENCV8 setting) makes it converge too; the
// k4..k6 regulariser leaves the 5-coefficient solve unchanged (it has no
// k4..k6).
TEST(CalibrateCamerasRealData, StereoRationalModelConvergesRegularized) {
  KINCAL_REQUIRE_SHARED_DATA("opencv-stereo-left-right");
  const CalibrationProblem problem = StereoLeftRightProblem();
  CalibrationOptions options;
  options.compute_covariance = false;
  options.cross_validate = false;
  const CalibrationSummary five = CalibrateCameras(problem, options);
  CalibrationOptions plain = options;
  plain.regularization = 0;
  const CalibrationSummary five_plain = CalibrateCameras(problem, plain);
  options.num_distortion = 8;
  const CalibrationSummary eight = CalibrateCameras(problem, options);
  plain.num_distortion = 8;
  const CalibrationSummary eight_lens_only = CalibrateCameras(problem, plain);
  plain.lens_regularization = 0;
  const CalibrationSummary eight_plain = CalibrateCameras(problem, plain);

  EXPECT_FALSE(eight_plain.converged) << eight_plain.termination;
  EXPECT_EQ(eight_plain.regularization_cost, 0.0);
  EXPECT_TRUE(eight_lens_only.converged) << eight_lens_only.termination;
  ASSERT_TRUE(eight.converged) << eight.termination;
  EXPECT_TRUE(SolveFailure(eight, options).empty());
  EXPECT_LT(eight.iterations, options.max_iterations);
  EXPECT_GT(eight.regularization_share, 0.0);
  EXPECT_LT(eight.regularization_share, 0.05);
  EXPECT_LT(eight.rms_px, 0.46);
  for (size_t c = 0; c < 2; ++c) {
    const CameraIntrinsics& a = five.cameras[c].intrinsics;
    const CameraIntrinsics& b = eight.cameras[c].intrinsics;
    const CameraIntrinsics& p = five_plain.cameras[c].intrinsics;
    EXPECT_LT(std::abs(a.fx - p.fx), 0.01) << c;
    EXPECT_LT(std::abs(five.cameras[c].rms_px - five_plain.cameras[c].rms_px),
              0.01)
        << c;
    EXPECT_LT(std::abs(b.fx - a.fx), 1.0) << c;
    EXPECT_LT(std::abs(b.cx - a.cx), 1.0) << c;
    EXPECT_LT(std::abs(b.cy - a.cy), 1.0) << c;
    std::printf(
        "camera %zu: 5 coeff fx %.3f cx %.3f cy %.3f rms %.4f (no k4..k6 "
        "regulariser "
        "fx %.3f rms %.4f); 8 coeff fx %.3f cx %.3f cy %.3f rms %.4f\n",
        c, a.fx, a.cx, a.cy, five.cameras[c].rms_px, p.fx,
        five_plain.cameras[c].rms_px, b.fx, b.cx, b.cy,
        eight.cameras[c].rms_px);
  }
  std::printf(
      "8 coeff: %d iterations (%s), rms %.4f px, regulariser share %.4g; "
      "lens regulariser only: %d iterations (%s); unregularised: %d "
      "iterations (%s)\n",
      eight.iterations, eight.termination.c_str(), eight.rms_px,
      eight.regularization_share, eight_lens_only.iterations,
      eight_lens_only.termination.c_str(), eight_plain.iterations,
      eight_plain.termination.c_str());
}

TEST(CalibrateCameras, NegativeRegularizationIsInputError) {
  CalibrationOptions options;
  options.regularization = -0.1;
  EXPECT_THROW(options.Check(), InputError);
  options.regularization = 0;
  options.lens_regularization = -1;
  EXPECT_THROW(options.Check(), InputError);
}

}  // namespace
}  // namespace kincal
