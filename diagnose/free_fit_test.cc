#include "diagnose/free_fit.h"

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
  ModelState a = state, b = state;
  FitOptions fo;
  fo.free = free;
  fo.bounds_center = &nominal;
  fo.compute_covariance = false;
  Fit(ms, fo, &a);
  FreeFitOptions ffo;
  ffo.free = free;
  ffo.bounds_center = &nominal;
  const double rss = FreeFit(ms, ffo, &b);
  double rss_a = 0;
  for (const Measurement& m : ms) rss_a += Residual(a, m).squaredNorm();
  EXPECT_NEAR(rss, rss_a, 1e-6 * rss_a + 1e-9);
  for (const ParamInfo& p : free) {
    EXPECT_NEAR(ParamValue(b, p), ParamValue(a, p),
                1e-6 * std::max(1.0, std::abs(ParamValue(a, p))))
        << p.name;
  }
}

}  // namespace
}  // namespace kincal
