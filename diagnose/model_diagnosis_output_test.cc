#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <sstream>

#include "diagnose/model_diagnosis.h"

namespace kincal {
namespace {

DiagnosisResult TwoFindings() {
  DiagnosisResult r;
  r.verdict = "effect_found";
  r.train_poses = 30;
  r.heldout_poses = 10;
  Finding cyclic;
  cyclic.cause = "cyclic2";
  cyclic.joint = "j3";
  cyclic.magnitude = 0.05;
  cyclic.unit = "deg";
  cyclic.ci_low = 0.04;
  cyclic.ci_high = 0.06;
  cyclic.equivalent.push_back({"transmission8", "j3", 0.1, "deg", 0.2, 0.3});
  Finding unexplained;
  unexplained.cause = "unexplained";
  unexplained.depends_on = {"j2", "t"};
  unexplained.smooth_k = 7;
  unexplained.p_value = std::numeric_limits<double>::quiet_NaN();
  unexplained.single_inputs = {{"j2", 0.4}};
  r.findings = {cyclic, unexplained};
  CandidateScore s;
  s.cause = "drift";
  s.k = 3;
  s.train_rms_mm = std::numeric_limits<double>::quiet_NaN();
  r.steps = {{s}};
  r.rows = {1, 0};
  r.heldout = {false, true};
  r.residuals = {Eigen::Vector3d(3, 4, 0), Eigen::Vector3d(0, 0, -1)};
  return r;
}

TEST(ModelDiagnosisOutputTest, JsonNamesSpecCausesAndNulls) {
  DiagnoseOptions options;
  options.seed = 7;
  const nlohmann::json j = DiagnosisJson(TwoFindings(), options);
  EXPECT_EQ(j["verdict"], "effect_found");
  ASSERT_EQ(j["findings"].size(), 2u);
  const nlohmann::json& f = j["findings"][0];
  EXPECT_EQ(f["cause"], "cyclic");  // cyclic2 is the spec's cyclic
  EXPECT_EQ(f["harmonic"], 2);
  EXPECT_TRUE(f["terms"].is_null());
  EXPECT_EQ(f["ci95"][1], 0.06);
  EXPECT_EQ(f["equivalent"][0]["cause"], "transmission");
  EXPECT_EQ(f["equivalent"][0]["terms"], 8);
  const nlohmann::json& u = j["findings"][1];
  EXPECT_TRUE(u["joint"].is_null());
  EXPECT_TRUE(u["p_value"].is_null());  // NaN becomes null
  EXPECT_EQ(u["depends_on"][1], "t");
  EXPECT_EQ(u["smooth_correction"]["k"], 7);
  EXPECT_EQ(u["smooth_correction"]["single_input_cv_explained"]["j2"], 0.4);
  EXPECT_TRUE(j["steps"][0][0]["train_rms_mm"].is_null());
  EXPECT_TRUE(j["steps"][0][0]["joint"].is_null());
  EXPECT_EQ(j["steps"][0][0]["parameters"], 3);
  EXPECT_EQ(j["seed"], 7);
  EXPECT_EQ(j["cross_validation"]["selection"], "single held-out split");
}

TEST(ModelDiagnosisOutputTest, ResidualsCsvRowsAndSets) {
  Observations obs;
  obs.rows.resize(2);
  obs.rows[0].pose = "p0";
  obs.rows[1].pose = "p,1";
  const std::string csv = ResidualsCsv(TwoFindings(), obs);
  std::istringstream in(csv);
  std::string line, header;
  int comments = 0;
  while (std::getline(in, line) && line[0] == '#') ++comments;
  EXPECT_EQ(comments, 2);
  EXPECT_EQ(line, "pose,set,dx_mm,dy_mm,dz_mm,error_mm");
  std::getline(in, line);
  EXPECT_EQ(line.substr(0, 12), "\"p,1\",train,");
  EXPECT_NE(line.find(",5"), std::string::npos);  // |(3, 4, 0)| = 5
  std::getline(in, line);
  EXPECT_EQ(line.substr(0, 11), "p0,heldout,");
}

}  // namespace
}  // namespace kincal
