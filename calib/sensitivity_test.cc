#include "calib/sensitivity.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>

#include "calib/calibrate.h"
#include "data/error.h"
#include "data/robot.h"
#include "synth/simulate.h"
#include "tests/testing/paths.h"

namespace kincal {
namespace {

using ::testing::Contains;

Robot Bh7() {
  return ReadRobotYaml(testing::SourceDir() + "/data/robots/bh7.yaml");
}

struct Fixture {
  SimulatedSession session;
  CalibrateResult paper;
};

// The paper's setting: one fixed point, joint readings only, calibrated by
// eq. (9) on all poses. Built once for the tests below.
const Fixture& Calibrated() {
  static const Fixture* f = [] {
    SimulateOptions opt;
    opt.mode = SimulateOptions::kFixedPoint;
    opt.fixed_points = 1;
    opt.poses_per_point = 40;
    opt.measure_points = false;
    opt.noise_mm = 0.03;
    opt.seed = 31;
    auto* fx = new Fixture;
    fx->session = Simulate(Bh7(), opt);
    CalibrateOptions c;
    c.method = CalibrateOptions::kPaper;
    c.holdout_fraction = 0.0;
    fx->paper = Calibrate(fx->session.nominal, fx->session.observations, c);
    return fx;
  }();
  return *f;
}

const SensitivityCurve& Curve(const SensitivityResult& r,
                              const std::string& n) {
  for (const SensitivityCurve& c : r.curves) {
    if (c.param.name == n) return c;
  }
  throw std::logic_error("no curve " + n);
}

TEST(SensitivityTest, OptimumHasEqualValleysBelowEta) {
  const Fixture& f = Calibrated();
  const SensitivityResult r =
      AnalyzeSensitivity(f.paper.calibrated, f.session.observations, {});
  ASSERT_EQ(r.curves.size(), 24u);
  EXPECT_EQ(r.verdict, "optimal") << (r.reasons.empty() ? "" : r.reasons[0]);
  EXPECT_TRUE(r.valleys_equal);
  EXPECT_TRUE(r.below_eta);
  EXPECT_NEAR(r.eps_mm, f.paper.epsilon.mean_mm, 1e-6);
  for (const SensitivityCurve& c : r.curves) {
    ASSERT_EQ(c.offsets.size(), 41u);
    EXPECT_DOUBLE_EQ(c.offsets.front(), -5.0);
    EXPECT_DOUBLE_EQ(c.offsets.back(), 5.0);
    EXPECT_NEAR(c.eps_mm[20], r.eps_mm, 1e-9) << c.param.name;
    EXPECT_FALSE(c.improves) << c.param.name;
    // Every acting parameter has its valley at the calibrated value.
    if (!c.flat) {
      EXPECT_LT(std::abs(c.valley_offset), 0.05) << c.param.name;
    }
  }
  // A 1 mm change of a link length moves the tips far more than the noise.
  EXPECT_GT(Curve(r, "j2.a").eps_mm.back(), 10 * r.eps_mm);
}

// Blind spots, reported: parameters eps ignores give flat curves whose
// valleys equal eps trivially.
TEST(SensitivityTest, ReportsFlatCurvesOfParametersEpsIgnores) {
  const Fixture& f = Calibrated();
  const SensitivityResult r =
      AnalyzeSensitivity(f.paper.calibrated, f.session.observations, {});
  // The tool's twist and the rotation about the needle do not move a tip.
  EXPECT_THAT(r.flat, Contains("tool.alpha"));
  EXPECT_THAT(r.flat, Contains("tool.theta"));
  // A rotation of the whole arm about the base z axis rotates every tip and
  // the centroid alike: eps cannot change.
  EXPECT_THAT(r.flat, Contains("j1.theta"));
  EXPECT_TRUE(Curve(r, "tool.alpha").flat);
  EXPECT_FALSE(Curve(r, "tool.alpha").identifiable);
  for (const std::string& name : r.flat) {
    EXPECT_THAT(r.unidentifiable, Contains(name));
  }
  ASSERT_GE(r.notes.size(), 2u);
  EXPECT_THAT(r.notes[0], ::testing::HasSubstr("flat curves"));
}

// The criterion's real blind spot: an error along a combination the data
// cannot separate (j1.d and j2.d both shift along parallel z axes) leaves
// eps and every curve as they were, so the verdict stays "optimal" for a
// model that is 3 mm wrong in two parameters.
TEST(SensitivityTest, CannotSeeErrorsAlongUnidentifiableCombinations) {
  const Fixture& f = Calibrated();
  Robot wrong = f.paper.calibrated;
  wrong.joints[0].d_mm += 3.0;
  wrong.joints[1].d_mm -= 3.0;
  const SensitivityResult r =
      AnalyzeSensitivity(wrong, f.session.observations, {});
  EXPECT_NEAR(r.eps_mm, f.paper.epsilon.mean_mm, 1e-9);
  EXPECT_EQ(r.verdict, "optimal");
}

// Away from the optimum the paper's verdict is "not optimal": valleys are
// unequal, and single parameters lower eps.
TEST(SensitivityTest, NominalModelIsNotOptimal) {
  const Fixture& f = Calibrated();
  SensitivityOptions opt;
  opt.steps = 21;
  const SensitivityResult r =
      AnalyzeSensitivity(f.session.nominal, f.session.observations, opt);
  EXPECT_EQ(r.verdict, "not_optimal");
  EXPECT_FALSE(r.valleys_equal);
  EXPECT_FALSE(r.reasons.empty());
  int improving = 0;
  for (const SensitivityCurve& c : r.curves) improving += c.improves;
  EXPECT_GT(improving, 3);
  EXPECT_GT(r.valley_max_mm - r.valley_min_mm, 0.05);
}

TEST(SensitivityTest, EtaDecidesWhenValleysAreEqual) {
  const Fixture& f = Calibrated();
  SensitivityOptions opt;
  opt.eta_mm = 0.5 * f.paper.epsilon.mean_mm;  // stricter than reached
  opt.params = {"j2.a", "j3.a"};
  const SensitivityResult r =
      AnalyzeSensitivity(f.paper.calibrated, f.session.observations, opt);
  ASSERT_EQ(r.curves.size(), 2u);
  EXPECT_TRUE(r.valleys_equal);
  EXPECT_FALSE(r.below_eta);
  EXPECT_EQ(r.verdict, "not_optimal");
}

TEST(SensitivityTest, RejectsBadOptionsAndDataWithoutFixedPoints) {
  const Fixture& f = Calibrated();
  SensitivityOptions even;
  even.steps = 40;
  EXPECT_THROW(
      AnalyzeSensitivity(f.paper.calibrated, f.session.observations, even),
      InputError);
  SensitivityOptions neg;
  neg.range = -1;
  EXPECT_THROW(
      AnalyzeSensitivity(f.paper.calibrated, f.session.observations, neg),
      InputError);
  SimulateOptions opt;
  opt.poses = 20;
  const SimulatedSession random = Simulate(Bh7(), opt);
  EXPECT_THROW(AnalyzeSensitivity(random.nominal, random.observations, {}),
               InputError);
}

}  // namespace
}  // namespace kincal
