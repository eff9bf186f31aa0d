// End-to-end: the seed paper's workflow through the public commands on
// single-point data (simulate --mode fixed-point -> calibrate --method paper
// -> sensitivity), and `import` of the public real data sets.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "data/atomic_file.h"
#include "tests/testing/paths.h"
#include "tests/testing/run.h"

namespace kincal::testing {
namespace {

using ::testing::HasSubstr;

TEST(PaperCliTest, FixedPointCalibrationThenSensitivityVerdict) {
  const std::string dir = MakeTempDir("paper_cli");
  RunResult r = RunKincal("simulate --robot " + SourceDir() +
                          "/data/robots/bh7.yaml --mode fixed-point "
                          "--fixed-points 1 --poses-per-point 40 --no-points "
                          "--noise 0.02 --seed 5 --out " +
                          dir + "/fp");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string robot = dir + "/fp/robot.yaml";
  const std::string obs = dir + "/fp/observations.csv";

  // The nominal model is not optimal by the paper's criterion.
  r = RunKincal("sensitivity --robot " + robot + " --obs " + obs + " --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  auto s = nlohmann::json::parse(r.out);
  EXPECT_EQ(s["verdict"], "not_optimal");

  r = RunKincal("calibrate --robot " + robot + " --obs " + obs +
                " --method paper --out " + dir + "/cal.yaml --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto c = nlohmann::json::parse(r.out);
  EXPECT_EQ(c["method"], "paper");
  EXPECT_LT(c["epsilon"]["mean_mm"].get<double>(), 0.1);
  EXPECT_LT(c["heldout_rms_mm"].get<double>(), 0.15);

  // After eq. (9): valleys equal and below eta, flat curves listed, and the
  // curves written as CSV and SVG.
  r = RunKincal("sensitivity --robot " + dir + "/cal.yaml --obs " + obs +
                " --json --out-csv " + dir + "/curves.csv --plot " + dir +
                "/curves.svg");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  s = nlohmann::json::parse(r.out);
  EXPECT_EQ(s["verdict"], "optimal");
  EXPECT_TRUE(s["below_eta"].get<bool>());
  EXPECT_THAT(s["flat"].dump(), HasSubstr("tool.alpha"));
  EXPECT_THAT(ReadFile(dir + "/curves.svg"), HasSubstr("<svg"));
  EXPECT_THAT(ReadFile(dir + "/curves.csv"), HasSubstr("# written by kincal"));
}

TEST(PaperCliTest, SensitivityAndImportRejectBadInput) {
  const std::string dir = MakeTempDir("paper_cli_bad");
  RunResult r = RunKincal("simulate --robot " + SourceDir() +
                          "/data/robots/bh7.yaml --poses 30 --seed 2 --out " +
                          dir + "/m");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  // Measured points only: the criterion needs fixed-point rows.
  r = RunKincal("sensitivity --robot " + dir + "/m/robot.yaml --obs " + dir +
                "/m/observations.csv --plot " + dir + "/never.svg");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_FALSE(Exists(dir + "/never.svg"));

  WriteFileAtomic(dir + "/bad.csv", "not;a;tracker;file\n1;2;3;4\n");
  r = RunKincal("import ipa-ur10 --in " + dir + "/bad.csv --out " + dir +
                "/never.csv");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_FALSE(Exists(dir + "/never.csv"));
  r = RunKincal("import mukca --dir " + dir + "/nowhere --out " + dir +
                "/never.csv");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_FALSE(Exists(dir + "/never.csv"));
}

TEST(PaperCliTest, ImportUr10SeriesThenCalibrate) {
  KINCAL_REQUIRE_SHARED_DATA("ipa-robot-accuracy");
  const std::string dir = MakeTempDir("paper_cli_ur10");
  RunResult r = RunKincal(
      "import ipa-ur10 --in " + SharedDataDir() +
      "/ipa-robot-accuracy/Series_C/measurements_random_poses.csv --robot " +
      SourceDir() + "/data/robots/ur10.yaml --every 4 --out " + dir +
      "/c.csv --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(ReadFile(dir + "/c.csv"), HasSubstr("# written by kincal"));
  r = RunKincal("calibrate --robot " + SourceDir() +
                "/data/robots/ur10.yaml --obs " + dir + "/c.csv --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto c = nlohmann::json::parse(r.out);
  // A geometric fit leaves about 0.5 mm on this arm (docs/REAL_DATA.md).
  EXPECT_LT(c["heldout_rms_mm"].get<double>(), 0.6);
  EXPECT_GT(c["heldout_rms_mm"].get<double>(), 0.3);
}

}  // namespace
}  // namespace kincal::testing
