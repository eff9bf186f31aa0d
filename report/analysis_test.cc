// The report's read and compute steps: inputs checked before computing, the
// bundle header found, a bundle result not re-calibrated, the structure pair
// found on the demo session.

#include "report/analysis.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>

#include "data/error.h"
#include "tests/testing/paths.h"

namespace kincal {
namespace {

const std::string kDemo = testing::SourceDir() + "/data/sessions/bh7_demo";

TEST(AnalysisTest, ObservationsNeedARobotAndRigJsonIsFoundBeside) {
  ReportOptions o;
  o.obs = kDemo + "/observations.csv";
  EXPECT_THROW(ReadReportInputs(o), InputError);
  ReportOptions s;
  s.session = kDemo + "/nowhere";
  EXPECT_THROW(ReadReportInputs(s), InputError);
}

TEST(AnalysisTest, BundleHeaderIsRead) {
  const std::string path = ::testing::TempDir() + "kincal_bundle_header.yaml";
  std::ofstream(path)
      << "# written by kincal 0.1.0: kincal bundle ...\n"
         "# calibrated by kincal bundle from the images of S\n"
         "# reprojection RMS 0.0503906984888 px (training), 0.03 px "
         "(held out)\nkincal_robot: 1\n";
  const BundleHeader h = ReadBundleHeader(path);
  EXPECT_TRUE(h.found);
  EXPECT_EQ(h.reprojection,
            "reprojection RMS 0.0504 px (training), 0.03 px (held out)");
  std::ofstream(path) << "# written by kincal 0.1.0: kincal calibrate\n"
                         "kincal_robot: 1\n";
  EXPECT_FALSE(ReadBundleHeader(path).found);
  std::remove(path.c_str());
}

TEST(AnalysisTest, ChanceShareOfAFiveByFiveGrid) {
  EXPECT_DOUBLE_EQ(ChanceShare(240), 0.1);
  EXPECT_DOUBLE_EQ(ChanceShare(16), 1.5);
}

TEST(AnalysisTest, DemoSessionCalibratesUnlessABundleResultIsGiven) {
  ReportOptions o;
  o.robot = kDemo + "/robot.yaml";
  o.obs = kDemo + "/observations.csv";
  const ReportInputs in = ReadReportInputs(o);
  const ReportAnalysis an = AnalyseReport(in, o);
  EXPECT_TRUE(an.has_calres);
  EXPECT_TRUE(an.has_geo);
  EXPECT_EQ(an.res_geo.stats.n, 240);
  EXPECT_GE(an.structure.a, 0);
  EXPECT_GT(an.structure.pair, ChanceShare(240));  // backlash left in j3
  EXPECT_TRUE(an.has_clear);
  EXPECT_FALSE(an.measured_sensitivity.empty());
  ReportInputs with_bundle = in;
  with_bundle.has_bundle = true;
  with_bundle.bundle = {{"reproj_rms_px", 0.05}, {"params", {}}};
  const ReportAnalysis b = AnalyseReport(with_bundle, o);
  EXPECT_FALSE(b.has_calres);
  EXPECT_TRUE(b.has_geo);
}

}  // namespace
}  // namespace kincal
