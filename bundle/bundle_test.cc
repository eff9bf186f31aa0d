#include "bundle/bundle.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <random>

#include "bundle/testing/synthetic.h"
#include "calib/model_state.h"
#include "data/error.h"
#include "data/rigid3.h"
#include "data/robot.h"
#include "synth/render.h"
#include "synth/simulate.h"
#include "tests/testing/paths.h"

namespace kincal {
namespace {

Robot Bh7() {
  return ReadRobotYaml(testing::SourceDir() + "/data/robots/bh7.yaml");
}

// Adds, over the bundle's parameters, ((estimate - truth) / sigma)^2 to
// `sum_z2` and their count to `n` (every sigma must be finite).
void AddSquaredErrorOverSigma(const Robot& true_robot, const BundleResult& r,
                              double* sum_z2, int* n) {
  ModelState truth;
  truth.chain = Chain::FromRobot(true_robot);
  for (const BundleParam& p : r.params) {
    const ParamInfo info = FindParam(truth, p.name);
    const double t = info.ToInterface(ParamValue(truth, info));
    EXPECT_TRUE(std::isfinite(p.sigma)) << p.name;
    const double z = (p.value - t) / p.sigma;
    *sum_z2 += z * z;
    ++*n;
  }
}

TEST(HandEye, RecoversBothTransformsFromExactPoses) {
  std::mt19937_64 rng(3);
  std::normal_distribution<double> n(0, 1);
  auto random_rigid = [&] {
    Rigid3 r;
    Eigen::Vector3d w(n(rng), n(rng), n(rng));
    r.R = Eigen::AngleAxisd(w.norm(), w.normalized()).toRotationMatrix();
    r.t = Eigen::Vector3d(n(rng), n(rng), n(rng)) * 100;
    return r;
  };
  const Rigid3 x = random_rigid(), y = random_rigid();
  std::vector<Rigid3> bf, rt;
  for (int i = 0; i < 6; ++i) {
    bf.push_back(random_rigid());
    rt.push_back(x * bf.back() * y);
  }
  Rigid3 xe, ye;
  ASSERT_TRUE(HandEyeStart(bf, rt, &xe, &ye));
  EXPECT_LT((xe.R - x.R).norm(), 1e-9);
  EXPECT_LT((ye.R - y.R).norm(), 1e-9);
  EXPECT_LT((xe.t - x.t).norm(), 1e-6);
  EXPECT_LT((ye.t - y.t).norm(), 1e-6);
  // All rotations about one axis leave the problem undetermined.
  std::vector<Rigid3> bf1, rt1;
  for (int i = 0; i < 6; ++i) {
    Rigid3 r;
    r.R =
        Eigen::AngleAxisd(0.3 * i, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    r.t = Eigen::Vector3d(i, 2 * i, 0);
    bf1.push_back(r);
    rt1.push_back(x * r * y);
  }
  EXPECT_FALSE(HandEyeStart(bf1, rt1, &xe, &ye));
}

// Exact corners (no noise): the bundle must reach the truth's reprojection
// floor and put the tips where the true robot puts them.
TEST(Bundle, ExactCornersGiveTheTrueTips) {
  SyntheticBundleOptions so;
  so.frames = 60;
  so.noise_px = 0.0;
  so.seed = 5;
  const SyntheticBundle s = MakeSyntheticBundle(Bh7(), so);
  BundleOptions o;
  const BundleResult r = RunBundle(s.nominal, s.rig, s.target, s.frames, o);
  EXPECT_LT(r.reproj_rms_px, 1e-3);
  EXPECT_LT(r.heldout_reproj_rms_px, 1e-3);
  EXPECT_EQ(r.dropped_tags, 0);
  // Tips of the calibrated robot vs the true ones, up to the base frame.
  EXPECT_LT(TipRmsAgainstTruth(s, r.calibrated, 100, 9), 1e-3);
  // The record compensate reads: nominal rows, travel, the rig as frame.
  ASSERT_TRUE(r.calibrated.HasNominal());
  EXPECT_EQ(r.calibrated.nominal_joints[1].a_mm, s.nominal.joints[1].a_mm);
  EXPECT_EQ(r.calibrated.fitted_on.poses, r.train_frames);
  ASSERT_EQ(r.calibrated.fitted_on.joint_range.size(), s.nominal.joints.size());
  EXPECT_LE(r.calibrated.fitted_on.joint_range[2][0],
            s.frames[r.train[0]].q_reading[2]);
  EXPECT_TRUE(r.calibrated.fitted_on.has_frame);
  EXPECT_EQ(r.calibrated.fitted_on.frame[3], r.rig_from_base[3]);
}

// Noisy corners: parameter errors against the truth are within 1.5x of the
// sigma the bundle reports (Monte Carlo over seeds; only the parameters the
// bundle estimates deviate from nominal, so truth and estimate are the same
// quantities).
TEST(Bundle, ReportedSigmaMatchesTheSpreadOverSeeds) {
  double sum_z2 = 0;
  int n = 0;
  for (int seed = 1; seed <= 8; ++seed) {
    SyntheticBundleOptions so;
    so.frames = 80;
    so.noise_px = 0.1;
    so.seed = 100 + seed;
    so.only_identifiable = true;
    const SyntheticBundle s = MakeSyntheticBundle(Bh7(), so);
    BundleOptions o;
    o.holdout_fraction = 0.0;
    const BundleResult r = RunBundle(s.nominal, s.rig, s.target, s.frames, o);
    AddSquaredErrorOverSigma(s.truth, r, &sum_z2, &n);
  }
  ASSERT_GT(n, 20);
  const double rms_z = std::sqrt(sum_z2 / n);
  // 1 when the sigma is right; the claim is within 1.5x either way.
  EXPECT_LT(rms_z, 1.5);
  EXPECT_GT(rms_z, 1 / 1.5);
  RecordProperty("rms_z", std::to_string(rms_z));
  std::printf("RMS of (estimate - truth) / sigma over %d parameters: %.3f\n", n,
              rms_z);
}

// One, two and three cameras on the stand (format v3) on the same poses
// and truths: the reported sigma is honest in each configuration (RMS of
// (estimate - truth) / sigma within 0.7..1.4), and the tips at fresh poses
// are within 2x of the stereo rig's.
TEST(Bundle, OneTwoAndThreeCamerasHonestSigmaAndTipsWithinTwiceStereo) {
  double tip_rms[4] = {0, 0, 0, 0};
  for (int cameras : {2, 1, 3}) {
    double sum_z2 = 0, sum_tip2 = 0;
    int n = 0;
    const int seeds = 6;
    for (int seed = 1; seed <= seeds; ++seed) {
      SyntheticBundleOptions so;
      so.frames = 80;
      so.noise_px = 0.1;
      so.seed = 300 + seed;
      so.cameras = cameras;
      so.only_identifiable = true;
      const SyntheticBundle s = MakeSyntheticBundle(Bh7(), so);
      ASSERT_EQ(s.rig.cameras.size(), static_cast<size_t>(cameras));
      BundleOptions o;
      o.holdout_fraction = 0.0;
      const BundleResult r = RunBundle(s.nominal, s.rig, s.target, s.frames, o);
      AddSquaredErrorOverSigma(s.truth, r, &sum_z2, &n);
      const double tip = TipRmsAgainstTruth(s, r.calibrated, 100, 9);
      sum_tip2 += tip * tip;
    }
    const double rms_z = std::sqrt(sum_z2 / n);
    tip_rms[cameras] = std::sqrt(sum_tip2 / seeds);
    std::printf(
        "%d camera(s): RMS z %.3f over %d parameters, tips at fresh "
        "poses %.4f mm\n",
        cameras, rms_z, n, tip_rms[cameras]);
    EXPECT_GT(rms_z, 0.7) << cameras << " camera(s)";
    EXPECT_LT(rms_z, 1.4) << cameras << " camera(s)";
    EXPECT_LT(tip_rms[cameras], 0.10) << cameras << " camera(s)";
  }
  EXPECT_LE(tip_rms[1], 2 * tip_rms[2]);
  EXPECT_LE(tip_rms[3], 2 * tip_rms[2]);
}

// Rotation angle (deg) and translation distance (mm) between two poses.
void ExpectSamePose(const Rigid3& a, const std::array<double, 6>& block,
                    double max_deg, double max_mm, const std::string& what) {
  const Rigid3 b = Rigid3FromPoseBlock(block.data());
  const double deg =
      Eigen::AngleAxisd(a.R.transpose() * b.R).angle() * 180.0 / M_PI;
  EXPECT_LT(deg, max_deg) << what;
  EXPECT_LT((a.t - b.t).norm(), max_mm) << what;
}

// Cameras on the flange (mount: flange), exact corners: the bundle finds the
// hidden mounting (flange_from_rig), the board's pose in the base and a
// robot whose tool row ends at the rig origin at fresh poses.
TEST(Bundle, FlangeExactCornersGiveMountingBoardAndRigOrigins) {
  for (int cameras : {1, 2}) {
    SyntheticBundleOptions so;
    so.frames = 60;
    so.noise_px = 0.0;
    so.seed = 5;
    so.flange = true;
    so.cameras = cameras;
    so.only_identifiable = true;
    const SyntheticBundle s = MakeSyntheticBundle(Bh7(), so);
    ASSERT_EQ(s.rig.mount, RigMount::kFlange);
    BundleOptions o;
    const BundleResult r = RunBundle(s.nominal, s.rig, s.target, s.frames, o);
    EXPECT_EQ(r.mount, RigMount::kFlange);
    EXPECT_LT(r.reproj_rms_px, 1e-3) << cameras;
    EXPECT_LT(r.heldout_tip_rms_mm, 1e-3) << cameras;
    ExpectSamePose(s.flange_from_rig, r.flange_from_rig, 1e-4, 1e-3,
                   "flange_from_rig");
    ExpectSamePose(s.base_from_target, r.base_from_target, 1e-4, 1e-3,
                   "base_from_target");
    EXPECT_LT(TipRmsAgainstTruth(s, r.calibrated, 100, 9), 1e-3) << cameras;
    EXPECT_THAT(r.identifiable, ::testing::Contains("flange_from_rig.tx"));
    EXPECT_THAT(r.identifiable, ::testing::Contains("base_from_target.rz"));
    // The measuring frame of the record: target_from_base.
    const Rigid3 target_from_base = s.base_from_target.Inverse();
    EXPECT_NEAR(r.calibrated.fitted_on.frame[3], target_from_base.t.x(), 1e-3);
  }
}

// Cameras on the flange, noisy corners, one and two cameras: the reported
// sigma is honest (RMS of (estimate - truth) / sigma within 0.7..1.4 over
// seeds) and the rig origins at fresh poses are within 0.10 mm.
TEST(Bundle, FlangeHonestSigmaAndRigOriginsAtFreshPoses) {
  for (int cameras : {2, 1}) {
    double sum_z2 = 0, sum_tip2 = 0;
    int n = 0;
    const int seeds = 12;
    for (int seed = 1; seed <= seeds; ++seed) {
      SyntheticBundleOptions so;
      so.frames = 80;
      so.noise_px = 0.1;
      so.seed = 500 + seed;
      so.cameras = cameras;
      so.flange = true;
      so.only_identifiable = true;
      const SyntheticBundle s = MakeSyntheticBundle(Bh7(), so);
      BundleOptions o;
      o.holdout_fraction = 0.0;
      const BundleResult r = RunBundle(s.nominal, s.rig, s.target, s.frames, o);
      double seed_z2 = 0;
      int seed_n = 0;
      AddSquaredErrorOverSigma(s.truth, r, &seed_z2, &seed_n);
      sum_z2 += seed_z2;
      n += seed_n;
      const double tip = TipRmsAgainstTruth(s, r.calibrated, 100, 9);
      sum_tip2 += tip * tip;
      std::printf("  seed %d: %zu frames, RMS z %.3f, tips %.4f mm\n", seed,
                  s.frames.size(), std::sqrt(seed_z2 / seed_n), tip);
    }
    const double rms_z = std::sqrt(sum_z2 / n);
    const double tip_rms = std::sqrt(sum_tip2 / seeds);
    std::printf(
        "flange, %d camera(s): RMS z %.3f over %d parameters, rig origins at "
        "fresh poses %.4f mm\n",
        cameras, rms_z, n, tip_rms);
    EXPECT_GT(rms_z, 0.7) << cameras << " camera(s)";
    EXPECT_LT(rms_z, 1.4) << cameras << " camera(s)";
    EXPECT_LT(tip_rms, 0.10) << cameras << " camera(s)";
  }
}

TEST(Bundle, TooFewTrackedFramesIsBadInput) {
  SyntheticBundleOptions so;
  so.frames = 2;
  const SyntheticBundle s = MakeSyntheticBundle(Bh7(), so);
  BundleOptions o;
  o.holdout_fraction = 0;
  EXPECT_THROW(RunBundle(s.nominal, s.rig, s.target, s.frames, o), InputError);
}

// 80 synthetic BH-7 frames with 0.03 px corner noise and only the
// identifiable parameters perturbed: the scene the outlier and weighting
// tests plant their bad corners in.
SyntheticBundle QuietBh7(int seed) {
  SyntheticBundleOptions so;
  so.frames = 80;
  so.noise_px = 0.03;
  so.seed = seed;
  so.only_identifiable = true;
  return MakeSyntheticBundle(Bh7(), so);
}

// A few gross corners among good ones (a dim oblique tag in a light-aware
// render: corners 0.5-3.4 px off among 0.03 px ones): the automatic Huber
// scale (3 sigma of the corners after a first fit) keeps them from pulling
// the robot, where a fixed 1 px scale, ~30 sigma, lets them.
TEST(Bundle, AutomaticHuberScaleKeepsGrossCornersFromPullingTheRobot) {
  SyntheticBundle s = QuietBh7(31);
  // Three corners of one tag 0.8 px off (random directions) in every 4th
  // frame: below the 1 px scale and the 1 px outlier-tag rule, 27 sigma.
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> angle(0, 2 * M_PI);
  for (size_t f = 0; f < s.frames.size(); f += 4) {
    auto& corners = s.frames[f].corners;
    ASSERT_GE(corners.size(), 3u);
    for (int k = 0; k < 3; ++k) {
      const double a = angle(rng);
      corners[k].px += 0.8 * Eigen::Vector2d(std::cos(a), std::sin(a));
    }
  }
  BundleOptions fixed;
  fixed.holdout_fraction = 0.0;
  fixed.huber_px = 1.0;
  fixed.outlier_sigmas = 0.0;  // the loss alone (the corner rule: below)
  BundleOptions automatic = fixed;
  automatic.huber_px = 0.0;
  const BundleResult rf =
      RunBundle(s.nominal, s.rig, s.target, s.frames, fixed);
  const BundleResult ra =
      RunBundle(s.nominal, s.rig, s.target, s.frames, automatic);
  const double tips_fixed = TipRmsAgainstTruth(s, rf.calibrated, 200, 5);
  const double tips_auto = TipRmsAgainstTruth(s, ra.calibrated, 200, 5);
  std::printf("Huber 1 px: tips %.4f mm; automatic (%.3f px): %.4f mm\n",
              tips_fixed, ra.huber_px, tips_auto);
  EXPECT_DOUBLE_EQ(rf.huber_px, 1.0);
  EXPECT_GT(ra.huber_px, 0.05);
  EXPECT_LT(ra.huber_px, 0.2);  // 3 x 0.03 x sqrt(2)-ish
  EXPECT_LT(tips_auto, 0.7 * tips_fixed);
}

// Corners 1.2 px off (40 sigma) on one tag of every 3rd frame, the others
// of the tag good: the automatic Huber loss bounds their pull, the corner
// rule (BundleOptions::outlier_sigmas) removes them, and exactly them.
TEST(Bundle, CornersFarOutsideTheNoiseAreDroppedOneByOne) {
  SyntheticBundle s = QuietBh7(32);
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> angle(0, 2 * M_PI);
  int planted = 0;
  for (size_t f = 0; f < s.frames.size(); f += 3) {
    auto& corners = s.frames[f].corners;
    ASSERT_GE(corners.size(), 2u);
    for (int k = 0; k < 2; ++k) {
      const double a = angle(rng);
      corners[k].px += 1.2 * Eigen::Vector2d(std::cos(a), std::sin(a));
      ++planted;
    }
  }
  BundleOptions kept;
  kept.holdout_fraction = 0.0;
  kept.outlier_sigmas = 0.0;
  BundleOptions dropped = kept;
  dropped.outlier_sigmas = 10.0;
  const BundleResult rk = RunBundle(s.nominal, s.rig, s.target, s.frames, kept);
  const BundleResult rd =
      RunBundle(s.nominal, s.rig, s.target, s.frames, dropped);
  const double tips_kept = TipRmsAgainstTruth(s, rk.calibrated, 200, 5);
  const double tips_dropped = TipRmsAgainstTruth(s, rd.calibrated, 200, 5);
  std::printf(
      "%d corners 1.2 px off: Huber alone %.4f mm, dropped (%d): "
      "%.4f mm\n",
      planted, tips_kept, rd.dropped_corners, tips_dropped);
  EXPECT_EQ(rk.dropped_corners, 0);
  EXPECT_EQ(rd.dropped_corners, planted);
  EXPECT_EQ(rd.dropped_tags, 0);
  EXPECT_LT(tips_dropped, 0.85 * tips_kept);  // measured 0.76
  EXPECT_LT(rd.reproj_rms_px, 0.6 * rk.reproj_rms_px);
}

// Dim tags' corners err more (ObserveOptions::full_weight_contrast): one
// tag observation in every second frame has 0.3 px noise against 0.03 px
// elsewhere. Weighted by the inverse of their error they no longer pull the
// robot; the reported RMS stays in pixels.
TEST(Bundle, CornersWeighInverseToTheirError) {
  SyntheticBundle s = QuietBh7(33);
  std::mt19937_64 rng(10);
  std::normal_distribution<double> noise(0, 0.3);
  int dim = 0;
  for (size_t f = 0; f < s.frames.size(); f += 2) {
    for (BundleCorner& c : s.frames[f].corners) {
      if (c.camera != 0 || c.tag != s.frames[f].corners[0].tag) continue;
      c.px += Eigen::Vector2d(noise(rng), noise(rng));
      c.weight = 0.1;
      ++dim;
    }
  }
  ASSERT_GE(dim, 100);
  std::vector<BundleFrame> alike = s.frames;
  for (BundleFrame& f : alike) {
    for (BundleCorner& c : f.corners) c.weight = 1.0;
  }
  BundleOptions o;
  o.holdout_fraction = 0.0;
  const BundleResult weighted =
      RunBundle(s.nominal, s.rig, s.target, s.frames, o);
  const BundleResult plain = RunBundle(s.nominal, s.rig, s.target, alike, o);
  const double tips_weighted =
      TipRmsAgainstTruth(s, weighted.calibrated, 200, 5);
  std::vector<BundleFrame> zero = s.frames;
  zero[3].corners[0].weight = 0;
  EXPECT_THROW(RunBundle(s.nominal, s.rig, s.target, zero, o), InputError);
  const double tips_plain = TipRmsAgainstTruth(s, plain.calibrated, 200, 5);
  std::printf(
      "%d dim corners: alike %.4f mm (%.3f px), weighted %.4f mm (%.3f px)\n",
      dim, tips_plain, plain.reproj_rms_px, tips_weighted,
      weighted.reproj_rms_px);
  EXPECT_LT(tips_weighted, 0.8 * tips_plain);
  // Weighted, the dim corners are within the noise and stay in the fit
  // (alike, the outlier rule drops most of them); the reported RMS is in
  // pixels, where they are 0.3 px off (weighted it would be ~0.03).
  EXPECT_GT(weighted.reproj_rms_px, 0.1);
}

}  // namespace
}  // namespace kincal
