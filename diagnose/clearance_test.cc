#include "diagnose/clearance.h"

#include <gtest/gtest.h>

#include "calib/calibrate.h"
#include "data/error.h"
#include "synth/simulate.h"
#include "tests/testing/paths.h"

namespace kincal {
namespace {

Robot Bh7() {
  return ReadRobotYaml(testing::SourceDir() + "/data/robots/bh7.yaml");
}

// Simulated session and the geometry calibrated on it (no extensions): the
// paper runs Section 4 after its Section 3 calibration.
struct Session {
  SimulatedSession sim;
  Robot calibrated;
};

Session Make(const std::vector<Effect>& effects, uint64_t seed,
             double noise_mm = 0.03, int poses = 120) {
  Session s;
  SimulateOptions so;
  so.poses = poses;
  so.noise_mm = noise_mm;
  so.effects = effects;
  so.seed = seed;
  s.sim = Simulate(Bh7(), so);
  CalibrateOptions co;
  co.holdout_fraction = 0.0;
  s.calibrated = Calibrate(s.sim.nominal, s.sim.observations, co).calibrated;
  return s;
}

TEST(ClearanceTest, LargeClearanceInJ3NamesJ3) {
  const Robot bh7 = Bh7();
  const Session s = Make({ParseEffect("backlash:j3:1.0", bh7)}, 5);
  const ClearanceResult r =
      DiagnoseClearance(s.calibrated, s.sim.observations, ClearanceOptions{});
  ASSERT_EQ(r.suspect, 2) << ClearanceJson(r).dump();
  // At the worst pose the j3 sweep removes the error: the minimum is near
  // the noise and the offset is about half the clearance width.
  const SweepCurve& j3 = r.sweeps[0].joints[2];
  EXPECT_LT(j3.error_min_mm, 0.25 * j3.error_before_mm);
  EXPECT_NEAR(std::abs(j3.at_offset), 0.5, 0.3);
  EXPECT_GT(r.sweeps[0].error_mm, 1.0);
}

TEST(ClearanceTest, CalibrateOptionMatchesCalibratingFirst) {
  const Robot bh7 = Bh7();
  const Session s = Make({ParseEffect("backlash:j3:1.0", bh7)}, 6);
  ClearanceOptions o;
  o.calibrate_geometry = true;
  const ClearanceResult with_option =
      DiagnoseClearance(s.sim.nominal, s.sim.observations, o);
  ClearanceOptions as_given;
  as_given.calibrate_geometry = false;
  const ClearanceResult by_hand =
      DiagnoseClearance(s.calibrated, s.sim.observations, as_given);
  EXPECT_EQ(with_option.suspect, 2);
  EXPECT_EQ(with_option.suspect, by_hand.suspect);
  EXPECT_NEAR(with_option.stats.rms_mm, by_hand.stats.rms_mm, 1e-3);
}

TEST(ClearanceTest, SweepAtZeroOffsetReproducesTheDeviation) {
  const Session s = Make({}, 3);
  ClearanceOptions o;
  o.gamma = 2.0;
  o.steps_per_side = 10;
  o.worst_poses = 3;
  const ClearanceResult r =
      DiagnoseClearance(s.calibrated, s.sim.observations, o);
  ASSERT_EQ(r.sweeps.size(), 3u);
  EXPECT_EQ(r.errors_mm.size(), s.sim.observations.rows.size());
  for (const PoseSweep& ps : r.sweeps) {
    ASSERT_EQ(ps.joints.size(), 5u);
    for (const SweepCurve& c : ps.joints) {
      EXPECT_EQ(c.offset.size(), 21u);
      EXPECT_DOUBLE_EQ(c.offset.front(), -2.0);
      EXPECT_NEAR(c.error_before_mm, ps.error_mm, 1e-9);
      EXPECT_LE(c.error_min_mm, c.error_before_mm + 1e-12);
      EXPECT_LE(std::abs(c.at_offset), 2.0 + 1e-9);
    }
  }
  // Worst first.
  EXPECT_GE(r.sweeps[0].error_mm, r.sweeps[1].error_mm);
  EXPECT_NEAR(r.sweeps[0].error_mm, r.stats.max_mm, 1e-12);
  const nlohmann::json j = ClearanceJson(r);
  EXPECT_EQ(j["worst_pose"], r.sweeps[0].pose);
  ASSERT_EQ(j["joints"].size(), 5u);
  EXPECT_EQ(j["joints"][0]["joint"], "j1");
  EXPECT_TRUE(j["joints"][0].contains("error_before_mm"));
  EXPECT_TRUE(j["joints"][0].contains("error_min_mm"));
  EXPECT_TRUE(j["joints"][0].contains("at_offset"));
  EXPECT_TRUE(j.contains("suspect"));
  const std::string csv = ClearanceCsv(r);
  EXPECT_NE(csv.find("kind,pose,joint,offset,error_mm"), std::string::npos);
  const std::string svg = ClearanceSvg(r);
  EXPECT_NE(svg.find("<svg"), std::string::npos);
  // The sweep plot's y axis ends at 3x the worst pose's error (the minimum
  // near zero stays visible), not at the sweep ends' tens of mm.
  EXPECT_NE(svg.find("clipped at 3x"), std::string::npos);
  EXPECT_NE(svg.find("error before"), std::string::npos);
}

TEST(ClearanceTest, TooFewPosesIsBadInput) {
  Session s = Make({}, 4, 0.03, 12);
  s.sim.observations.rows.resize(2);
  EXPECT_THROW(
      DiagnoseClearance(s.calibrated, s.sim.observations, ClearanceOptions{}),
      InputError);
  ClearanceOptions bad;
  bad.gamma = -1;
  EXPECT_THROW(DiagnoseClearance(s.calibrated, s.sim.observations, bad),
               InputError);
}

}  // namespace
}  // namespace kincal
