// `diagnose model` on measured data we did not make: the UR10 laser-tracker
// series (ipa-robot-accuracy, ../shared/data). Trained on series C alone,
// the selected model must lower C's held-out RMS and the RMS on series B
// (which the selection never sees) by at least 30 % against plain geometry,
// with named causes (docs/DIAGNOSE.md, "Real robots"). Skips with a message
// when the data are absent.
#include <gtest/gtest.h>

#include "calib/evaluate.h"
#include "data/import_ipa.h"
#include "diagnose/model_diagnosis.h"
#include "tests/testing/paths.h"

namespace kincal {
namespace {

std::string Ipa(const std::string& file) {
  return testing::SharedDataDir() + "/ipa-robot-accuracy/" + file;
}

TEST(DiagnoseRealData, Ur10SeriesCNamesWhatCarriesToSeriesB) {
  KINCAL_REQUIRE_SHARED_DATA("ipa-robot-accuracy");
  const Robot ur10 =
      ReadRobotYaml(testing::SourceDir() + "/data/robots/ur10.yaml");
  const Observations c =
      ReadIpaSeries(Ipa("Series_C/measurements_random_poses.csv")).observations;
  const Observations b =
      ReadIpaSeries(Ipa("Series_B/measurements_joint_configurations.csv"))
          .observations;
  const DiagnosisResult r = DiagnoseModel(ur10, c, {});
  ASSERT_EQ(r.verdict, "effect_found");
  // C's own held-out poses: 0.4995 -> 0.1315 mm when this was written.
  EXPECT_LT(r.final_heldout_rms_mm, 0.7 * r.nominal_heldout_rms_mm);
  // The largest single gain is a named cause, not the last resort.
  ASSERT_FALSE(r.findings.empty());
  EXPECT_NE(r.findings[0].cause, "unexplained");
  EXPECT_LT(r.findings[0].heldout_rms_after_mm,
            0.85 * r.findings[0].heldout_rms_before_mm);
  // Series B, frame registered only: plain geometry 0.910 mm, the model
  // selected on C 0.515 mm when this was written.
  DiagnoseOptions geometry_only;
  geometry_only.causes = {"gain"};
  geometry_only.false_alarm = 1e-300;
  const DiagnosisResult g = DiagnoseModel(ur10, c, geometry_only);
  for (const Finding& f : g.findings) ASSERT_EQ(f.cause, "unexplained");
  const double plain_b = Evaluate(g.extended, b).stats.rms_mm;
  const double extended_b = Evaluate(r.extended, b).stats.rms_mm;
  RecordProperty("b_plain_mm", std::to_string(plain_b));
  RecordProperty("b_extended_mm", std::to_string(extended_b));
  EXPECT_GT(plain_b, 0.8);
  EXPECT_LT(extended_b, 0.7 * plain_b);
}

}  // namespace
}  // namespace kincal
