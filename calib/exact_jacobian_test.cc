#include "calib/exact_jacobian.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "data/urdf.h"
#include "synth/simulate.h"
#include "tests/testing/paths.h"

namespace kincal {
namespace {

// Every parameter a measured row depends on: geometry of every row entry
// (beta and the unused dh entry included), every joint error entry, the
// global block and the frame.
std::vector<ParamInfo> AllParams(const ModelState& state) {
  std::vector<ParamInfo> all;
  const Chain& c = state.chain;
  for (int r = 0; r <= c.num_joints(); ++r) {
    for (int i = 0; i < kRowBlockSize; ++i) {
      ParamInfo p;
      p.name = "row" + std::to_string(r) + "." + std::to_string(i);
      p.kind = ParamKind::kRow;
      p.block = r;
      p.index = i;
      all.push_back(p);
    }
  }
  for (int j = 0; j < c.num_joints(); ++j)
    for (int i = 0; i < kJointErrorBlockSize; ++i)
      all.push_back(JointErrorParam(c, j, i));
  for (const ParamInfo& p : DriftParams()) all.push_back(p);
  for (const ParamInfo& p : MountParams()) all.push_back(p);
  for (const ParamInfo& p : FrameParams()) all.push_back(p);
  return all;
}

// The exact Jacobian equals calib/fit.h's autodiff ResidualJacobian (and the
// residuals calib's Residual) with every family set to a non-zero value,
// time and thermal inputs varying, for a dh, an mdh and a urdf chain.
void Check(const Robot& robot, uint64_t seed) {
  SimulateOptions so;
  so.poses = 40;
  so.seed = seed;
  const SimulatedSession s = Simulate(robot, so);
  ModelState state;
  state.chain = Chain::FromRobot(robot);
  std::vector<Measurement> ms =
      MakeMeasurements(state.chain, s.observations, &state);
  ASSERT_GE(ms.size(), 10u);
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (Measurement& m : ms) {
    m.input.t_h = 2.0 + u(rng);
    m.input.thermal_x = 1.5 * u(rng);
  }
  ms[0].input.thermal_x = 0.0;  // the unscaled branch too
  Chain& c = state.chain;
  for (int r = 0; r <= c.num_joints(); ++r) c.rows[r].p[4] += 0.01 * u(rng);
  for (auto& e : c.joint_errors)
    for (double& v : e) v = 1e-3 * u(rng);
  c.joint_errors[1].fill(0.0);  // a joint without errors (read angle's trig)
  // Transmission series on the other joints' travel (part of the readings
  // fall outside it: both branches).
  for (int j = 0; j < c.num_joints(); ++j) {
    double lo = 1e300, hi = -1e300;
    for (const Measurement& m : ms) {
      lo = std::min(lo, m.input.q[j]);
      hi = std::max(hi, m.input.q[j]);
    }
    c.rows[j].transmission_lo = lo + 0.1 * (hi - lo);
    c.rows[j].transmission_hi = hi - 0.1 * (hi - lo);
  }
  // A periodic transmission on one revolute joint (calib/chain.h
  // ChainRow::periodic_basis): defined at every angle.
  c.rows[2].periodic_basis.resize(kPeriodicTerms * kMaxTransmissionTerms);
  for (double& b : c.rows[2].periodic_basis) b = 0.1 * u(rng);
  for (double& v : c.drift) v = 1e-3 * u(rng);
  for (int i = 0; i < 3; ++i) {
    state.meas_from_base[i] = 0.3 * u(rng);
    state.meas_from_base[3 + i] = 500.0 * u(rng);
  }
  const std::vector<ParamInfo> params = AllParams(state);
  const Eigen::MatrixXd reference = ResidualJacobian(ms, state, params);
  Eigen::VectorXd r;
  Eigen::MatrixXd J;
  ResidualsAndJacobian(ms, state, params, &r, &J);
  ASSERT_EQ(J.rows(), reference.rows());
  ASSERT_EQ(J.cols(), reference.cols());
  for (size_t i = 0; i < ms.size(); ++i) {
    EXPECT_LT((r.segment<3>(3 * i) - Residual(state, ms[i])).norm(), 1e-9);
  }
  for (int col = 0; col < J.cols(); ++col) {
    const double scale = 1.0 + reference.col(col).cwiseAbs().maxCoeff();
    EXPECT_LT((J.col(col) - reference.col(col)).cwiseAbs().maxCoeff(),
              1e-9 * scale)
        << robot.name << " " << params[col].name;
  }
  // A subset of the parameters (some joints' error entries, no global
  // entry): the same columns.
  std::vector<ParamInfo> some;
  std::vector<int> cols;
  for (int col = 0; col < static_cast<int>(params.size()); ++col) {
    const ParamInfo& p = params[col];
    if (p.kind == ParamKind::kDrift || (p.kind == ParamKind::kJointError &&
                                        (p.block % 2 == 1 || p.index % 3 != 0)))
      continue;
    some.push_back(p);
    cols.push_back(col);
  }
  Eigen::VectorXd r_some;
  Eigen::MatrixXd J_some;
  ResidualsAndJacobian(ms, state, some, &r_some, &J_some);
  for (size_t c = 0; c < cols.size(); ++c) {
    const double scale = 1.0 + reference.col(cols[c]).cwiseAbs().maxCoeff();
    EXPECT_LT((J_some.col(c) - reference.col(cols[c])).cwiseAbs().maxCoeff(),
              1e-9 * scale)
        << robot.name << " subset " << some[c].name;
  }
  // Without the Jacobian: the same residuals.
  Eigen::VectorXd r2;
  ResidualsAndJacobian(ms, state, params, &r2, nullptr);
  EXPECT_EQ((r2 - r).norm(), 0.0);

  // Poses shared among threads (blocks of 256 or more): the same residuals
  // and Jacobian; the normal matrix in row blocks: J^T J.
  std::vector<Measurement> many;
  while (many.size() < 1400) many.insert(many.end(), ms.begin(), ms.end());
  Eigen::VectorXd r_one, r_two;
  Eigen::MatrixXd J_one, J_two;
  ResidualsAndJacobian(many, state, params, &r_one, &J_one, 1);
  ResidualsAndJacobian(many, state, params, &r_two, &J_two, 2);
  EXPECT_EQ((r_two - r_one).norm(), 0.0);
  EXPECT_EQ((J_two - J_one).norm(), 0.0);
  const Eigen::MatrixXd normal = J_one.transpose() * J_one;
  for (int threads : {1, 2}) {
    const Eigen::MatrixXd a = NormalMatrix(J_one, threads);
    EXPECT_LT((a - normal).norm(), 1e-12 * normal.norm()) << threads;
    EXPECT_EQ((a - a.transpose()).norm(), 0.0) << threads;
  }
}

TEST(ExactJacobianTest, MatchesAutodiffDh) {
  Check(ReadRobotYaml(testing::SourceDir() + "/data/robots/ur10.yaml"), 1);
  Check(ReadRobotYaml(testing::SourceDir() + "/data/robots/bh7.yaml"), 2);
}

TEST(ExactJacobianTest, MatchesAutodiffMdh) {
  Robot r = ReadRobotYaml(testing::SourceDir() + "/data/robots/ur10.yaml");
  r.convention = Convention::kMdh;
  Check(r, 3);
}

TEST(ExactJacobianTest, MatchesAutodiffUrdf) {
  Check(ReadRobot(testing::SourceDir() + "/data/robots/industrial7.urdf"), 4);
}

}  // namespace
}  // namespace kincal
