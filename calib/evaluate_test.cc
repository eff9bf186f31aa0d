#include "calib/evaluate.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "data/error.h"
#include "data/robot.h"
#include "synth/simulate.h"
#include "tests/testing/paths.h"

namespace kincal {
namespace {

SimulateOptions SessionOptions() {
  SimulateOptions so;
  so.poses = 60;
  so.seed = 8;
  so.noise_mm = 0.02;
  return so;
}

SimulatedSession Session() {
  const Robot bh7 =
      ReadRobotYaml(testing::SourceDir() + "/data/robots/bh7.yaml");
  return Simulate(bh7, SessionOptions());
}

// A second campaign of Session()'s robot with the instrument moved: its
// frame turned by `turn_rad` about the rotation vector's z and moved 500 mm
// along x.
SimulatedSession MovedInstrument(const SimulatedSession& a, double turn_rad) {
  std::array<double, 6> moved = a.meas_from_base;
  moved[2] += turn_rad;
  moved[3] += 500;
  SimulateOptions so = SessionOptions();
  so.meas_from_base = moved;
  return Simulate(a.nominal, so);
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

// Two campaigns of the same robot with the instrument moved in between
// (rotation vector z + 30 deg, 500 mm along x): one frame per series brings
// both to the noise level; one frame for all rows is hundreds of mm off.
TEST(EvaluateTest, OneFramePerSeries) {
  const SimulatedSession a = Session();
  const SimulatedSession b = MovedInstrument(a, 30.0 * M_PI / 180.0);
  Observations both = a.observations;
  for (Observation& o : both.rows) o.series = "A";
  for (Observation o : b.observations.rows) {
    o.pose = "b" + o.pose;
    o.series = "B";
    both.rows.push_back(o);
  }
  const EvaluateResult r = Evaluate(a.truth, both);
  ASSERT_EQ(r.series.size(), 2u);
  EXPECT_EQ(r.series[0].name, "A");
  EXPECT_EQ(r.series[1].name, "B");
  EXPECT_EQ(r.stats.n, 120);
  for (const SeriesEvaluation& s : r.series) {
    EXPECT_EQ(s.stats.n, 60);
    EXPECT_EQ(s.usable.size(), 60u);
    EXPECT_LT(s.stats.rms_mm, 0.1);
  }
  EXPECT_LT(r.stats.rms_mm, 0.1);
  EXPECT_FALSE(r.has_robust);
  // Each series' registered frame is its own true frame.
  for (int k = 0; k < 6; ++k) {
    const double tol = k < 3 ? 1e-3 : 0.5;
    EXPECT_NEAR(r.series[0].state.meas_from_base[k], a.meas_from_base[k], tol);
    EXPECT_NEAR(r.series[1].state.meas_from_base[k], b.meas_from_base[k], tol);
  }
  EXPECT_EQ(r.state.meas_from_base, r.series[0].state.meas_from_base);

  Observations unlabelled = both;
  for (Observation& o : unlabelled.rows) o.series.clear();
  const EvaluateResult one = Evaluate(a.truth, unlabelled);
  ASSERT_EQ(one.series.size(), 1u);
  EXPECT_GT(one.stats.rms_mm, 100.0);
}

// A labelled file with one series gives the unlabelled figures exactly.
TEST(EvaluateTest, OneLabelledSeriesSameAsNone) {
  const SimulatedSession s = Session();
  Observations labelled = s.observations;
  for (Observation& o : labelled.rows) o.series = "C";
  const EvaluateResult plain = Evaluate(s.truth, s.observations);
  const EvaluateResult r = Evaluate(s.truth, labelled);
  ASSERT_EQ(r.series.size(), 1u);
  EXPECT_EQ(r.series[0].name, "C");
  EXPECT_EQ(r.stats.rms_mm, plain.stats.rms_mm);
  EXPECT_EQ(r.stats.max_mm, plain.stats.max_mm);
  EXPECT_EQ(r.errors_mm, plain.errors_mm);
  EXPECT_EQ(r.series[0].stats.rms_mm, plain.stats.rms_mm);
}

// Gross rows of one series are found against that series' frame.
TEST(EvaluateTest, GrossRowsPerSeries) {
  SimulatedSession s = Session();
  for (size_t i = 0; i < s.observations.rows.size(); ++i) {
    s.observations.rows[i].series = i < 30 ? "A" : "B";
  }
  s.observations.rows[40].p_in_meas.y() += 5.0;
  const EvaluateResult r = Evaluate(s.truth, s.observations);
  ASSERT_EQ(r.outliers.size(), 1u);
  EXPECT_EQ(r.outliers[0].row, 40);
  ASSERT_TRUE(r.has_robust);
  EXPECT_FALSE(r.series[0].has_robust);
  EXPECT_TRUE(r.series[1].has_robust);
  EXPECT_EQ(r.series[1].robust_stats.n, 29);
  EXPECT_EQ(r.robust.stats.n, 59);
  EXPECT_LT(r.robust.stats.rms_mm, 0.1);
}

// A series too small to register a frame is bad input naming the series.
TEST(EvaluateTest, TooSmallSeriesIsInputErrorNamingIt) {
  SimulatedSession s = Session();
  for (size_t i = 0; i < s.observations.rows.size(); ++i) {
    s.observations.rows[i].series = i < 58 ? "A" : "tiny";
  }
  try {
    Evaluate(s.truth, s.observations);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("series 'tiny'"), std::string::npos)
        << e.what();
  }
}

// Two campaigns concatenated without labels (the second frame turned and
// moved): the jump is found at the first row of the second campaign; one
// campaign, or the nominal model on one, shows none.
TEST(EvaluateTest, FindsFrameJumpOfUnlabelledCampaigns) {
  const SimulatedSession a = Session();
  const SimulatedSession b = MovedInstrument(a, 0.5);
  Observations both = a.observations;
  for (size_t i = 0; i < 40; ++i) {
    Observation o = b.observations.rows[i];
    o.pose = "b" + o.pose;
    both.rows.push_back(o);
  }
  const FrameJump jump = FindFrameJump(a.nominal, both);
  EXPECT_TRUE(jump.found);
  EXPECT_EQ(jump.first_row_after, 60);
  EXPECT_GT(jump.one_frame_rms_mm, 100.0);
  EXPECT_LT(jump.before_rms_mm, 5.0);
  EXPECT_LT(jump.after_rms_mm, 5.0);
  // The second campaign first: found from the last rows' frame.
  Observations swapped;
  swapped.source = both.source;
  swapped.joint_names = both.joint_names;
  for (size_t i = 60; i < both.rows.size(); ++i)
    swapped.rows.push_back(both.rows[i]);
  for (size_t i = 0; i < 60; ++i) swapped.rows.push_back(both.rows[i]);
  const FrameJump back = FindFrameJump(a.nominal, swapped);
  EXPECT_TRUE(back.found);
  EXPECT_EQ(back.first_row_after, 40);

  EXPECT_FALSE(FindFrameJump(a.nominal, a.observations).found);
  EXPECT_FALSE(FindFrameJump(a.truth, a.observations).found);
}

}  // namespace
}  // namespace kincal
