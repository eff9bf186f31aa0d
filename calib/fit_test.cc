#include "calib/fit.h"

#include <gtest/gtest.h>

#include <cmath>

#include "data/error.h"
#include "data/robot.h"
#include "synth/simulate.h"
#include "tests/testing/paths.h"

namespace kincal {
namespace {

struct FitCase {
  Robot robot;
  SimulatedSession session;
  ModelState state;
  std::vector<Measurement> ms;
};

FitCase MakeSetup(double noise_mm) {
  FitCase s;
  s.robot = ReadRobotYaml(testing::SourceDir() + "/data/robots/bh7.yaml");
  SimulateOptions so;
  so.poses = 80;
  so.seed = 21;
  so.noise_mm = noise_mm;
  s.session = Simulate(s.robot, so);
  s.state.chain = Chain::FromRobot(s.session.nominal);
  s.ms = MakeMeasurements(s.state.chain, s.session.observations, &s.state);
  return s;
}

// The frame registered, then the geometry freed within its bounds: the
// fit lands at the noise level, its sigma0 estimates the noise, and the
// covariance gives finite 1-sigma for every free parameter.
TEST(FitTest, FrameThenGeometryReachNoise) {
  FitCase s = MakeSetup(0.02);
  ASSERT_EQ(s.ms.size(), 80u);
  EXPECT_EQ(DistinctPoses(s.ms), 80);
  InitializeFrameAndPoints(s.ms, &s.state);
  FitOptions options;
  options.free = FrameParams();
  const Chain nominal = s.state.chain;
  options.bounds_center = &nominal;
  for (const char* name : {".a", ".d"}) {
    for (int r = 1; r < 4; ++r)
      options.free.push_back(
          FindParam(s.state, s.state.chain.rows[r].name + name));
  }
  const FitSummary fit = Fit(s.ms, options, &s.state);
  EXPECT_TRUE(fit.converged) << fit.termination;
  EXPECT_LT(fit.final_rms_mm, fit.initial_rms_mm);
  EXPECT_EQ(fit.residual_mm.size(), s.ms.size());
  ASSERT_EQ(fit.params.size(), options.free.size());
  for (size_t i = 0; i < fit.sigmas.size(); ++i)
    EXPECT_TRUE(std::isfinite(fit.sigmas[i])) << fit.params[i].name;
  // Every free row entry stays within its box about the centre.
  for (const ParamInfo& p : fit.params) {
    if (p.kind != ParamKind::kRow) continue;
    EXPECT_LE(
        std::abs(ParamValue(s.state, p) - nominal.rows[p.block].p[p.index]),
        RowBound(nominal, p) * (1 + 1e-9))
        << p.name;
  }
  const Eigen::Vector3d r = Residual(s.state, s.ms[0]);
  EXPECT_NEAR(r.norm(), fit.residual_mm[0], 1e-9);
}

// The residual Jacobian matches central differences of Residual.
TEST(FitTest, ResidualJacobianMatchesDifferences) {
  FitCase s = MakeSetup(0.0);
  InitializeFrameAndPoints(s.ms, &s.state);
  s.ms.resize(5);
  std::vector<ParamInfo> params = FrameParams();
  params.push_back(FindParam(s.state, s.state.chain.rows[2].name + ".theta"));
  const Eigen::MatrixXd J = ResidualJacobian(s.ms, s.state, params);
  ASSERT_EQ(J.rows(), 15);
  ASSERT_EQ(J.cols(), static_cast<int>(params.size()));
  const double h = 1e-6;
  for (size_t c = 0; c < params.size(); ++c) {
    ModelState plus = s.state, minus = s.state;
    *ParamAddress(&plus, params[c]) += h;
    *ParamAddress(&minus, params[c]) -= h;
    for (size_t i = 0; i < s.ms.size(); ++i) {
      const Eigen::Vector3d d =
          (Residual(plus, s.ms[i]) - Residual(minus, s.ms[i])) / (2 * h);
      for (int a = 0; a < 3; ++a)
        EXPECT_NEAR(J(3 * i + a, c), d[a], 1e-4 * (1 + std::abs(d[a])))
            << params[c].name;
    }
  }
}

TEST(FitTest, ErrorStatsAndBounds) {
  const ErrorStats e = ComputeErrorStats({3.0, 4.0});
  EXPECT_EQ(e.n, 2);
  EXPECT_NEAR(e.mean_mm, 3.5, 1e-12);
  EXPECT_NEAR(e.rms_mm, std::sqrt(12.5), 1e-12);
  EXPECT_NEAR(e.max_mm, 4.0, 1e-12);
  FitCase s = MakeSetup(0.0);
  const ParamInfo a = FindParam(s.state, s.state.chain.rows[1].name + ".a");
  FitOptions options;
  options.bound_override[a.name] = 42.0;
  EXPECT_EQ(RowBound(s.state.chain, a, options), 42.0);
  EXPECT_EQ(RowBound(s.state.chain, a), s.state.chain.bound_length_mm);
}

TEST(FitTest, FrameNeedsNonCollinearPoints) {
  FitCase s = MakeSetup(0.0);
  s.ms.resize(2);
  EXPECT_THROW(InitializeFrameAndPoints(s.ms, &s.state), InputError);
}

}  // namespace
}  // namespace kincal
