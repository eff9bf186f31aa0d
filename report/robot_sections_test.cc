// The robot sections: each appears only with its inputs; the diagnosis
// without findings is a sentence, not an empty table; a bundle result's
// parameters are its own.

#include "report/robot_sections.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace kincal {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

TEST(RobotSectionsTest, DiagnosisTableOnlyWithFindings) {
  ReportInputs in;
  in.has_diag = true;
  in.diag = {{"verdict", "no_effect"}, {"findings", nlohmann::json::array()}};
  ReportOptions o;
  o.diagnosis = "d.json";
  HtmlReport empty("t");
  AddDiagnosisSection(in, o, &empty);
  EXPECT_THAT(empty.Page(""), HasSubstr("No significant effect"));
  EXPECT_THAT(empty.Page(""), Not(HasSubstr("<table>")));
  in.diag["findings"].push_back(
      {{"cause", "backlash"}, {"joint", "j3"}, {"magnitude", 0.15}});
  HtmlReport one("t");
  AddDiagnosisSection(in, o, &one);
  EXPECT_THAT(one.Page(""), HasSubstr("<td>backlash</td><td>j3</td>"));
}

TEST(RobotSectionsTest, NothingWithoutTheirInputs) {
  ReportInputs in;
  ReportAnalysis an;
  HtmlReport page("t");
  AddResidualsSection(in, an, ReportOptions(), &page);
  AddStructureSection(in, an, ReportOptions(), &page);
  AddWorkspaceSection(an, ReportOptions(), &page);
  AddSensitivitySection(an, &page);
  AddClearanceSection(an, &page);
  AddIdentifiabilitySection(in, an, &page);
  AddParametersSection(in, an, ReportOptions(), &page);
  EXPECT_TRUE(page.sections().empty());
  EXPECT_EQ(page.figures(), 0);
}

TEST(RobotSectionsTest, MeasuredSensitivityCurvesOnePlotPerUnit) {
  ReportAnalysis an;
  an.has_geo = true;
  an.measured_sensitivity = {{"j2.a", "mm", {-1, 0, 1}, {0.5, 0.3, 0.5}},
                             {"j2.theta", "deg", {-1, 0, 1}, {0.9, 0.3, 0.8}}};
  HtmlReport page("t");
  AddSensitivitySection(an, &page);
  EXPECT_EQ(page.sections(), std::vector<std::string>{"sensitivity"});
  EXPECT_EQ(page.figures(), 2);
  EXPECT_THAT(page.Page(""), HasSubstr("RMS error vs angles"));
}

TEST(RobotSectionsTest, BundleParametersAreTheBundlesOwn) {
  ReportInputs in;
  in.has_bundle = true;
  in.bundle = {
      {"params", {{{"name", "j2.a"}, {"value", 200.161}, {"sigma", 0.0086}}}},
      {"identifiable", {"j2.a"}},
      {"unidentifiable", {"j1.d"}}};
  ReportOptions o;
  o.bundle = "b.json";
  HtmlReport page("t");
  AddIdentifiabilitySection(in, ReportAnalysis(), &page);
  AddParametersSection(in, ReportAnalysis(), o, &page);
  const std::string html = page.Page("");
  EXPECT_EQ(page.sections(),
            (std::vector<std::string>{"identifiability", "parameters"}));
  EXPECT_THAT(html, HasSubstr("<td>j2.a</td><td class='num'>200.161</td>"));
  EXPECT_THAT(html, HasSubstr("Held at nominal (redundant with the others or "
                              "the frames): j1.d."));
}

}  // namespace
}  // namespace kincal
