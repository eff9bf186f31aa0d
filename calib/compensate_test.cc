#include "calib/compensate.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <random>

#include "data/error.h"
#include "data/robot.h"
#include "tests/testing/paths.h"

namespace kincal {
namespace {

using ::testing::HasSubstr;

Robot LoadRobot(const std::string& name) {
  return ReadRobotYaml(testing::SourceDir() + "/data/robots/" + name);
}

// A UR10 whose real geometry and joint errors differ from the nominal rows
// it records (the controller's kinematics).
Robot ExtendedUr10() {
  const Robot nominal = LoadRobot("ur10.yaml");
  Robot real = nominal;
  real.joints[1].a_mm += 0.6;
  real.joints[2].alpha_deg += 0.05;
  real.joints[3].theta_deg -= 0.04;
  real.tool.d_mm += 0.3;
  real.extensions.push_back(
      {"backlash", "shoulder_lift_joint", {{"width", 0.04}}});
  real.extensions.push_back(
      {"compliance", "elbow_joint", {{"per_torque", 1e-5}}});
  real.extensions.push_back({"transmission",
                             "wrist_1_joint",
                             {{"lo", -150}, {"hi", -30}, {"s1", 0.02}}});
  real.SetNominal(nominal);
  return real;
}

std::vector<CompensateTarget> RandomTargets(const Robot& robot, int n,
                                            bool rotation, uint64_t seed) {
  const Chain nominal = Chain::FromRobot(robot.Nominal());
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<CompensateTarget> out;
  for (int i = 0; i < n; ++i) {
    const std::vector<double> q = {40 * u(rng),       -90 + 30 * u(rng),
                                   90 + 30 * u(rng),  -90 + 40 * u(rng),
                                   -90 + 40 * u(rng), 60 * u(rng)};
    const Eigen::Matrix4d pose = ModelPoseAtReadings(nominal, q, {}, false);
    CompensateTarget t;
    t.id = "T" + std::to_string(i + 1);
    t.target.position_mm = pose.block<3, 1>(0, 3);
    t.target.has_rotation = rotation;
    t.target.rotation = pose.block<3, 3>(0, 0);
    out.push_back(t);
  }
  return out;
}

// The real robot executing readings in order: its tip per command.
std::vector<Eigen::Vector3d> Execute(const Robot& real,
                                     const std::vector<CompensatedTarget>& c) {
  const Chain chain = Chain::FromRobot(real);
  std::vector<Eigen::Vector3d> tips;
  std::vector<double> previous, s;
  for (const CompensatedTarget& t : c) {
    IkContext context;
    s = ApproachDirections(previous, t.q, s);
    context.s = s;
    tips.push_back(ModelPoseAtReadings(chain, t.q, context).block<3, 1>(0, 3));
    previous = t.q;
  }
  return tips;
}

TEST(CompensateTest, ReachesTargetsThroughTheWholeModel) {
  const Robot real = ExtendedUr10();
  for (bool rotation : {false, true}) {
    const auto targets = RandomTargets(real, 40, rotation, 5);
    const CompensateResult r = Compensate(real, targets, CompensateOptions{});
    ASSERT_EQ(r.reached, 40) << r.targets[0].why;
    const auto tips = Execute(real, r.targets);
    double worst = 0.0, worst_nominal = 0.0;
    for (size_t i = 0; i < tips.size(); ++i) {
      worst = std::max(worst, (tips[i] - targets[i].target.position_mm).norm());
      worst_nominal = std::max(worst_nominal, r.targets[i].uncompensated_mm);
    }
    // Executed on the real robot in the same order (backlash included):
    // on target; the controller's own readings miss by the model's errors.
    EXPECT_LT(worst, 1e-5) << "rotation " << rotation;
    EXPECT_GT(worst_nominal, 0.5);
    EXPECT_GT(r.uncompensated_rms_mm, 0.3);
    EXPECT_TRUE(r.warnings.Has("no_covariance"));
  }
}

TEST(CompensateTest, JointProgramIsCompensatedToItsNominalPoses) {
  const Robot real = ExtendedUr10();
  CompensateTarget t;
  t.id = "p1";
  t.from_joints = true;
  t.seed = {10, -80, 100, -110, -85, 20};
  const CompensateResult r = Compensate(real, {t}, CompensateOptions{});
  ASSERT_TRUE(r.targets[0].reached);
  EXPECT_EQ(r.targets[0].q_nom, t.seed);
  const Eigen::Matrix4d want =
      ModelPoseAtReadings(Chain::FromRobot(real.Nominal()), t.seed, {}, false);
  const auto tips = Execute(real, r.targets);
  EXPECT_LT((tips[0] - want.block<3, 1>(0, 3)).norm(), 1e-5);
  // Readings change by the calibration's size (hundredths of a degree).
  double largest = 0.0;
  for (int j = 0; j < 6; ++j) {
    largest = std::max(largest, std::abs(r.targets[0].q[j] - t.seed[j]));
  }
  EXPECT_GT(largest, 1e-3);
  EXPECT_LT(largest, 1.0);
}

TEST(CompensateTest, SigmaPropagatesTheCovariance) {
  Robot real = ExtendedUr10();
  // tool.d moves the tip along the flange axis 1:1 (and the compliance's
  // torque a little): sigma = its sigma.
  real.fitted_on.poses = 100;
  real.fitted_on.covariance_params = {"tool.d"};
  real.fitted_on.covariance = Eigen::MatrixXd::Constant(1, 1, 0.04);
  real.fitted_on.systematic_rms_mm = 0.0;
  const auto targets = RandomTargets(real, 3, true, 7);
  const CompensateResult r = Compensate(real, targets, CompensateOptions{});
  for (const auto& t : r.targets) {
    ASSERT_TRUE(t.reached);
    EXPECT_NEAR(t.sigma_mm, 0.2, 1e-4);
    EXPECT_NEAR(t.predicted_mm, 0.2, 1e-4);
  }
  EXPECT_NEAR(r.predicted_rms_mm, 0.2, 1e-4);
  // The unexplained part adds in quadrature.
  real.fitted_on.systematic_rms_mm = 0.15;
  const CompensateResult s = Compensate(real, targets, CompensateOptions{});
  EXPECT_NEAR(s.targets[0].sigma_mm, 0.25, 1e-4);
  // A calibrated row's beta is found although its alpha is no longer 0.
  real.joints[2].alpha_deg = 0.01;
  real.joints[2].beta_deg = 0.002;
  real.fitted_on.covariance_params = {"elbow_joint.beta"};
  EXPECT_GT(Compensate(real, targets, CompensateOptions{}).targets[0].sigma_mm,
            0.0);
  // A covariance naming nothing in the model is refused.
  real.fitted_on.covariance_params = {"tool.q"};
  EXPECT_THROW(Compensate(real, targets, CompensateOptions{}), InputError);
}

// A model fitted on two series (one measuring frame each): the covariance's
// frame.<series>.* resolve; targets given in series B's instrument frame are
// located through B's frame, not the first series'.
TEST(CompensateTest, TargetsInTheMeasuringFrameOfANamedSeries) {
  Robot real = ExtendedUr10();
  real.fitted_on.poses = 100;
  real.fitted_on.has_frame = true;
  real.fitted_on.frame = {0, 0, 0, 0, 0, 0};
  const std::array<double, 6> frame_b = {0, 0, 90, 1000, -200, 50};
  real.fitted_on.series_frames = {{"A", real.fitted_on.frame}, {"B", frame_b}};
  real.fitted_on.covariance_params = {"frame.B.x", "tool.d"};
  real.fitted_on.covariance = Eigen::Matrix2d::Identity() * 0.04;
  real.fitted_on.systematic_rms_mm = 0.0;
  auto targets = RandomTargets(real, 3, false, 9);
  // Base -> B: rotation 90 deg about z, then the translation.
  const Eigen::Matrix3d rz =
      Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Eigen::Vector3d t_b(1000, -200, 50);
  auto in_b = targets;
  for (auto& t : in_b) t.target.position_mm = rz * t.target.position_mm + t_b;
  CompensateOptions options;
  options.targets_in_measuring_frame = true;
  options.series = "B";
  const CompensateResult r = Compensate(real, in_b, options);
  const CompensateResult base = Compensate(real, targets, CompensateOptions{});
  ASSERT_EQ(r.reached, 3);
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 6; ++j) {
      EXPECT_NEAR(r.targets[i].q[j], base.targets[i].q[j], 1e-6);
    }
    // frame.B.x (0.2 mm) and tool.d (0.2 mm, along the flange axis).
    EXPECT_GT(r.targets[i].sigma_mm, 0.2);
    EXPECT_LE(r.targets[i].sigma_mm, 0.2 * std::sqrt(2.0) + 1e-4);
  }
  EXPECT_FALSE(r.warnings.Has("series_frame_assumed"));
  // No series named: the first one's frame, and a warning says so.
  options.series.clear();
  EXPECT_TRUE(
      Compensate(real, targets, options).warnings.Has("series_frame_assumed"));
  // A series the model was not fitted on is refused, naming the others.
  options.series = "Z";
  try {
    Compensate(real, in_b, options);
    FAIL() << "unknown series accepted";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("A, B"));
  }
}

