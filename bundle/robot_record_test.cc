#include "bundle/robot_record.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "bundle/bundle.h"
#include "bundle/testing/synthetic.h"
#include "calib/chain.h"
#include "calib/compensate.h"
#include "calib/inverse_kinematics.h"
#include "data/rigid3.h"
#include "data/robot.h"
#include "synth/simulate.h"
#include "tests/testing/paths.h"

namespace kincal {
namespace {

using ::testing::Contains;

Robot Bh7() {
  return ReadRobotYaml(testing::SourceDir() + "/data/robots/bh7.yaml");
}

int IndexOf(const std::vector<std::string>& names, const std::string& name) {
  const auto it = std::find(names.begin(), names.end(), name);
  return it == names.end() ? -1 : static_cast<int>(it - names.begin());
}

// The frames whose joint 1 reading is in the top quarter of the session see
// no tags: the session's travel is wider than what the fit can use. The
// robot file's covariance has the bundle's sigma^2 on its diagonal (interface
// units) and names the measuring frame and the tool row's position; its
// travel and pose count are the training frames', not the session's.
TEST(RobotRecord, CovarianceDiagonalIsSigmaSquaredAndTravelIsTheFittedFrames) {
  SyntheticBundleOptions so;
  so.frames = 80;
  so.noise_px = 0.1;
  so.seed = 11;
  SyntheticBundle s = MakeSyntheticBundle(Bh7(), so);
  std::vector<double> q1;
  for (const BundleFrame& f : s.frames) q1.push_back(f.q_reading[1]);
  std::sort(q1.begin(), q1.end());
  const double cut = q1[q1.size() * 3 / 4];
  for (BundleFrame& f : s.frames) {
    if (f.q_reading[1] > cut) f.corners.clear();
  }
  BundleOptions o;
  const BundleResult r = RunBundle(s.nominal, s.rig, s.target, s.frames, o);
  const FitRecord& rec = r.calibrated.fitted_on;

  ASSERT_FALSE(r.params.empty());
  ASSERT_EQ(rec.covariance.rows(),
            static_cast<int>(rec.covariance_params.size()));
  for (const BundleParam& p : r.params) {
    const int k = IndexOf(rec.covariance_params, p.name);
    ASSERT_GE(k, 0) << p.name;
    ASSERT_TRUE(std::isfinite(p.sigma)) << p.name;
    EXPECT_NEAR(rec.covariance(k, k), p.sigma * p.sigma,
                1e-9 * p.sigma * p.sigma)
        << p.name;
  }
  EXPECT_THAT(rec.covariance_params, Contains("frame.rx"));
  EXPECT_THAT(rec.covariance_params, Contains("frame.z"));
  EXPECT_THAT(rec.covariance_params, Contains("tool.d"));
  EXPECT_TRUE(rec.has_frame);
  EXPECT_EQ(rec.frame[3], r.rig_from_base[3]);
  // The frame's variances: the bundle's for rig_from_base (interface units).
  const int p = static_cast<int>(r.params.size());
  const int tx = IndexOf(rec.covariance_params, "frame.x");
  EXPECT_NEAR(rec.covariance(tx, tx), r.covariance(p + 3, p + 3),
              1e-9 * r.covariance(p + 3, p + 3));

  // Travel and poses: the training frames the fit used.
  EXPECT_EQ(rec.poses, r.train_frames);
  ASSERT_EQ(rec.joint_range.size(), s.nominal.joints.size());
  for (size_t j = 0; j < s.nominal.joints.size(); ++j) {
    double lo = 1e300, hi = -1e300;
    for (int i : r.train) {
      lo = std::min(lo, s.frames[i].q_reading[j]);
      hi = std::max(hi, s.frames[i].q_reading[j]);
    }
    EXPECT_EQ(rec.joint_range[j][0], lo) << j;
    EXPECT_EQ(rec.joint_range[j][1], hi) << j;
  }
  EXPECT_LE(rec.joint_range[1][1], cut);
  EXPECT_GT(q1.back(), cut);
}

// Where the calibrated robot's tool row truly ends, in the measuring frame:
// the needle tip in the rig frame on a stand; with the cameras on the
// flange the rig origin in the target frame.
Eigen::Vector3d TrueToolRowEnd(const SyntheticBundle& s, const Chain& truth,
                               const std::vector<double>& q) {
  const Eigen::Vector3d tip =
      ModelPoseAtReadings(truth, q, {}).block<3, 1>(0, 3);
  if (s.rig.mount != RigMount::kFlange) return s.rig_from_base * tip;
  Chain to_flange = truth;  // a DH tool row of zeros is the identity
  to_flange.rows[to_flange.tool_row()].p.fill(0.0);
  const Rigid3 base_from_flange =
      Rigid3::FromMatrix(ModelPoseAtReadings(to_flange, q, {}));
  return s.base_from_target.Inverse() *
         (base_from_flange * s.flange_from_rig.t);
}

// RMS over `seeds` seeds x 50 fresh poses of |model - truth| / sigma for the
// tool row's end in the measuring frame: the model through the file's
// frame, sigma from compensate's TipUncertainty on the file's covariance.
double ToolRowEndErrorOverSigma(bool flange, int seeds) {
  double sum_z2 = 0;
  int n = 0;
  for (int seed = 1; seed <= seeds; ++seed) {
    SyntheticBundleOptions so;
    so.frames = 80;
    so.noise_px = 0.1;
    so.seed = 700 + seed;
    so.only_identifiable = true;
    so.flange = flange;
    const SyntheticBundle s = MakeSyntheticBundle(Bh7(), so);
    BundleOptions o;
    o.holdout_fraction = 0.0;
    const BundleResult r = RunBundle(s.nominal, s.rig, s.target, s.frames, o);
    const Chain model = Chain::FromRobot(r.calibrated);
    const Chain truth = Chain::FromRobot(s.truth);
    const TipUncertainty uncertainty(r.calibrated, model);
    std::array<double, 6> frame = r.calibrated.fitted_on.frame;
    for (int k = 0; k < 3; ++k) frame[k] *= M_PI / 180.0;
    SimulateOptions fo;
    fo.poses = 50;
    fo.noise_mm = 0;
    fo.sigma_length_mm = 0;
    fo.sigma_angle_deg = 0;
    fo.seed = 900 + seed;
    const SimulatedSession fresh = Simulate(s.truth, fo);
    double seed_z2 = 0;
    for (const Observation& row : fresh.observations.rows) {
      const Eigen::Vector3d model_end = ApplyFrame(
          frame.data(),
          Vec3<double>(
              ModelPoseAtReadings(model, row.q, {}).block<3, 1>(0, 3)));
      const double sigma = uncertainty.SigmaMm(row.q, IkContext{});
      EXPECT_TRUE(std::isfinite(sigma) && sigma > 0);
      const double z =
          (model_end - TrueToolRowEnd(s, truth, row.q)).norm() / sigma;
      seed_z2 += z * z;
    }
    std::printf("  %s seed %d: RMS error/sigma %.3f over %zu fresh poses\n",
                flange ? "flange" : "stand", seed,
                std::sqrt(seed_z2 / fresh.observations.rows.size()),
                fresh.observations.rows.size());
    sum_z2 += seed_z2;
    n += static_cast<int>(fresh.observations.rows.size());
  }
  const double rms_z = std::sqrt(sum_z2 / n);
  std::printf("%s: RMS of error / predicted sigma over %d poses: %.3f\n",
              flange ? "flange" : "stand", n, rms_z);
  return rms_z;
}

// The covariance the robot file carries predicts the error at fresh poses
// (pixel noise is the only error here): RMS of error / sigma within
// 0.7..1.4 on a stand (the needle tip in the rig frame) and with the cameras
// on the flange (the rig origin in the target frame).
TEST(RobotRecord, SigmaOfTheFileMatchesTheErrorAtFreshPoses) {
  const double stand = ToolRowEndErrorOverSigma(false, 6);
  EXPECT_GT(stand, 0.7);
  EXPECT_LT(stand, 1.4);
  const double flange = ToolRowEndErrorOverSigma(true, 4);
  EXPECT_GT(flange, 0.7);
  EXPECT_LT(flange, 1.4);
}

}  // namespace
}  // namespace kincal
