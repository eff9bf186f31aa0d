// The verdict's wording rules (report/verdict.h): one held-out figure per
// model with its source, no percentages on too few poses, "no significant
// effect" for an empty finding list, a bundle result's own figures, and the
// tolerance line with its chi-square interval.

#include "report/verdict.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>

namespace kincal {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

std::string Joined(const std::vector<std::string>& lines) {
  std::string s;
  for (const auto& l : lines) s += l + "\n";
  return s;
}

// Two joints and a structure share over `poses` poses.
void WithStructure(int poses, ReportInputs* in, ReportAnalysis* an) {
  in->has_robot = true;
  in->robot.joints.resize(2);
  in->robot.joints[0].name = "j1";
  in->robot.joints[1].name = "j2";
  an->has_geo = true;
  an->res_geo.stats.n = poses;
  an->res_geo.stats.rms_mm = 0.3;
  an->structure.a = 0;
  an->structure.b = 1;
  an->structure.poses = poses;
  an->structure.pair = 0.3;
  an->structure.a_alone = 0.1;
  an->structure.b_alone = 0.05;
}

nlohmann::json Diagnosis(bool with_finding) {
  nlohmann::json d = {
      {"verdict", with_finding ? "effect_found" : "no_effect"},
      {"findings", nlohmann::json::array()},
      {"holdout_fraction", 0.25},
      {"heldout_poses", 60},
      {"nominal", {{"heldout_rms_mm", 0.344}}},
      {"final", {{"heldout_rms_mm", with_finding ? 0.0543 : 0.344}}}};
  if (with_finding) {
    d["findings"].push_back({{"cause", "backlash"},
                             {"joint", "j3"},
                             {"magnitude", 0.151},
                             {"unit", "deg"},
                             {"ci95", {0.15, 0.153}},
                             {"heldout_rms_before_mm", 0.344},
                             {"heldout_rms_after_mm", 0.0543}});
  }
  return d;
}

TEST(VerdictTest, StructureSharesNeedEnoughPoses) {
  ReportInputs in;
  ReportAnalysis an;
  WithStructure(16, &in, &an);
  const std::string few = StructureSentence(in, an);
  EXPECT_THAT(few, HasSubstr("too few poses (16)"));
  EXPECT_THAT(few, Not(HasSubstr("%")));
  WithStructure(240, &in, &an);
  const std::string many = StructureSentence(in, an);
  EXPECT_THAT(many, HasSubstr("explains 30 %"));
  EXPECT_THAT(many, HasSubstr("by chance ~10 %"));
  // A share outside 0..100 % is never printed.
  an.structure.pair = 1.5;
  EXPECT_THAT(StructureSentence(in, an), HasSubstr("too few poses"));
}

TEST(VerdictTest, DiagnosisHeldOutFigureIsTheOnlyOneAndNamesItsSource) {
  ReportInputs in;
  ReportAnalysis an;
  WithStructure(240, &in, &an);
  in.has_diag = true;
  in.diag = Diagnosis(true);
  an.has_calres = true;  // the report's own calibration, 20 % held out
  an.calres.heldout.rms_mm = 0.119;
  an.calres.heldout.n = 48;
  an.calres.train.rms_mm = 0.3;
  const std::string v = Joined(WriteVerdict(in, an, ReportOptions()));
  EXPECT_THAT(v, HasSubstr("Diagnosis: effect found."));
  EXPECT_THAT(v, HasSubstr("0.344 mm with the calibrated geometry -> 0.0543 mm "
                           "(held out: 25 % of poses (60) by diagnose model)"));
  EXPECT_THAT(v, Not(HasSubstr("0.119")));
  EXPECT_THAT(v, HasSubstr("backlash in j3, 0.151 deg [0.15, 0.153]"));
  // Without the diagnosis the report's own run is quoted, with its source.
  in.has_diag = false;
  const std::string own = Joined(WriteVerdict(in, an, ReportOptions()));
  EXPECT_THAT(own, HasSubstr("held-out RMS 0.119 mm (held out: 20 % of poses "
                             "(48) by this report's calibration, seed 1)"));
}

TEST(VerdictTest, EmptyFindingsReadNoSignificantEffect) {
  ReportInputs in;
  ReportAnalysis an;
  in.has_diag = true;
  in.diag = Diagnosis(false);
  const std::string v = Joined(WriteVerdict(in, an, ReportOptions()));
  EXPECT_THAT(v, HasSubstr("Diagnosis: no significant effect"));
  EXPECT_THAT(v, HasSubstr("0.344 mm (held out: 25 % of poses (60)"));
  EXPECT_THAT(v, Not(HasSubstr("->")));
}

TEST(VerdictTest, FewHeldOutPosesAreCalledRough) {
  ReportInputs in;
  ReportAnalysis an;
  an.has_calres = true;
  an.calres.heldout.rms_mm = 0.2;
  an.calres.heldout.n = 3;
  const std::string v = Joined(WriteVerdict(in, an, ReportOptions()));
  EXPECT_THAT(v, HasSubstr("only 3 held-out poses: a rough figure"));
}

TEST(VerdictTest, BundleResultShowsItsOwnFigures) {
  ReportInputs in;
  ReportAnalysis an;
  in.has_bundle = true;
  in.bundle = {{"reproj_rms_px", 0.0504},
               {"heldout_reproj_rms_px", 0.0295},
               {"sigma0_px", 0.036},
               {"heldout_tip_rms_mm", 0.449},
               {"heldout_tips", 6},
               {"heldout_frames", 6},
               {"params", nlohmann::json::array({{{"name", "j2.a"}}})},
               {"unidentifiable", {"j1.d"}}};
  ReportOptions opt;
  opt.bundle = "b.json";
  const std::string v = Joined(WriteVerdict(in, an, opt));
  EXPECT_THAT(v, HasSubstr("held-out tip error 0.449 mm (held out: 6 tips of "
                           "6 frames by kincal bundle)"));
  EXPECT_THAT(v, HasSubstr("reprojection RMS 0.0504 px (training), 0.0295 px"));
  EXPECT_THAT(v, HasSubstr("sigma0 0.036 px"));
  const HeldOutFigure h = FinalHeldOut(in, an, opt);
  EXPECT_DOUBLE_EQ(h.rms_mm, 0.449);
  EXPECT_EQ(h.n, 6);
}

TEST(VerdictTest, CamcalResultNamesTheWorstView) {
  ReportInputs in;
  in.camcal = {{"cameras",
                {{{"name", "left"},
                  {"rms_px", 0.419},
                  {"holdout_rms_px", 0.441},
                  {"view_rms_px", {0.2, 1.22, 0.3}}}}}};
  const std::string v =
      Joined(WriteVerdict(in, ReportAnalysis(), ReportOptions()));
  EXPECT_THAT(v, HasSubstr("left RMS 0.419 px (held out 0.441 px)"));
  EXPECT_THAT(v, HasSubstr("Worst view: 2 (left, 1.22 px)"));
  EXPECT_THAT(v, Not(HasSubstr("No robot data")));
}

TEST(VerdictTest, ChiSquareQuantileMatchesTables) {
  EXPECT_NEAR(ChiSquareQuantile(0.975, 10), 20.483, 0.1);
  EXPECT_NEAR(ChiSquareQuantile(0.025, 10), 3.247, 0.05);
  EXPECT_NEAR(ChiSquareQuantile(0.975, 180), 219.04, 0.3);
  EXPECT_NEAR(ChiSquareQuantile(0.025, 180), 144.74, 0.3);
}

TEST(VerdictTest, ToleranceUsesTheIntervalOfTheFinalHeldOutError) {
  ReportInputs in;
  ReportAnalysis an;
  in.has_diag = true;
  in.diag = Diagnosis(true);  // final held-out 0.0543 mm on 60 poses
  ReportOptions opt;
  opt.tolerance_mm = 0.1;
  ToleranceCheck t = CheckTolerance(in, an, opt);
  EXPECT_TRUE(t.available);
  EXPECT_TRUE(t.pass);
  EXPECT_LT(t.lo_mm, 0.0543);
  EXPECT_GT(t.hi_mm, 0.0543);
  EXPECT_LT(t.hi_mm, 0.0543 * 1.15);  // 180 components: a narrow interval
  EXPECT_THAT(t.words, HasSubstr("PASS"));
  opt.tolerance_mm = 0.03;
  t = CheckTolerance(in, an, opt);
  EXPECT_FALSE(t.pass);
  EXPECT_THAT(t.words, HasSubstr("FAIL: "));
  opt.tolerance_mm = 0.056;  // inside the interval: not shown to pass
  t = CheckTolerance(in, an, opt);
  EXPECT_FALSE(t.pass);
  EXPECT_THAT(t.words, HasSubstr("not shown to pass"));
  // The line leads the verdict.
  EXPECT_EQ(WriteVerdict(in, an, opt)[0], t.words);
  // Few held-out poses: not decided, whatever the interval.
  in.diag["heldout_poses"] = 4;
  opt.tolerance_mm = 10.0;
  t = CheckTolerance(in, an, opt);
  EXPECT_FALSE(t.pass);
  EXPECT_THAT(t.words, HasSubstr("NOT DECIDED"));
  EXPECT_THAT(t.words, HasSubstr("too few held-out poses (4"));
  // Nothing held out: said, and no pass.
  ReportInputs none;
  t = CheckTolerance(none, an, opt);
  EXPECT_FALSE(t.available);
  EXPECT_FALSE(t.pass);
}

}  // namespace
}  // namespace kincal
