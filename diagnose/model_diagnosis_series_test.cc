// diagnose model on several series (spec v3 column `series`): one
// measuring frame per series, the robot shared; validation series each
// scored with its own frame.

#include <gtest/gtest.h>

#include <cmath>

#include "data/urdf.h"
#include "diagnose/model_diagnosis.h"
#include "synth/simulate.h"
#include "tests/testing/paths.h"

namespace kincal {
namespace {

Robot Bh7() {
  return ReadRobotYaml(testing::SourceDir() + "/data/robots/bh7.yaml");
}

// A campaign of `poses` poses of `robot` (its geometry as it is, a 0.1 deg
// backlash in j3) seen from a frame moved by `shift_mm` along x and `turn`
// rad about z from the simulation's own, every row labelled `series`.
SimulatedSession Campaign(const Robot& robot, uint64_t seed, int poses,
                          double shift_mm, double turn,
                          const std::string& series) {
  SimulateOptions so;
  so.poses = poses;
  so.seed = seed;
  so.noise_mm = 0.02;
  so.sigma_length_mm = 0.0;
  so.sigma_angle_deg = 0.0;
  so.effects = {ParseEffect("backlash:j3:0.1", robot)};
  so.meas_from_base =
      std::array<double, 6>{0.1, -0.2, 0.3 + turn, 800 + shift_mm, 200, -300};
  SimulatedSession s = Simulate(robot, so);
  for (Observation& o : s.observations.rows) {
    o.series = series;
    o.pose = series + o.pose;
  }
  return s;
}

// The hidden robot: BH-7 with seed 5's geometric deviations.
Robot Hidden() {
  SimulateOptions so;
  so.poses = 10;
  so.seed = 5;
  return Simulate(Bh7(), so).truth;
}

Observations Concatenate(const Observations& a, const Observations& b) {
  Observations out = a;
  for (const Observation& o : b.rows) out.rows.push_back(o);
  return out;
}

// Trained on two series with different hidden frames, the diagnosis names
// the backlash as on one series, and two validation series (one file, two
// more frames) are predicted at the noise level, each with its own frame:
// one frame for both would leave hundreds of mm.
TEST(DiagnoseSeriesTest, FramePerSeriesInTrainingAndValidation) {
  const Robot hidden = Hidden();
  const Observations train =
      Concatenate(Campaign(hidden, 31, 150, 0, 0, "A").observations,
                  Campaign(hidden, 32, 150, 600, 0.7, "B").observations);
  DiagnoseOptions options;
  options.validation.push_back(
      Concatenate(Campaign(hidden, 33, 60, -400, -0.5, "V1").observations,
                  Campaign(hidden, 34, 60, 300, 1.2, "V2").observations));
  const DiagnosisResult r = DiagnoseModel(Bh7(), train, options);
  ASSERT_EQ(r.verdict, "effect_found");
  EXPECT_EQ(r.findings[0].cause, "backlash");
  EXPECT_EQ(r.findings[0].joint, "j3");
  EXPECT_NEAR(std::abs(r.findings[0].magnitude), 0.1, 0.025);
  EXPECT_EQ(r.state.NumFrames(), 2);
  const double floor_mm = std::sqrt(3.0) * 0.02;
  EXPECT_LT(r.final_heldout_rms_mm, 1.3 * floor_mm);
  EXPECT_LT(r.final_validation_rms_mm, 2.0 * floor_mm);
  EXPECT_LT(r.final_validation_rms_mm, r.nominal_validation_rms_mm);
}

}  // namespace
}  // namespace kincal
