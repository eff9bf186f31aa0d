#include "diagnose/catalogue.h"

#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include "data/robot.h"
#include "synth/simulate.h"
#include "tests/testing/paths.h"

namespace kincal {
namespace {

TEST(CatalogueTest, CauseNamesRoundTrip) {
  EXPECT_EQ(CatalogueCauses().size(), 11u);
  EXPECT_EQ(TransmissionTerms(TransmissionCause(5)), 5);  // periodic support
  EXPECT_EQ(CyclicHarmonic("cyclic"), 1);
  EXPECT_EQ(CyclicHarmonic(CyclicCause(3)), 3);
  EXPECT_EQ(CyclicHarmonic("gain"), 0);
  EXPECT_EQ(TransmissionTerms(TransmissionCause(16)), 16);
  EXPECT_EQ(TransmissionTerms("transmission"), 0);
  EXPECT_EQ(SpecCauseName(CyclicCause(2)), "cyclic");
  EXPECT_EQ(SpecCauseName(TransmissionCause(24)), "transmission");
  EXPECT_EQ(SpecCauseName("backlash"), "backlash");
}

TEST(CatalogueTest, CandidatesFollowTheData) {
  const Robot bh7 =
      ReadRobotYaml(testing::SourceDir() + "/data/robots/bh7.yaml");
  SimulateOptions so;
  so.poses = 60;
  so.seed = 2;
  const SimulatedSession s = Simulate(bh7, so);
  ModelState state;
  state.chain = Chain::FromRobot(bh7);
  std::vector<Measurement> ms =
      MakeMeasurements(state.chain, s.observations, &state);
  const std::vector<Candidate> only_backlash =
      CatalogueCandidates(state.chain, ms, {"backlash", "gain"});
  std::set<std::string> causes;
  for (const Candidate& c : only_backlash) causes.insert(c.cause);
  EXPECT_TRUE(causes.count("gain"));
  EXPECT_EQ(causes.count("drift"), 0u);
  // Drift needs time stamps that vary.
  auto has_drift = [&]() {
    for (const Candidate& c : CatalogueCandidates(state.chain, ms))
      if (c.cause == "drift") return true;
    return false;
  };
  for (size_t i = 0; i < ms.size(); ++i) ms[i].input.t_h = 0.01 * i;
  EXPECT_TRUE(has_drift());
  for (Measurement& m : ms) m.input.t_h = 0.0;
  EXPECT_FALSE(has_drift());
  const Candidate cyc = MakeCandidate(state.chain, "cyclic", 2);
  ASSERT_EQ(cyc.params.size(), 2u);
  EXPECT_EQ(cyc.Label(state.chain), "cyclic:" + state.chain.rows[2].name);
  EXPECT_EQ(MakeCandidate(state.chain, TransmissionCause(8), 1).params.size(),
            8u);
  EXPECT_EQ(MakeCandidate(state.chain, "drift", -1).Label(state.chain),
            "drift");
}

TEST(CatalogueTest, MagnitudeUnitsAndDeltaMethod) {
  const Robot bh7 =
      ReadRobotYaml(testing::SourceDir() + "/data/robots/bh7.yaml");
  ModelState state;
  state.chain = Chain::FromRobot(bh7);
  const Candidate backlash = MakeCandidate(state.chain, "backlash", 2);
  *ParamAddress(&state, backlash.params[0]) = 0.001;  // rad
  // Without a covariance: the value, NaN interval.
  Magnitude m = CandidateMagnitude(backlash, state, FitSummary{}, 1.0);
  EXPECT_EQ(m.unit, "deg");
  EXPECT_NEAR(m.value, 0.001 * 180 / M_PI, 1e-12);
  EXPECT_TRUE(std::isnan(m.ci_low));
  // With a covariance of the parameter: sigma in degrees, 95 % interval.
  FitSummary fit;
  fit.params = backlash.params;
  fit.covariance = Eigen::MatrixXd::Constant(1, 1, 1e-8);  // sigma 1e-4 rad
  m = CandidateMagnitude(backlash, state, fit, 1.0);
  EXPECT_NEAR(m.sigma, 1e-4 * 180 / M_PI, 1e-12);
  EXPECT_NEAR(m.ci_high - m.value, 1.959964 * m.sigma, 1e-6 * m.sigma);
  // Cyclic: the amplitude of (cos, sin), interval clipped at 0.
  const Candidate cyc = MakeCandidate(state.chain, "cyclic", 1);
  *ParamAddress(&state, cyc.params[0]) = 3e-4;
  *ParamAddress(&state, cyc.params[1]) = 4e-4;
  m = CandidateMagnitude(cyc, state, FitSummary{}, 1.0);
  EXPECT_NEAR(m.value, 5e-4 * 180 / M_PI, 1e-12);
}

}  // namespace
}  // namespace kincal
