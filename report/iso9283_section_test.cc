// The ISO 9283 section: only with its figures; the table carries every
// pose's AP, its components, l̄, S_l and RP, and pass/fail with a
// tolerance.

#include "report/iso9283_section.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace kincal {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

ReportAnalysis TwoPoses(bool with_tolerance) {
  ReportAnalysis an;
  an.has_iso9283 = true;
  an.iso9283_robot = "bh7.yaml";
  Iso9283Pose p1 = PoseCharacteristics(Eigen::Vector3d(0, 0, 0),
                                       {{0.3, 0.0, 0.0}, {0.1, 0.0, 0.0}});
  p1.label = "P1";
  Iso9283Pose p2 = PoseCharacteristics(Eigen::Vector3d(0, 0, 0),
                                       {{0.0, 0.05, 0.0}, {0.0, 0.03, 0.0}});
  p2.label = "P2";
  an.iso9283.tolerance_given = with_tolerance;
  if (with_tolerance) {
    p1.pass = false;
    an.iso9283.pass = false;
  }
  an.iso9283.poses = {p1, p2};
  an.iso9283.ap_max_mm = p1.ap_mm;
  an.iso9283.rp_max_mm = p1.rp_mm;
  an.iso9283.registration_rows = 4;
  an.iso9283.registration_rms_mm = 0.05;
  return an;
}

TEST(Iso9283SectionTest, NothingWithoutFigures) {
  HtmlReport page("t");
  AddIso9283Section(ReportAnalysis(), ReportOptions(), &page);
  EXPECT_TRUE(page.sections().empty());
}

TEST(Iso9283SectionTest, TableOfEveryPoseAndPassFail) {
  ReportOptions o;
  o.iso9283 = "cycles.csv";
  HtmlReport plain("t");
  AddIso9283Section(TwoPoses(false), o, &plain);
  EXPECT_EQ(plain.sections(), std::vector<std::string>{"iso9283"});
  const std::string html = plain.Page("");
  // P1: barycentre 0.2, AP 0.2; l = 0.1, 0.1: l̄ 0.1, S_l 0, RP 0.1.
  EXPECT_THAT(html, HasSubstr("<td>P1</td><td class='num'>2</td><td "
                              "class='num'>0.2</td>"));
  EXPECT_THAT(html, HasSubstr("Largest AP 0.2 mm, largest RP 0.1 mm."));
  EXPECT_THAT(html, HasSubstr("registered on the tested poses"));
  EXPECT_THAT(html, Not(HasSubstr("PASS")));
  o.tolerance_mm = 0.15;
  HtmlReport checked("t");
  AddIso9283Section(TwoPoses(true), o, &checked);
  EXPECT_THAT(checked.Page(""), HasSubstr("<td>NO</td>"));
  EXPECT_THAT(checked.Page(""), HasSubstr("FAIL"));
}

}  // namespace
}  // namespace kincal
