// BuildReport on the demo session: the sections follow the inputs, the
// verdict quotes one held-out figure per model, an empty finding list is
// said in words, --tolerance adds its line, bad input fails first.

#include "report/report.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>

#include "data/error.h"
#include "tests/testing/paths.h"

namespace kincal {
namespace {

using ::testing::Contains;
using ::testing::HasSubstr;
using ::testing::Not;

ReportOptions Demo() {
  const std::string s = testing::SourceDir() + "/data/sessions/bh7_demo";
  ReportOptions o;
  o.robot = s + "/robot.yaml";
  o.obs = s + "/observations.csv";
  return o;
}

TEST(ReportTest, RobotAndObservationsGiveTheRobotSections) {
  ReportOptions o = Demo();
  o.tolerance_mm = 1.0;
  const ReportResult r = BuildReport(o);
  EXPECT_EQ(r.sections,
            (std::vector<std::string>{
                "verdict", "residuals", "structure", "workspace", "sensitivity",
                "clearance", "identifiability", "parameters", "provenance"}));
  EXPECT_GE(r.figures, 10);
  // No diagnosis: the report's own calibration is the held-out figure.
  EXPECT_THAT(r.html, HasSubstr("by this report&#39;s calibration, seed 1"));
  // 240 poses: the structure shares are quoted.
  EXPECT_THAT(r.html, HasSubstr("by chance ~10 %"));
  EXPECT_TRUE(r.tolerance_given);
  EXPECT_TRUE(r.tolerance_available);
  EXPECT_TRUE(r.pass);  // ~0.33 mm held out against 1 mm
  EXPECT_LT(r.heldout_lo_mm, r.heldout_rms_mm);
  EXPECT_GT(r.heldout_hi_mm, r.heldout_rms_mm);
  EXPECT_THAT(r.html, HasSubstr("<p class='pass'>PASS: held-out RMS"));
}

TEST(ReportTest, DiagnosisWithoutFindingsSaysNoSignificantEffect) {
  const std::string path = ::testing::TempDir() + "kincal_report_diag.json";
  std::ofstream(path) << R"({"verdict": "no_effect", "findings": [],
      "holdout_fraction": 0.25, "heldout_poses": 60,
      "nominal": {"heldout_rms_mm": 0.344}, "final": {"heldout_rms_mm": 0.344}})";
  ReportOptions o;
  o.diagnosis = path;
  const ReportResult r = BuildReport(o);
  std::remove(path.c_str());
  EXPECT_THAT(r.sections, Contains("diagnosis"));
  EXPECT_THAT(r.html, HasSubstr("No significant effect"));
  EXPECT_THAT(r.html, Not(HasSubstr("<th>cause</th>")));
  EXPECT_THAT(r.html, HasSubstr("held out: 25 % of poses (60) by diagnose"));
}

TEST(ReportTest, BadInputFailsBeforeAnyComputation) {
  const std::string path = ::testing::TempDir() + "kincal_report_bad.json";
  std::ofstream(path) << "{\"findings\": []}";
  ReportOptions o = Demo();
  o.diagnosis = path;
  int calls = 0;
  EXPECT_THROW(BuildReport(o, [&](const std::string&) { ++calls; }),
               InputError);
  EXPECT_EQ(calls, 0);
  o.diagnosis.clear();
  o.bundle = path;  // not a bundle result either
  EXPECT_THROW(BuildReport(o), InputError);
  std::remove(path.c_str());
}

}  // namespace
}  // namespace kincal
