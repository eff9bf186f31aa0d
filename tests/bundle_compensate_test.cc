// The bundle's robot goes back to the robot with its uncertainty: a rendered
// BH-7 session is bundled (`kincal bundle --out`), then `kincal compensate`
// takes a joint program of 200 fresh poses of the same true robot. The
// robot file carries the frames the bundle used (fitted_on) and a
// covariance, so compensate gives every target a finite sigma; the true
// error of the bundle's model at each fresh pose (noise-free true tips in
// the rig frame, the model through its recorded frame) is compared with it.

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "calib/chain.h"
#include "calib/inverse_kinematics.h"
#include "data/observations.h"
#include "data/rigid3.h"
#include "data/robot.h"
#include "tests/testing/fresh_poses.h"
#include "tests/testing/paths.h"
#include "tests/testing/run.h"

namespace kincal {
namespace {

using testing::RunKincal;
using testing::RunResult;

// A joint program (compensate --targets, joint columns only) of `obs`' rows.
void WriteJointProgram(const Observations& obs, const std::string& path) {
  std::ofstream out(path);
  out << "target";
  for (const std::string& j : obs.joint_names) out << "," << j;
  out << "\n";
  out.precision(17);
  for (size_t i = 0; i < obs.rows.size(); ++i) {
    out << "f" << i;
    for (double q : obs.rows[i].q) out << "," << q;
    out << "\n";
  }
}

// A simulated session's true measuring frame (truth.json meas_from_base):
// the rig with --render, another frame without.
Rigid3 TrueMeasFromBase(const std::string& truth_json) {
  std::ifstream in(truth_json);
  const nlohmann::json j = nlohmann::json::parse(in);
  std::array<double, 6> block{};
  for (int k = 0; k < 3; ++k) {
    block[k] = j["meas_from_base"]["rotation_vector_deg"][k].get<double>() *
               M_PI / 180.0;
    block[k + 3] = j["meas_from_base"]["t_mm"][k].get<double>();
  }
  return Rigid3FromPoseBlock(block.data());
}

TEST(BundleCompensate, FileCarriesUsedTravelAndASigmaThatCoversTheError) {
  const std::string bh7 = testing::SourceDir() + "/data/robots/bh7.yaml";
  const std::string dir = testing::MakeTempDir("bundle_compensate");
  const std::string s = dir + "/s";
  RunResult r =
      RunKincal("simulate --robot " + bh7 + " --out " + s +
                " --poses 120 --noise 0 --seed 7 --render --render-noise 1.5 "
                "--render-blur 0.5 --render-width 640 --render-height 512 "
                "--render-cameras 2");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  r = RunKincal("bundle --robot " + s + "/robot.yaml --rig " + s +
                "/rig.yaml --target " + s + "/target.yaml --session " + s +
                "/session --quiet --out " + dir + "/b.yaml --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json bundle = nlohmann::json::parse(r.out);

  // fitted_on: the training frames the bundle used, not the session's 120.
  const Robot cal = ReadRobotYaml(dir + "/b.yaml");
  EXPECT_EQ(cal.fitted_on.poses, bundle["train_frames"].get<int>());
  EXPECT_LT(cal.fitted_on.poses, 120);
  EXPECT_FALSE(cal.fitted_on.covariance_params.empty());
  ASSERT_TRUE(cal.fitted_on.has_frame);

  // 200 fresh poses of the same true robot (rows 120..319 of the seed).
  r = RunKincal("simulate --robot " + bh7 + " --out " + dir +
                "/fresh --poses 320 --noise 0 --seed 7");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  testing::KeepRowsFrom(dir + "/fresh/observations.csv", dir + "/fresh.csv",
                        120);
  const Observations fresh =
      ReadObservationsCsv(dir + "/fresh.csv", cal.JointNames());
  ASSERT_EQ(fresh.rows.size(), 200u);
  WriteJointProgram(fresh, dir + "/T.csv");
  r = RunKincal("compensate --robot " + dir + "/b.yaml --targets " + dir +
                "/T.csv --out " + dir + "/Q.csv --skip-unreachable --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json comp = nlohmann::json::parse(r.out);
  for (const auto& w : comp.value("warnings", nlohmann::json::array())) {
    EXPECT_NE(w["code"], "no_covariance") << w["message"];
    EXPECT_NE(w["code"], "no_fit_record") << w["message"];
  }
  ASSERT_EQ(comp["targets"].size(), fresh.rows.size());

  // The model's tip in the rig frame (the recorded frame) against the true
  // tip there (the fresh tips moved from their session's frame into the
  // rendered session's rig), over the predicted sigma.
  const Rigid3 rig_from_fresh =
      TrueMeasFromBase(s + "/truth.json") *
      TrueMeasFromBase(dir + "/fresh/truth.json").Inverse();
  const Chain model = Chain::FromRobot(cal);
  std::array<double, 6> frame = cal.fitted_on.frame;
  for (int k = 0; k < 3; ++k) frame[k] *= M_PI / 180.0;
  double sum_z2 = 0, sum_e2 = 0, sum_s2 = 0, inside_z2 = 0;
  int inside = 0;  // inside the fitted travel
  for (size_t i = 0; i < fresh.rows.size(); ++i) {
    const nlohmann::json& t = comp["targets"][i];
    ASSERT_TRUE(t["sigma_mm"].is_number()) << t.dump();
    const double sigma = t["sigma_mm"].get<double>();
    ASSERT_TRUE(std::isfinite(sigma) && sigma > 0) << t.dump();
    const Eigen::Vector3d tip = ApplyFrame(
        frame.data(),
        Vec3<double>(
            ModelPoseAtReadings(model, fresh.rows[i].q, {}).block<3, 1>(0, 3)));
    const double e = (tip - rig_from_fresh * fresh.rows[i].p_in_meas).norm();
    sum_z2 += e * e / (sigma * sigma);
    if (t["extrapolated"].empty()) {
      inside_z2 += e * e / (sigma * sigma);
      ++inside;
    }
    sum_e2 += e * e;
    sum_s2 += sigma * sigma;
  }
  const double n = static_cast<double>(fresh.rows.size());
  const double rms_z = std::sqrt(sum_z2 / n);
  std::printf(
      "bundle on %d of 120 frames: RMS true error %.4f mm, RMS predicted "
      "sigma %.4f mm, RMS error/sigma %.3f over %zu fresh poses\n",
      cal.fitted_on.poses, std::sqrt(sum_e2 / n), std::sqrt(sum_s2 / n), rms_z,
      fresh.rows.size());
  std::printf("inside the fitted travel: %d poses, RMS error/sigma %.3f\n",
              inside, std::sqrt(inside_z2 / std::max(1, inside)));
  RecordProperty("rms_error_over_sigma", std::to_string(rms_z));
  // Measured 1.338 (1.161 over the 44 poses inside the fitted travel; true
  // error 0.053 mm against a predicted 0.040 mm). It was 3.07 while the
  // corners carried a tag-scale bias and a fixed 1 px Huber scale let a few
  // gross corners pull the robot (docs/BUNDLE.md). On synthetic corners with
  // independent noise the same propagation gives 0.98
  // (bundle_robot_record_test).
  EXPECT_LT(rms_z, 1.6);
  EXPECT_GT(rms_z, 0.7);
}

}  // namespace
}  // namespace kincal
