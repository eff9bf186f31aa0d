#include "diagnose/free_fit.h"

#include <gtest/gtest.h>

#include "diagnose/model_diagnosis.h"
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
  // Both refit paths: Ceres autodiff in the free parameters, and
  // Levenberg-Marquardt on the exact Jacobian (with its covariance).
  for (bool exact : {false, true}) {
    SCOPED_TRACE(exact ? "exact Jacobian" : "Ceres autodiff");
    ModelState b = state;
    FreeFitOptions ffo;
    ffo.free = free;
    ffo.bounds_center = &nominal;
    ffo.exact_jacobian = exact;
    const double rss = FreeFit(ms, ffo, &b);
    EXPECT_NEAR(rss, rss_a, 1e-6 * rss_a + 1e-9);
    for (const ParamInfo& p : free) {
      EXPECT_NEAR(ParamValue(b, p), ParamValue(a, p),
                  1e-6 * std::max(1.0, std::abs(ParamValue(a, p))))
          << p.name;
    }
  }
  ModelState c = state;
  FreeFitOptions ffo;
  ffo.free = free;
  ffo.bounds_center = &nominal;
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

// The whole diagnosis on both refit paths (DiagnoseOptions::exact_jacobian)
// with a validation series: same findings, magnitudes, intervals, held-out
// and validation figures.
TEST(FreeFitTest, DiagnosisSameOnBothPaths) {
  const Robot ur10 =
      ReadRobotYaml(testing::SourceDir() + "/data/robots/ur10.yaml");
  auto sim = [&](uint64_t seed) {
    SimulateOptions so;
    so.poses = 150;
    so.seed = seed;
    so.effects = {ParseEffect("mount_compliance:0.03", ur10),
                  ParseEffect("cyclic:elbow_joint:0.05", ur10)};
    return Simulate(ur10, so);
  };
  const SimulatedSession train = sim(5), other = sim(6);
  DiagnosisResult r[2];
  for (int exact = 0; exact < 2; ++exact) {
    DiagnoseOptions o;
    o.exact_jacobian = exact == 1;
    o.validation = {other.observations};
    r[exact] = DiagnoseModel(train.nominal, train.observations, o);
  }
  ASSERT_EQ(r[0].findings.size(), r[1].findings.size());
  ASSERT_GE(r[1].findings.size(), 2u);
  for (size_t i = 0; i < r[0].findings.size(); ++i) {
    const Finding &a = r[0].findings[i], &b = r[1].findings[i];
    EXPECT_EQ(a.cause, b.cause);
    EXPECT_EQ(a.joint, b.joint);
    const double sigma = (a.ci_high - a.ci_low) / 3.92;
    EXPECT_NEAR(a.magnitude, b.magnitude, 0.01 * sigma) << a.cause;
    EXPECT_NEAR(a.ci_high - a.ci_low, b.ci_high - b.ci_low, 0.01 * sigma);
    EXPECT_NEAR(a.heldout_rms_after_mm, b.heldout_rms_after_mm,
                1e-4 * a.heldout_rms_after_mm);
    EXPECT_NEAR(a.validation_rms_after_mm, b.validation_rms_after_mm,
                1e-4 * a.validation_rms_after_mm);
  }
  EXPECT_NEAR(r[0].final_validation_rms_mm, r[1].final_validation_rms_mm,
              1e-4 * r[0].final_validation_rms_mm);
}

}  // namespace
}  // namespace kincal
