// End-to-end checks of `kincal diagnose model --folds K` (k-fold
// cross-validation of the selection): bad fold counts exit 2 and write
// nothing; the same command twice prints the same JSON; the contract's
// fields stay, the cross-validation's are added.

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>

#include "tests/testing/paths.h"
#include "tests/testing/run.h"

namespace kincal {
namespace {

using testing::RunKincal;
using testing::RunResult;

std::string Session(const std::string& name, int poses,
                    const std::string& effect = "") {
  const std::string dir = testing::MakeTempDir(name);
  const RunResult r = RunKincal(
      "simulate --robot " + testing::SourceDir() + "/data/robots/bh7.yaml" +
      " --out " + dir + "/s --poses " + std::to_string(poses) + " --seed 5" +
      (effect.empty() ? "" : " --effect " + effect));
  EXPECT_EQ(r.exit_code, 0) << r.err;
  return dir;
}

TEST(DiagnoseFoldsTest, BadFoldCountsExitTwoAndWriteNothing) {
  const std::string dir = Session("folds_bad", 50);
  const std::string base = "diagnose model --robot " + dir +
                           "/s/robot.yaml --obs " + dir +
                           "/s/observations.csv --json --out " + dir +
                           "/cal.yaml --residuals " + dir + "/res.csv";
  const RunResult many = RunKincal(base + " --folds 1000");
  EXPECT_EQ(many.exit_code, 2);
  EXPECT_NE(many.err.find("--folds 1000"), std::string::npos) << many.err;
  EXPECT_NE(many.err.find("distinct training poses"), std::string::npos)
      << many.err;
  EXPECT_TRUE(many.out.empty()) << many.out;
  const RunResult negative = RunKincal(base + " --folds -2");
  EXPECT_EQ(negative.exit_code, 2);
  EXPECT_NE(negative.err.find("--folds"), std::string::npos) << negative.err;
  EXPECT_FALSE(testing::Exists(dir + "/cal.yaml"));
  EXPECT_FALSE(testing::Exists(dir + "/res.csv"));
}

TEST(DiagnoseFoldsTest, SameJsonTwiceAndContractFields) {
  const std::string dir = Session("folds_json", 150, "backlash:j3:0.1");
  const std::string cmd = "diagnose model --robot " + dir +
                          "/s/robot.yaml --obs " + dir +
                          "/s/observations.csv --json";
  const RunResult a = RunKincal(cmd + " --folds 5");
  const RunResult b = RunKincal(cmd + " --folds 5");
  ASSERT_EQ(a.exit_code, 0) << a.err;
  ASSERT_EQ(b.exit_code, 0) << b.err;
  nlohmann::json ja = nlohmann::json::parse(a.out);
  nlohmann::json jb = nlohmann::json::parse(b.out);
  for (nlohmann::json* j : {&ja, &jb}) j->erase("seconds");
  EXPECT_EQ(ja.dump(), jb.dump());
  // The spec's fields ("Diagnosis result"), then the added ones.
  EXPECT_EQ(ja["verdict"], "effect_found");
  EXPECT_TRUE(ja["nominal"]["train_rms_mm"].is_number());
  EXPECT_TRUE(ja["nominal"]["heldout_rms_mm"].is_number());
  EXPECT_TRUE(ja["final"]["heldout_rms_mm"].is_number());
  const nlohmann::json& f = ja["findings"][0];
  EXPECT_EQ(f["cause"], "backlash");
  EXPECT_EQ(f["joint"], "j3");
  for (const char* key :
       {"magnitude", "heldout_rms_before_mm", "heldout_rms_after_mm",
        "cv_rms_before_mm", "cv_rms_after_mm"}) {
    EXPECT_TRUE(f[key].is_number()) << key;
  }
  EXPECT_EQ(f["unit"], "deg");
  EXPECT_EQ(f["ci95"].size(), 2u);
  EXPECT_EQ(ja["folds"], 5);
  EXPECT_EQ(ja["cross_validation"]["folds"], 5);
  EXPECT_TRUE(ja["cross_validation"]["nominal_rms_mm"].is_number());
  // --folds 0: the single held-out split, no cross-validated figures.
  const RunResult single = RunKincal(cmd + " --folds 0");
  ASSERT_EQ(single.exit_code, 0) << single.err;
  const nlohmann::json js = nlohmann::json::parse(single.out);
  EXPECT_EQ(js["folds"], 0);
  EXPECT_TRUE(js["nominal"]["cv_rms_mm"].is_null());
  EXPECT_EQ(js["findings"][0]["cause"], "backlash");
}

}  // namespace
}  // namespace kincal
