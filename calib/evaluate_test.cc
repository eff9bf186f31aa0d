#include "calib/evaluate.h"

#include <gtest/gtest.h>

#include "data/error.h"
#include "data/robot.h"
#include "synth/simulate.h"
#include "tests/testing/paths.h"

namespace kincal {
namespace {

SimulatedSession Session() {
  const Robot bh7 =
      ReadRobotYaml(testing::SourceDir() + "/data/robots/bh7.yaml");
  SimulateOptions so;
  so.poses = 60;
  so.seed = 8;
  so.noise_mm = 0.02;
  return Simulate(bh7, so);
}

// The true model with only the frame registered predicts at the noise
// level; the nominal one (the robot's deviations unknown) does not.
TEST(EvaluateTest, TrueModelAtNoiseNominalWorse) {
  const SimulatedSession s = Session();
  const EvaluateResult truth = Evaluate(s.truth, s.observations);
  EXPECT_EQ(truth.stats.n, 60);
  EXPECT_EQ(truth.rows.size(), 60u);
  EXPECT_LT(truth.stats.rms_mm, 0.1);
  EXPECT_FALSE(truth.has_robust);
  const EvaluateResult nominal = Evaluate(s.nominal, s.observations);
  EXPECT_GT(nominal.stats.rms_mm, 5 * truth.stats.rms_mm);
}

// A few rows 5 mm off are listed and left out of the robust figures.
TEST(EvaluateTest, GrossRowsListedAndLeftOut) {
  SimulatedSession s = Session();
  for (int k : {3, 17}) s.observations.rows[k].p_in_meas.y() += 5.0;
  const EvaluateResult r = Evaluate(s.truth, s.observations);
  ASSERT_TRUE(r.has_robust);
  ASSERT_EQ(r.outliers.size(), 2u);
  for (const RowOutlier& o : r.outliers) EXPECT_TRUE(o.excluded);
  EXPECT_EQ(r.robust.stats.n, 58);
  EXPECT_LT(r.robust.stats.rms_mm, 0.1);
  EXPECT_GT(r.stats.rms_mm, r.robust.stats.rms_mm);
}

TEST(EvaluateTest, NoUsableRowIsInputError) {
  SimulatedSession s = Session();
  for (Observation& o : s.observations.rows) o.has_point = false;
  EXPECT_THROW(Evaluate(s.truth, s.observations), InputError);
}

}  // namespace
}  // namespace kincal
