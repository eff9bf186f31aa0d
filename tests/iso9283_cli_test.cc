// kincal iso9283 end to end: the commands of docs/ISO9283.md on the demo
// session data/sessions/iso9283_demo (diagnose/iso9283_test.cc
// DemoSession), their figures, the exit-2 refusals, and the ISO 9283
// figures in report and diagnose compare.

#include <gtest/gtest.h>

#include <algorithm>
#include <nlohmann/json.hpp>

#include "tests/testing/paths.h"
#include "tests/testing/run.h"

namespace kincal {
namespace {

using testing::RunKincal;
using testing::RunResult;

std::string Demo(const std::string& file) {
  return testing::SourceDir() + "/data/sessions/iso9283_demo/" + file;
}

std::string Robot() { return testing::SourceDir() + "/data/robots/bh7.yaml"; }

nlohmann::json Json(const RunResult& r) {
  EXPECT_EQ(r.exit_code, 0) << r.err;
  return nlohmann::json::parse(r.out);
}

TEST(Iso9283Cli, ContractFieldsAndTheFrameRegisteredOnThePoses) {
  const nlohmann::json j =
      Json(RunKincal("iso9283 --robot " + Robot() + " --obs " +
                     Demo("cycles.csv") + " --json"));
  ASSERT_EQ(j["poses"].size(), 5u);
  EXPECT_EQ(j["poses"][0]["pose"], "P1");
  EXPECT_EQ(j["poses"][1]["pose"], "P5");  // order of first visit
  double ap_max = 0, rp_max = 0;
  for (const auto& p : j["poses"]) {
    EXPECT_EQ(p["n"], 30);
    for (const char* f : {"ap_mm", "rp_mm", "ap_x_mm", "ap_y_mm", "ap_z_mm",
                          "l_mean_mm", "s_l_mm"}) {
      EXPECT_TRUE(p[f].is_number()) << f;
    }
    EXPECT_EQ(p["barycentre_mm"].size(), 3u);
    EXPECT_FALSE(p.contains("pass"));
    ap_max = std::max(ap_max, p["ap_mm"].get<double>());
    rp_max = std::max(rp_max, p["rp_mm"].get<double>());
  }
  EXPECT_DOUBLE_EQ(j["ap_max_mm"].get<double>(), ap_max);
  EXPECT_DOUBLE_EQ(j["rp_max_mm"].get<double>(), rp_max);
  EXPECT_EQ(j["frame"], "registered_on_poses");
  EXPECT_EQ(j["registration_rows"], 150);
  EXPECT_EQ(j["unlabelled_rows"], 5);  // the warm-up cycle
  // Noise 0.02 mm per axis: RP about 3.6 sigma.
  EXPECT_GT(j["rp_max_mm"].get<double>(), 0.05);
  EXPECT_LT(j["rp_max_mm"].get<double>(), 0.1);
  EXPECT_FALSE(j.contains("warnings"));
}

TEST(Iso9283Cli, FrameFromOtherPosesAndTolerance) {
  const nlohmann::json own =
      Json(RunKincal("iso9283 --robot " + Robot() + " --obs " +
                     Demo("cycles.csv") + " --json"));
  const nlohmann::json j =
      Json(RunKincal("iso9283 --robot " + Robot() + " --obs " +
                     Demo("cycles.csv") + " --frame-from " + Demo("frame.csv") +
                     " --tolerance 0.5 --rp-tolerance 0.1 --json"));
  EXPECT_EQ(j["frame"], "given");
  EXPECT_EQ(j["registration_rows"], 40);
  // The fit on the tested poses took up part of AP.
  EXPECT_GT(j["ap_max_mm"].get<double>(), own["ap_max_mm"].get<double>() + 0.1);
  // RP does not depend on the frame.
  EXPECT_NEAR(j["rp_max_mm"].get<double>(), own["rp_max_mm"].get<double>(),
              1e-9);
  EXPECT_EQ(j["pass"], true);
  EXPECT_EQ(j["tolerance_mm"], 0.5);
  EXPECT_EQ(j["rp_tolerance_mm"], 0.1);
  for (const auto& p : j["poses"]) EXPECT_EQ(p["pass"], true);
  const nlohmann::json tight = Json(RunKincal(
      "iso9283 --robot " + Robot() + " --obs " + Demo("cycles.csv") +
      " --frame-from " + Demo("frame.csv") + " --tolerance 0.2 --json"));
  EXPECT_EQ(tight["pass"], false);
}

TEST(Iso9283Cli, ApproachFlippingEveryCycleRaisesRp) {
  const nlohmann::json standard =
      Json(RunKincal("iso9283 --robot " + Robot() + " --obs " +
                     Demo("cycles.csv") + " --json"));
  const nlohmann::json flipping =
      Json(RunKincal("iso9283 --robot " + Robot() + " --obs " +
                     Demo("multidirectional.csv") + " --json"));
  EXPECT_GT(flipping["rp_max_mm"].get<double>(),
            standard["rp_max_mm"].get<double>() + 0.05);
}

TEST(Iso9283Cli, BadInputIsExit2) {
  const RunResult unlabelled =
      RunKincal("iso9283 --robot " + Robot() + " --obs " + Demo("frame.csv"));
  EXPECT_EQ(unlabelled.exit_code, 2);
  EXPECT_NE(unlabelled.err.find("no row has a fixed_point label"),
            std::string::npos)
      << unlabelled.err;
  const std::string dir = testing::MakeTempDir("iso9283");
  const RunResult once = testing::RunShell(
      "head -12 " + Demo("cycles.csv") + " > " + dir + "/once.csv && " +
      testing::KincalBinary() + " iso9283 --robot " + Robot() + " --obs " +
      dir + "/once.csv");
  EXPECT_EQ(once.exit_code, 2);
  EXPECT_NE(once.err.find("once.csv:9:1: pose 'P1' is visited once"),
            std::string::npos)
      << once.err;
}

TEST(Iso9283Cli, FewerCyclesThanTheStandardsAreWarned) {
  const std::string dir = testing::MakeTempDir("iso9283_few");
  // Two comment lines, the header, the warm-up cycle, two measured cycles.
  const RunResult r = testing::RunShell(
      "head -18 " + Demo("cycles.csv") + " > " + dir + "/two.csv && " +
      testing::KincalBinary() + " iso9283 --robot " + Robot() + " --obs " +
      dir + "/two.csv --json");
  const nlohmann::json j = Json(r);
  ASSERT_EQ(j["poses"].size(), 5u);
  EXPECT_EQ(j["poses"][0]["n"], 2);
  ASSERT_TRUE(j.contains("warnings"));
  EXPECT_EQ(j["warnings"].size(), 5u);
  EXPECT_EQ(j["warnings"][0]["code"], "iso9283_few_cycles");
}

TEST(Iso9283Cli, ReportSectionAndCompare) {
  const std::string dir = testing::MakeTempDir("iso9283_report");
  const nlohmann::json report = Json(RunKincal(
      "report --robot " + Robot() + " --iso9283 " + Demo("cycles.csv") +
      " --tolerance 0.1 --out " + dir + "/report.html --json"));
  EXPECT_NE(std::find(report["sections"].begin(), report["sections"].end(),
                      "iso9283"),
            report["sections"].end());
  EXPECT_EQ(report["iso9283"]["pass"], false);  // AP above 0.1 mm
  EXPECT_GT(report["iso9283"]["ap_max_mm"].get<double>(), 0.1);
  const nlohmann::json compare =
      Json(RunKincal("diagnose compare " + Demo("multidirectional.csv") + " " +
                     Demo("cycles.csv") + " --robot " + Robot() + " --json"));
  ASSERT_TRUE(compare.contains("iso9283"));
  EXPECT_EQ(compare["iso9283"]["poses"].size(), 5u);
  EXPECT_GT(compare["iso9283"]["rp_max_before_mm"].get<double>(),
            compare["iso9283"]["rp_max_after_mm"].get<double>());
}

}  // namespace
}  // namespace kincal
