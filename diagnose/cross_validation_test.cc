#include "diagnose/cross_validation.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>

#include "data/error.h"
#include "diagnose/model_diagnosis.h"
#include "synth/simulate.h"
#include "tests/testing/paths.h"

namespace kincal {
namespace {

Robot Load(const std::string& name) {
  return ReadRobotYaml(testing::SourceDir() + "/data/robots/" + name);
}

SimulatedSession Sim(const Robot& robot, const std::string& effect,
                     uint64_t seed, int poses, double noise_mm = 0.03) {
  SimulateOptions so;
  so.poses = poses;
  so.noise_mm = noise_mm;
  so.seed = seed;
  if (!effect.empty()) so.effects = {ParseEffect(effect, robot)};
  return Simulate(robot, so);
}

DiagnoseOptions Folds(int k) {
  DiagnoseOptions o;
  o.folds = k;
  o.folds_given = true;
  return o;
}

TEST(FoldsTest, SeededBalancedAndRepeatsTogether) {
  std::vector<Measurement> ms(103);
  for (size_t i = 0; i < ms.size(); ++i) ms[i].input.q = {double(i), 0.0};
  // Rows 10..14 repeat one pose: they must share a fold.
  for (int i = 10; i < 15; ++i) ms[i].input.q = {10.0, 0.0};
  const FoldPlan a = MakeFolds(ms, 5, 1), b = MakeFolds(ms, 5, 1);
  const FoldPlan c = MakeFolds(ms, 5, 2);
  EXPECT_EQ(a.folds, 5);
  EXPECT_EQ(a.fold_of, b.fold_of);  // seeded: reproducible
  EXPECT_NE(a.fold_of, c.fold_of);  // another seed, other folds
  std::vector<int> size(5, 0);
  for (int f : a.fold_of) {
    ASSERT_GE(f, 0);
    ASSERT_LT(f, 5);
    ++size[f];
  }
  EXPECT_LE(*std::max_element(size.begin(), size.end()) -
                *std::min_element(size.begin(), size.end()),
            5);  // the repeated group is the only imbalance
  std::set<int> repeat_folds;
  for (int i = 10; i < 15; ++i) repeat_folds.insert(a.fold_of[i]);
  EXPECT_EQ(repeat_folds.size(), 1u);
}

// The linearised fold step (one Gauss-Newton step from the training fit)
// gives the cross-validated RMS of full refits per fold, for the base model
// and every candidate the F-test passes; out-of-fold errors exceed the
// in-sample ones.
TEST(CrossValidatedRmsTest, LinearisedMatchesRefitPerFold) {
  const SimulatedSession s = Sim(Load("bh7.yaml"), "backlash:j3:0.05", 41, 120);
  DiagnoseOptions lin = Folds(5), refit = Folds(5);
  refit.cv_refit = true;
  const DiagnosisResult a = DiagnoseModel(s.nominal, s.observations, lin);
  const DiagnosisResult b = DiagnoseModel(s.nominal, s.observations, refit);
  ASSERT_EQ(a.folds, 5);
  ASSERT_TRUE(std::isfinite(a.nominal_cv_rms_mm));
  EXPECT_NEAR(a.nominal_cv_rms_mm, b.nominal_cv_rms_mm,
              1e-3 * b.nominal_cv_rms_mm);
  EXPECT_GT(a.nominal_cv_rms_mm, a.nominal_train_rms_mm);
  int compared = 0;
  ASSERT_EQ(a.steps.size(), b.steps.size());
  for (size_t st = 0; st < a.steps.size(); ++st) {
    for (size_t c = 0; c < a.steps[st].size(); ++c) {
      const double x = a.steps[st][c].cv_rms_mm, y = b.steps[st][c].cv_rms_mm;
      EXPECT_EQ(std::isfinite(x), std::isfinite(y));
      if (!std::isfinite(x) || !std::isfinite(y)) continue;
      EXPECT_NEAR(x, y, 1e-3 * y)
          << a.steps[st][c].cause << " " << a.steps[st][c].joint;
      EXPECT_GT(x, a.steps[st][c].train_rms_mm);
      ++compared;
    }
  }
  EXPECT_GT(compared, 0);
  ASSERT_FALSE(a.findings.empty());
  EXPECT_EQ(a.findings[0].cause, "backlash");
  EXPECT_LT(a.findings[0].cv_rms_after_mm, a.findings[0].cv_rms_before_mm);
}

// Where one seeded split decides wrongly and the k folds do not (BH-7,
// 0.03 mm noise; the seeds are where `bench/diagnose_bench --only cv-sim`
// saw the split fail): a real compliance of j5 (0.03 deg, 120 poses) whose
// held-out RMS happens not to drop, so the single split rejects it; and a
// null session where a third harmonic of j3 passes the F-test and the
// held-out split, but does not predict the left-out folds significantly
// better.
TEST(KFoldSelectionTest, RightWhereTheSingleSplitIsWrong) {
  const Robot bh7 = Load("bh7.yaml");
  for (uint64_t seed : {5004, 5028}) {
    const SimulatedSession s = Sim(bh7, "compliance:j5:0.03", seed, 120);
    const DiagnosisResult single =
        DiagnoseModel(s.nominal, s.observations, Folds(0));
    // The single split misses the compliance (seed 5004 now names the
    // transmission series of j5 in its place, which can take the shape of a
    // j5 torque over the travel; 5028 names nothing).
    EXPECT_TRUE(single.verdict == "no_significant_effect" ||
                single.findings[0].cause != "compliance")
        << seed;
    const DiagnosisResult kfold =
        DiagnoseModel(s.nominal, s.observations, Folds(5));
    ASSERT_EQ(kfold.verdict, "effect_found") << seed;
    const Finding& f = kfold.findings[0];
    EXPECT_EQ(f.cause, "compliance");
    EXPECT_EQ(f.joint, "j5");
    EXPECT_NEAR(std::abs(f.magnitude), 0.03, 0.25 * 0.03);
    EXPECT_EQ(kfold.findings.size(), 1u);
    EXPECT_LT(f.cv_rms_after_mm, f.cv_rms_before_mm);
  }
  const SimulatedSession null = Sim(bh7, "", 947941497, 124, 0.0384507);
  const DiagnosisResult single =
      DiagnoseModel(null.nominal, null.observations, Folds(0));
  ASSERT_EQ(single.findings.size(), 1u);
  EXPECT_EQ(single.findings[0].cause, "cyclic3");
  EXPECT_EQ(DiagnoseModel(null.nominal, null.observations, Folds(5)).verdict,
            "no_significant_effect");
}

// The step winner: the lowest cross-validated RMS, unless the most
// significant candidate predicts within cv_tie_z standard errors of it. A
// compliance of j5 on BH-7 is nested in cyclic j5 (cos, sin), whose extra
// parameters fit the noise: the lowest cross-validated RMS alone names
// a more flexible family that nests it (cyclic, or the periodic
// transmission's first harmonic), the tie rule compliance.
TEST(KFoldSelectionTest, TiesGoToTheMostSignificant) {
  const SimulatedSession s =
      Sim(Load("bh7.yaml"), "compliance:j5:0.1819", 815625349, 252, 0.0486883);
  DiagnoseOptions lowest = Folds(5);
  lowest.cv_tie_z = 0.0;
  const DiagnosisResult a = DiagnoseModel(s.nominal, s.observations, lowest);
  ASSERT_FALSE(a.findings.empty());
  EXPECT_NE(a.findings[0].cause, "compliance");
  EXPECT_EQ(a.findings[0].joint, "j5");
  const DiagnosisResult b = DiagnoseModel(s.nominal, s.observations, Folds(5));
  ASSERT_FALSE(b.findings.empty());
  EXPECT_EQ(b.findings[0].cause, "compliance");
  EXPECT_EQ(b.findings[0].joint, "j5");
  EXPECT_NEAR(b.findings[0].magnitude, 0.1819, 0.25 * 0.1819);
  // Both are significant and predict alike: each lists the other.
  ASSERT_FALSE(b.findings[0].equivalent.empty());
  EXPECT_EQ(b.findings[0].equivalent[0].cause, "cyclic");
}

// Hidden effects under 5 folds: cause, joint, magnitude within 25 %; null
// sessions (several seeds, both robots): no false alarm (the F-test's
// family-wise rate per step is 1 %).
TEST(KFoldSelectionTest, HiddenEffectsFoundAndNullSessionsQuiet) {
  const Robot bh7 = Load("bh7.yaml"), ur10 = Load("ur10.yaml");
  struct Case {
    const Robot* robot;
    std::string effect, cause, joint;
    double magnitude;
    uint64_t seed;
    int poses;
  };
  const std::vector<Case> cases = {
      {&bh7, "backlash:j3:0.03", "backlash", "j3", 0.03, 51, 120},
      {&bh7, "compliance:j5:0.1", "compliance", "j5", 0.1, 52, 150},
      {&ur10, "elastostatic:shoulder_lift_joint:0.03", "elastostatic",
       "shoulder_lift_joint", 0.03, 53, 200},
      {&ur10, "cyclic:elbow_joint:0.02", "cyclic", "elbow_joint", 0.02, 54,
       150},
  };
  for (const Case& c : cases) {
    const SimulatedSession s = Sim(*c.robot, c.effect, c.seed, c.poses);
    const DiagnosisResult r =
        DiagnoseModel(s.nominal, s.observations, Folds(5));
    EXPECT_EQ(r.folds, 5);
    ASSERT_EQ(r.verdict, "effect_found") << c.effect;
    const Finding& f = r.findings[0];
    EXPECT_EQ(f.cause, c.cause) << c.effect;
    EXPECT_EQ(f.joint, c.joint) << c.effect;
    EXPECT_NEAR(std::abs(f.magnitude), c.magnitude, 0.25 * c.magnitude)
        << c.effect;
    EXPECT_LT(f.cv_rms_after_mm, f.cv_rms_before_mm);
    for (size_t i = 1; i < r.findings.size(); ++i) {
      EXPECT_EQ(r.findings[i].cause, "unexplained") << c.effect;
    }
  }
  for (uint64_t seed : {61, 62, 63, 64}) {
    const SimulatedSession s = Sim(seed % 2 ? bh7 : ur10, "", seed, 200);
    const DiagnosisResult r =
        DiagnoseModel(s.nominal, s.observations, Folds(5));
    EXPECT_EQ(r.verdict, "no_significant_effect") << "seed " << seed;
    EXPECT_TRUE(std::isfinite(r.nominal_cv_rms_mm));
  }
}

TEST(KFoldSelectionTest, SeededAndReproducible) {
  const SimulatedSession s = Sim(Load("bh7.yaml"), "gain:j3:0.002", 71, 150);
  DiagnoseOptions o = Folds(5);
  const nlohmann::json a =
      DiagnosisJson(DiagnoseModel(s.nominal, s.observations, o), o);
  const nlohmann::json b =
      DiagnosisJson(DiagnoseModel(s.nominal, s.observations, o), o);
  nlohmann::json a2 = a, b2 = b;
  a2.erase("seconds");
  b2.erase("seconds");
  EXPECT_EQ(a2.dump(), b2.dump());
  EXPECT_EQ(a["folds"], 5);
  EXPECT_TRUE(a["nominal"]["cv_rms_mm"].is_number());
  EXPECT_TRUE(a["findings"][0]["cv_rms_after_mm"].is_number());
  EXPECT_TRUE(a["steps"][0][0].contains("cv_rms_mm"));
  // Another seed: other split and folds, other cross-validated figures.
  o.seed = 2;
  const nlohmann::json c =
      DiagnosisJson(DiagnoseModel(s.nominal, s.observations, o), o);
  EXPECT_NE(c["nominal"]["cv_rms_mm"], a["nominal"]["cv_rms_mm"]);
}

TEST(KFoldSelectionTest, DefaultFoldsFollowThePoses) {
  const Robot bh7 = Load("bh7.yaml");
  const SimulatedSession big = Sim(bh7, "", 81, 240);
  EXPECT_EQ(DiagnoseModel(big.nominal, big.observations, {}).folds, 5);
  // 40 poses: 30 training poses allow 3 folds of 10.
  const SimulatedSession small = Sim(bh7, "", 82, 40);
  EXPECT_EQ(DiagnoseModel(small.nominal, small.observations, {}).folds, 3);
  EXPECT_EQ(DiagnoseModel(big.nominal, big.observations, Folds(1)).folds, 0);
}

TEST(KFoldSelectionTest, BadFoldCountsAreInputErrors) {
  const SimulatedSession s = Sim(Load("bh7.yaml"), "", 91, 50);
  EXPECT_THROW(DiagnoseModel(s.nominal, s.observations, Folds(1000)),
               InputError);
  EXPECT_THROW(DiagnoseModel(s.nominal, s.observations, Folds(-1)), InputError);
  try {
    DiagnoseModel(s.nominal, s.observations, Folds(1000));
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("--folds 1000"), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace kincal
