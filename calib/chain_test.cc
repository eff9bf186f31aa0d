#include "calib/chain.h"

#include <ceres/jet.h>
#include <gtest/gtest.h>

#include <cmath>

#include "data/robot.h"
#include "tests/testing/paths.h"

namespace kincal {
namespace {

constexpr double kDeg = M_PI / 180.0;

Chain Bh7() {
  return Chain::FromRobot(
      ReadRobotYaml(testing::SourceDir() + "/data/robots/bh7.yaml"));
}

PoseInput Input(const Chain& chain, const std::vector<double>& reading) {
  PoseInput in;
  for (int j = 0; j < chain.num_joints(); ++j) {
    in.q.push_back(chain.ReadingToInternal(j, reading[j]));
  }
  in.s.assign(reading.size(), 0.0);
  in.tau.assign(reading.size(), 0.0);
  return in;
}

// Closed form of BH-7's nominal chain, derived by hand from Table 1:
// three parallel vertical axes (j1 prismatic, j2, j3 revolute), then
// phi = q2 + q3 + q4 - 90 deg, z4 = (-sin phi, cos phi, 0),
// z5 = (-sin q5 cos phi, -sin q5 sin phi, -cos q5),
// tip = (200 c2 + 200 c23, 200 s2 + 200 s23, q1 - 170) + 145 z4 + 150 z5.
Eigen::Vector3d Bh7TipByHand(const std::vector<double>& r) {
  const double q1 = r[0], q2 = r[1] * kDeg, q3 = r[2] * kDeg;
  const double q4 = r[3] * kDeg, q5 = r[4] * kDeg;
  const double phi = q2 + q3 + q4 - M_PI / 2;
  const Eigen::Vector3d o3(200 * std::cos(q2) + 200 * std::cos(q2 + q3),
                           200 * std::sin(q2) + 200 * std::sin(q2 + q3), q1);
  const Eigen::Vector3d z4(-std::sin(phi), std::cos(phi), 0);
  const Eigen::Vector3d z5(-std::sin(q5) * std::cos(phi),
                           -std::sin(q5) * std::sin(phi), -std::cos(q5));
  return o3 + Eigen::Vector3d(0, 0, -170) + 145 * z4 + 150 * z5;
}

TEST(ChainTest, Bh7AtPaperPoseMatchesHandComputation) {
  const Chain chain = Bh7();
  // The paper's pose dt1 (Section 4): j1 in mm, j2..j5 in degrees.
  const std::vector<double> dt1 = {78.4602, 36.0462, 95.4866, 153.0275,
                                   -45.1143};
  const Eigen::Vector3d tip = TipInBase(chain, Input(chain, dt1));
  const Eigen::Vector3d expected = Bh7TipByHand(dt1);
  EXPECT_NEAR((tip - expected).norm(), 0.0, 1e-9)
      << "fk " << tip.transpose() << " hand " << expected.transpose();
  // A coarse sanity value: the tip is within reach of the base.
  EXPECT_LT(tip.head<2>().norm(), 400.0 + 145.0 + 150.0);
}

TEST(ChainTest, Bh7MatchesHandComputationAtRandomPoses) {
  const Chain chain = Bh7();
  std::srand(7);
  for (int k = 0; k < 50; ++k) {
    std::vector<double> r(5);
    r[0] = std::rand() % 150;
    for (int j = 1; j < 5; ++j) r[j] = (std::rand() % 3600) / 10.0 - 180.0;
    EXPECT_NEAR((TipInBase(chain, Input(chain, r)) - Bh7TipByHand(r)).norm(),
                0.0, 1e-9);
  }
}

// Standard DH and modified DH describe the same robot when the rows are
// re-parameterised (Craig 3.4): here a planar 2R arm.
TEST(ChainTest, DhAndMdhAgreeOnPlanarArm) {
  Robot dh;
  dh.convention = Convention::kDh;
  dh.joints = {RobotRow{}, RobotRow{}};
  dh.joints[0].name = "j1";
  dh.joints[0].a_mm = 300;
  dh.joints[1].name = "j2";
  dh.joints[1].a_mm = 250;
  Robot mdh = dh;
  mdh.convention = Convention::kMdh;
  mdh.joints[0].a_mm = 0;
  mdh.joints[1].a_mm = 300;
  mdh.tool.a_mm = 250;
  const Chain c_dh = Chain::FromRobot(dh), c_mdh = Chain::FromRobot(mdh);
  for (double q1 : {-40.0, 10.0, 75.0}) {
    for (double q2 : {-120.0, 0.0, 33.0}) {
      const Eigen::Vector3d a = TipInBase(c_dh, Input(c_dh, {q1, q2}));
      const Eigen::Vector3d b = TipInBase(c_mdh, Input(c_mdh, {q1, q2}));
      EXPECT_NEAR((a - b).norm(), 0.0, 1e-9);
      EXPECT_NEAR(a.x(),
                  300 * std::cos(q1 * kDeg) + 250 * std::cos((q1 + q2) * kDeg),
                  1e-9);
    }
  }
}

// Autodiff through the templated FK equals central differences.
TEST(ChainTest, AutodiffJacobianMatchesNumeric) {
  const Chain chain = Bh7();
  const PoseInput in =
      Input(chain, {78.4602, 36.0462, 95.4866, 153.0275, -45.1143});
  using J = ceres::Jet<double, kRowBlockSize>;
  for (int row = 0; row < static_cast<int>(chain.rows.size()); ++row) {
    std::vector<std::array<J, kRowBlockSize>> rows_j(chain.rows.size());
    std::vector<const J*> ptrs;
    for (size_t r = 0; r < chain.rows.size(); ++r) {
      for (int k = 0; k < kRowBlockSize; ++k) {
        rows_j[r][k] = J(chain.rows[r].p[k]);
        if (static_cast<int>(r) == row) rows_j[r][k].v[k] = 1.0;
      }
      ptrs.push_back(rows_j[r].data());
    }
    const Vec3<J> tip = TipInBase<J>(chain, ptrs.data(), nullptr, nullptr, in);
    for (int k = 0; k < kRowBlockSize; ++k) {
      const double h = 1e-6;
      Chain plus = chain, minus = chain;
      plus.rows[row].p[k] += h;
      minus.rows[row].p[k] -= h;
      const Eigen::Vector3d num =
          (TipInBase(plus, in) - TipInBase(minus, in)) / (2 * h);
      for (int a = 0; a < 3; ++a) {
        EXPECT_NEAR(tip[a].v[k], num[a], 1e-5 * (1 + std::abs(num[a])))
            << "row " << row << " param " << k << " axis " << a;
      }
    }
  }
}

TEST(ChainTest, JointErrorModelShiftsJointValue) {
  const Chain nominal = Bh7();
  Chain with_backlash = nominal;
  with_backlash.joint_errors[2][kBacklash] = 0.5 * kDeg;  // j3, 0.5 deg
  PoseInput in = Input(nominal, {50, 10, 20, 30, 40});
  in.s[2] = 1.0;  // j3 approached moving positive: q = q_read - b/2
  PoseInput shifted = Input(nominal, {50, 10, 19.75, 30, 40});
  EXPECT_NEAR(
      (TipInBase(with_backlash, in) - TipInBase(nominal, shifted)).norm(), 0.0,
      1e-9);
  // Gain: q = (1 + g) q_read.
  Chain with_gain = nominal;
  with_gain.joint_errors[1][kGain] = 0.01;
  PoseInput gain_shifted = Input(nominal, {50, 10.1, 20, 30, 40});
  EXPECT_NEAR((TipInBase(with_gain, Input(nominal, {50, 10, 20, 30, 40})) -
               TipInBase(nominal, gain_shifted))
                  .norm(),
              0.0, 1e-9);
}

TEST(ChainTest, ApproachDirectionAndGravityTorque) {
  const Chain chain = Bh7();
  Observations obs;
  obs.joint_names = {"j1", "j2", "j3", "j4", "j5"};
  auto row = [](std::vector<double> q) {
    Observation o;
    o.q = q;
    return o;
  };
  obs.rows = {row({0, 0, 0, 0, 0}), row({10, 5, 0, 0, 0}),
              row({10, 2, 0, 0, 0}), row({5, 2, 0, 0, 0})};
  const auto inputs = MakePoseInputs(chain, obs);
  ASSERT_EQ(inputs.size(), 4u);
  EXPECT_EQ(inputs[0].s[1], 0.0);   // unknown at the first row
  EXPECT_EQ(inputs[1].s[1], 1.0);   // j2 moved up
  EXPECT_EQ(inputs[2].s[1], -1.0);  // j2 moved down
  EXPECT_EQ(inputs[3].s[1], -1.0);  // j2 did not move: keeps its sign
  EXPECT_EQ(inputs[3].s[0], -1.0);  // j1 moved down
  // BH-7's j1..j4 axes are vertical: gravity has no torque about them; the
  // prismatic j1 carries the full weight (z . g = -1).
  EXPECT_NEAR(inputs[1].tau[0], -1.0, 1e-12);
  EXPECT_NEAR(inputs[1].tau[1], 0.0, 1e-9);
  // j5's axis is horizontal: a tool sticking out sideways has a torque.
  std::vector<Eigen::Vector3d> origins, axes;
  JointAxesInBase(chain, inputs[1].q, &origins, &axes);
  EXPECT_NEAR(axes[4].z(), 0.0, 1e-12);
}

// The cached transmission terms (PoseInput::transmission_sines) are the
// terms TransmissionError evaluates one at a time: for a periodic basis and
// for a sine series over the travel.
TEST(ChainTest, CachedTransmissionTermsMatchTheFunction) {
  Chain c = Bh7();
  c.rows[1].periodic_basis.resize(kPeriodicTerms * kMaxTransmissionTerms);
  for (size_t i = 0; i < c.rows[1].periodic_basis.size(); ++i) {
    c.rows[1].periodic_basis[i] = std::sin(0.37 * static_cast<double>(i));
  }
  c.rows[2].transmission_lo = -1.0;
  c.rows[2].transmission_hi = 1.5;
  const PoseInput base = Input(c, {50, 200, -40, 30, 10});
  for (double q2 : {-2.9, 0.3, 3.0}) {
    PoseInput in = base;
    in.q[1] = q2;
    FillTransmissionSines(c, &in);
    ASSERT_EQ(in.transmission_sines.size(),
              static_cast<size_t>(kMaxTransmissionTerms * c.num_joints()));
    for (int j : {1, 2}) {
      for (int k = 0; k < kMaxTransmissionTerms; ++k) {
        double unit[kMaxTransmissionTerms] = {};
        unit[k] = 1.0;
        EXPECT_NEAR(in.transmission_sines[kMaxTransmissionTerms * j + k],
                    TransmissionError(unit, in.q[j], c.rows[j]), 1e-12)
            << "joint " << j << " term " << k;
      }
    }
  }
}

TEST(ChainTest, RobotRoundTripKeepsValuesAndExtensions) {
  const Robot robot =
      ReadRobotYaml(testing::SourceDir() + "/data/robots/bh7.yaml");
  Chain chain = Chain::FromRobot(robot);
  chain.rows[2].p[2] = 199.5;
  chain.joint_errors[2][kBacklash] = 0.3 * kDeg;
  chain.drift = {0.1, 0, 0};
  const Robot out = chain.ToRobot(robot);
  EXPECT_DOUBLE_EQ(out.joints[2].a_mm, 199.5);
  ASSERT_EQ(out.extensions.size(), 2u);
  const Chain back =
      Chain::FromRobot(ParseRobotYaml(FormatRobotYaml(out), "roundtrip.yaml"));
  EXPECT_NEAR(back.joint_errors[2][kBacklash], 0.3 * kDeg, 1e-15);
  EXPECT_DOUBLE_EQ(back.drift[0], 0.1);
  EXPECT_DOUBLE_EQ(back.rows[2].p[2], 199.5);
}

}  // namespace
}  // namespace kincal
