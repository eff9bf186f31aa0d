#include "calib/free_fit.h"

#include <gtest/gtest.h>

#include "synth/simulate.h"
#include "tests/testing/paths.h"

namespace kincal {
namespace {

// The compact refit and calib/fit.h's Fit solve the same problem: same
// optimum on a UR10 session with thermal growth and mount compliance freed
// beside geometry and frame.
TEST(FreeFitTest, SameOptimumAsFit) {
  const Robot ur10 =
      ReadRobotYaml(testing::SourceDir() + "/data/robots/ur10.yaml");
  SimulateOptions so;
  so.poses = 120;
  so.seed = 3;
  so.effects = {ParseEffect("thermal:elbow_joint:0.2", ur10),
                ParseEffect("mount_compliance:0.02", ur10)};
  const SimulatedSession s = Simulate(ur10, so);
  const Chain nominal = Chain::FromRobot(ur10);
  ModelState state;
  state.chain = nominal;
  const std::vector<Measurement> ms =
      MakeMeasurements(nominal, s.observations, &state);
  InitializeFrameAndPoints(ms, &state);
  std::vector<ParamInfo> free = FrameParams();
  for (const char* name :
       {"shoulder_lift_joint.a", "elbow_joint.a", "elbow_joint.theta",
        "elbow_joint.thermal", "mount.iso"}) {
    free.push_back(FindParam(state, name));
  }
  ModelState a = state;
  FitOptions fo;
  fo.free = free;
  fo.bounds_center = &nominal;
  fo.compute_covariance = true;
  const FitSummary fit = Fit(ms, fo, &a);
  double rss_a = 0;
  for (const Measurement& m : ms) rss_a += Residual(a, m).squaredNorm();
  // Levenberg-Marquardt on the exact Jacobian.
  ModelState b = state;
  FreeFitOptions ffo;
  ffo.free = free;
  ffo.bounds_center = &nominal;
  const double rss = FreeFit(ms, ffo, &b);
  EXPECT_NEAR(rss, rss_a, 1e-6 * rss_a + 1e-9);
  for (const ParamInfo& p : free) {
    EXPECT_NEAR(ParamValue(b, p), ParamValue(a, p),
                1e-6 * std::max(1.0, std::abs(ParamValue(a, p))))
        << p.name;
  }
  // With covariance, at calib/fit.h's tolerances.
  ModelState c = state;
  ffo.function_tolerance = ffo.parameter_tolerance = 1e-12;
  const FitSummary exact = FreeFitWithCovariance(ms, ffo, &c);
  EXPECT_NEAR(exact.sigma0_mm, fit.sigma0_mm, 1e-6 * fit.sigma0_mm);
  ASSERT_EQ(exact.covariance.rows(), fit.covariance.rows());
  for (int i = 0; i < fit.covariance.rows(); ++i) {
    EXPECT_NEAR(exact.sigmas[i], fit.sigmas[i], 1e-4 * fit.sigmas[i])
        << free[i].name;
    for (int j = 0; j < fit.covariance.cols(); ++j) {
      const double scale =
          std::sqrt(fit.covariance(i, i) * fit.covariance(j, j));
      EXPECT_NEAR(exact.covariance(i, j), fit.covariance(i, j), 1e-4 * scale);
    }
  }
}

}  // namespace
}  // namespace kincal