TEST(CompensateTest, ExtrapolationAndUnreachableTargetsAreNamed) {
  Robot real = ExtendedUr10();
  real.fitted_on.poses = 100;
  real.fitted_on.joint_range = {{-60, 60},   {-130, -50}, {50, 130},
                                {-150, -30}, {-150, -30}, {-90, 90}};
  auto targets = RandomTargets(real, 2, false, 9);
  targets[1].target.position_mm = Eigen::Vector3d(3000, 0, 0);  // too far
  const CompensateResult r = Compensate(real, targets, CompensateOptions{});
  EXPECT_TRUE(r.targets[0].reached);
  EXPECT_FALSE(r.targets[1].reached);
  EXPECT_THAT(r.targets[1].why, HasSubstr("do not reach"));
  EXPECT_EQ(r.reached, 1);
  // A target whose shoulder pan leaves the fitted travel.
  CompensateTarget far;
  far.id = "far";
  far.from_joints = true;
  far.seed = {100, -90, 90, -90, -90, 0};
  const CompensateResult e = Compensate(real, {far}, CompensateOptions{});
  ASSERT_EQ(e.targets[0].extrapolated.size(), 1u);
  EXPECT_THAT(e.targets[0].extrapolated[0],
              HasSubstr("shoulder_pan_joint at 100"));
  // A target inside a gap of the fitted readings is named too.
  real.fitted_on.joint_range[0] = {-60, 120};
  real.fitted_on.joint_gap.assign(6, {NAN, NAN});
  real.fitted_on.joint_gap[0] = {80, 110};
  const CompensateResult g = Compensate(real, {far}, CompensateOptions{});
  ASSERT_EQ(g.targets[0].extrapolated.size(), 1u);
  EXPECT_THAT(g.targets[0].extrapolated[0],
              HasSubstr("inside a gap of the fitted readings (80.000 .. "
                        "110.000)"));
}

TEST(CompensateTest, ThermalModelNeedsATemperature) {
  Robot real = ExtendedUr10();
  real.extensions.push_back({"thermal", "elbow_joint", {{"rate", 1e-5}}});
  real.fitted_on.poses = 50;
  real.fitted_on.thermal_input = "temp_c";
  real.fitted_on.temp_lo_c = 20;
  real.fitted_on.temp_hi_c = 30;
  const auto targets = RandomTargets(real, 1, false, 11);
  try {
    Compensate(real, targets, CompensateOptions{});
    FAIL() << "thermal model without a temperature accepted";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("--temp-c"));
  }
  CompensateOptions hot;
  hot.temp_c = 35.0;
  const CompensateResult r = Compensate(real, targets, hot);
  ASSERT_TRUE(r.targets[0].reached);
  ASSERT_EQ(r.targets[0].extrapolated.size(), 1u);
  EXPECT_THAT(r.targets[0].extrapolated[0], HasSubstr("temperature 35.00"));
}

}  // namespace
}  // namespace kincal
