// End-to-end tests of `kincal compensate` through the public commands:
// a true robot with hidden effects is simulated (`kincal simulate`),
// calibrated and diagnosed (`kincal diagnose model --out`), then fresh
// targets are compensated (`kincal compensate`) and the commanded readings
// "executed" on the true robot, in the commanded order (backlash follows
// it). The lab states its instrument's noise (--noise), which lets the
// diagnosis size what its model leaves unexplained. Targets are given in the
// instrument's frame (where a lab locates them) and the executed tips compared
// there. The figures are printed; the assertions are the issue's: tip error at
// most 1.5x the measurement noise and 5x below the nominal inverse kinematics'
// readings, and an honest predicted sigma.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "calib/inverse_kinematics.h"
#include "data/csv.h"
#include "data/observations.h"
#include "data/robot.h"
#include "data/targets_csv.h"
#include "data/urdf.h"
#include "tests/testing/paths.h"
#include "tests/testing/run.h"

namespace kincal {
namespace {

using ::testing::HasSubstr;
using testing::RunKincal;
using testing::RunResult;

void WriteText(const std::string& path, const std::string& text) {
  std::ofstream(path) << text;
}

struct RoundTripCase {
  std::string name;
  std::string robot_args;  // --robot ... [--tip ...]
  std::vector<std::string> effects;
  double noise_mm = 0.02;
  int poses = 300;
};

struct RoundTripFigures {
  double compensated_rms_mm = 0, nominal_rms_mm = 0, z_rms = 0;
  double noise_3d_mm = 0;
  int n = 0;
};

// Fresh targets: the true robot's tips at random readings inside the limits
// (less 10 % of each range), in a seeded order; in the true base frame.
std::vector<Eigen::Vector3d> FreshTargets(const Robot& truth, int n,
                                          uint64_t seed) {
  const Chain chain = Chain::FromRobot(truth);
  std::mt19937 rng(seed);
  std::vector<Eigen::Vector3d> out;
  for (int i = 0; i < n; ++i) {
    std::vector<double> q;
    for (const RobotRow& j : truth.joints) {
      const double lo = j.HasLimits() ? j.lower : -170.0;
      const double hi = j.HasLimits() ? j.upper : 170.0;
      const double m = 0.1 * (hi - lo);
      q.push_back(std::uniform_real_distribution<double>(lo + m, hi - m)(rng));
    }
    out.push_back(ModelPoseAtReadings(chain, q, {}, false).block<3, 1>(0, 3));
  }
  return out;
}

// The true measuring frame of a simulated session (truth.json): the
// instrument that locates the targets.
Eigen::Isometry3d TrueMeasFromBase(const std::string& truth_json) {
  std::ifstream in(truth_json);
  const nlohmann::json j = nlohmann::json::parse(in);
  const auto r = j["meas_from_base"]["rotation_vector_deg"];
  const auto t = j["meas_from_base"]["t_mm"];
  const Eigen::Vector3d w =
      Eigen::Vector3d(r[0].get<double>(), r[1].get<double>(),
                      r[2].get<double>()) *
      M_PI / 180.0;
  Eigen::Isometry3d m = Eigen::Isometry3d::Identity();
  m.linear() = Eigen::AngleAxisd(w.norm(), w.normalized()).toRotationMatrix();
  m.translation() = Eigen::Vector3d(t[0].get<double>(), t[1].get<double>(),
                                    t[2].get<double>());
  return m;
}

// The true robot's tip for commanded rows in order (approach directions
// from the order; session time 0).
std::vector<Eigen::Vector3d> Execute(
    const Robot& truth, const std::vector<std::vector<double>>& rows) {
  const Chain chain = Chain::FromRobot(truth);
  std::vector<Eigen::Vector3d> tips;
  std::vector<double> previous, s;
  for (const auto& q : rows) {
    s = ApproachDirections(previous, q, s);
    IkContext context;
    context.s = s;
    tips.push_back(ModelPoseAtReadings(chain, q, context).block<3, 1>(0, 3));
    previous = q;
  }
  return tips;
}

std::vector<std::vector<double>> ReadJointRows(const std::string& path,
                                               const Robot& robot) {
  const TargetsFile f = ReadTargetsCsv(path, robot.JointNames());
  std::vector<std::vector<double>> rows;
  for (const TargetRow& r : f.rows) rows.push_back(r.joints);
  return rows;
}

RoundTripFigures RunRoundTrip(const RoundTripCase& c) {
  const std::string dir = testing::MakeTempDir("compensate_" + c.name);
  std::string effects;
  for (const auto& e : c.effects) effects += " --effect " + e;
  RunResult sim =
      RunKincal("simulate " + c.robot_args + " --out " + dir + "/sim --poses " +
                std::to_string(c.poses) + " --noise " +
                std::to_string(c.noise_mm) + " --no-time --seed 11" + effects);
  EXPECT_EQ(sim.exit_code, 0) << sim.err;
  const Robot truth = ReadRobotYaml(dir + "/sim/truth_robot.yaml");
  const Robot nominal = ReadRobotYaml(dir + "/sim/robot.yaml");
  RunResult diag = RunKincal(
      "diagnose model --robot " + dir + "/sim/robot.yaml --obs " + dir +
      "/sim/observations.csv --out " + dir + "/extended.yaml --noise " +
      std::to_string(c.noise_mm) + " --json");
  EXPECT_EQ(diag.exit_code, 0) << diag.err;
  std::printf("[%s] diagnosis: %s\n", c.name.c_str(),
              nlohmann::json::parse(diag.out)["findings"].dump().c_str());
  // The lab's case: targets located by the instrument (in its frame), the
  // model placing them through the frame it was registered in.
  const Eigen::Isometry3d meas_from_base =
      TrueMeasFromBase(dir + "/sim/truth.json");
  std::vector<Eigen::Vector3d> goals = FreshTargets(truth, 200, 23);
  for (Eigen::Vector3d& g : goals) g = meas_from_base * g;
  std::ostringstream targets_csv;
  targets_csv.precision(12);
  targets_csv << "target,x,y,z\n";
  for (size_t i = 0; i < goals.size(); ++i) {
    targets_csv << "T" << i + 1 << "," << goals[i].x() << "," << goals[i].y()
                << "," << goals[i].z() << "\n";
  }
  WriteText(dir + "/targets.csv", targets_csv.str());
  RunResult comp = RunKincal(
      "compensate --robot " + dir + "/extended.yaml --targets " + dir +
      "/targets.csv --frame measuring --out " + dir + "/q.csv --json");
  EXPECT_EQ(comp.exit_code, 0) << comp.err;
  const nlohmann::json j = nlohmann::json::parse(comp.out);
  EXPECT_EQ(j["n"], 200);
  EXPECT_EQ(j["reached"], 200);
  // The controller's readings for the same targets: the nominal model's
  // inverse kinematics (what commanding without compensation does).
  const std::vector<std::vector<double>> compensated =
      ReadJointRows(dir + "/q.csv", truth);
  std::vector<std::vector<double>> controller;
  std::vector<double> sigma;
  for (const auto& t : j["targets"]) {
    controller.push_back(t["q_nominal"].get<std::vector<double>>());
    sigma.push_back(t["sigma_mm"].get<double>());
  }
  auto tips = Execute(truth, compensated);
  auto nominal_tips = Execute(truth, controller);
  for (auto& p : tips) p = meas_from_base * p;
  for (auto& p : nominal_tips) p = meas_from_base * p;
  RoundTripFigures f;
  f.n = static_cast<int>(tips.size());
  double z2 = 0;
  for (int i = 0; i < f.n; ++i) {
    const Eigen::Vector3d& goal = goals[i];
    const double e = (tips[i] - goal).norm();
    f.compensated_rms_mm += e * e;
    f.nominal_rms_mm += (nominal_tips[i] - goal).squaredNorm();
    z2 += (e / sigma[i]) * (e / sigma[i]);
  }
  f.compensated_rms_mm = std::sqrt(f.compensated_rms_mm / f.n);
  f.nominal_rms_mm = std::sqrt(f.nominal_rms_mm / f.n);
  f.z_rms = std::sqrt(z2 / f.n);
  f.noise_3d_mm = std::sqrt(3.0) * c.noise_mm;
  std::printf(
      "[%s] 200 fresh targets on the true robot: compensated RMS %.4f mm, "
      "nominal IK %.4f mm (ratio %.1f), measurement noise (3D) %.4f mm, "
      "RMS error/sigma %.2f, predicted RMS %.4f mm\n",
      c.name.c_str(), f.compensated_rms_mm, f.nominal_rms_mm,
      f.nominal_rms_mm / f.compensated_rms_mm, f.noise_3d_mm, f.z_rms,
      j["predicted_rms_mm"].get<double>());
  return f;
}

// `z_low`, `z_high`: the RMS error / sigma accepted (the issue's 0.7..1.4
// unless the case says why its sigma is off).
void ExpectIssueFigures(const RoundTripFigures& f, double z_low = 0.7,
                        double z_high = 1.4) {
  EXPECT_LE(f.compensated_rms_mm, 1.5 * f.noise_3d_mm);
  EXPECT_GE(f.nominal_rms_mm / f.compensated_rms_mm, 5.0);
  EXPECT_GE(f.z_rms, z_low);
  EXPECT_LE(f.z_rms, z_high);
}

// BH-7's diagnosis names the hidden j2 transmission as a periodic function
// over the revolution; the robot file's covariance carries its fitted
// coefficients with their basis, so sigma covers it too.
TEST(CompensateCli, RoundTripBh7) {
  ExpectIssueFigures(RunRoundTrip(
      {"bh7",
       "--robot " + testing::SourceDir() + "/data/robots/bh7.yaml",
       {"backlash:j3:0.05", "compliance:j5:0.03", "transmission:j2:0.02"}}));
}

TEST(CompensateCli, RoundTripUr10) {
  ExpectIssueFigures(RunRoundTrip(
      {"ur10",
       "--robot " + testing::SourceDir() + "/data/robots/ur10.yaml",
       {"backlash:shoulder_lift_joint:0.05", "compliance:elbow_joint:0.03",
        "transmission:wrist_1_joint:0.02"}}));
}

TEST(CompensateCli, RoundTripPanda) {
  const std::string urdf = testing::SharedDataDir() + "/mukca/urdf/panda.urdf";
  if (!testing::Exists(urdf)) {
    GTEST_SKIP() << "shared data absent: " << urdf;
  }
  ExpectIssueFigures(RunRoundTrip(
      {"panda",
       "--robot " + urdf + " --tip panda_hand",
       {"backlash:panda_joint2:0.05", "compliance:panda_joint4:0.03",
        "transmission:panda_joint6:0.02"}}));
}

TEST(CompensateCli, ContractUnreachableProgramAndBadInput) {
  const std::string dir = testing::MakeTempDir("compensate_contract");
  const std::string robot = testing::SourceDir() + "/data/robots/ur10.yaml";
  WriteText(dir + "/t.csv",
            "target,x,y,z,rx,ry,rz\n"
            "a,-800,-200,400,180,0,0\n"
            "far,4000,0,0,0,0,0\n");
  RunResult r = RunKincal("compensate --robot " + robot + " --targets " + dir +
                          "/t.csv --out " + dir + "/q.csv --json");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.err, HasSubstr("1 of 2 targets cannot be reached; the first, "
                               "far"));
  EXPECT_THAT(r.err, HasSubstr("--skip-unreachable"));
  EXPECT_FALSE(testing::Exists(dir + "/q.csv"));
  r = RunKincal("compensate --robot " + robot + " --targets " + dir +
                "/t.csv --out " + dir +
                "/q.csv --skip-unreachable "
                "--program urscript --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  for (const char* key : {"n", "reached", "unreachable", "extrapolated",
                          "predicted_rms_mm", "predicted_max_mm", "seconds"}) {
    EXPECT_TRUE(j.contains(key)) << key;
  }
  EXPECT_EQ(j["unreachable"], nlohmann::json::array({"far"}));
  EXPECT_EQ(j["program"], dir + "/q.script");
  // A nominal robot file without a record: compensation is the identity up
  // to the solver, and the missing record is said.
  EXPECT_THAT(j["warnings"].dump(), HasSubstr("no_covariance"));
  std::ifstream script(dir + "/q.script");
  std::stringstream ss;
  ss << script.rdbuf();
  EXPECT_THAT(ss.str(), HasSubstr("movej(["));
  EXPECT_THAT(ss.str(), HasSubstr("# a\n"));
  std::ifstream q(dir + "/q.csv");
  std::stringstream qs;
  qs << q.rdbuf();
  EXPECT_THAT(qs.str(), HasSubstr("target,shoulder_pan_joint,"));
  EXPECT_THAT(qs.str(), HasSubstr("# written by"));
  // A bad cell: file:line:column and exit 2.
  WriteText(dir + "/bad.csv", "target,x,y,z\na,1,two,3\n");
  r = RunKincal("compensate --robot " + robot + " --targets " + dir +
                "/bad.csv --out " + dir + "/q2.csv");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.err, HasSubstr("bad.csv:2:5: y: expected a number"));
  // A program in radians is said.
  WriteText(dir + "/rad.csv",
            "pose,shoulder_pan_joint,shoulder_lift_joint,elbow_joint,"
            "wrist_1_joint,wrist_2_joint,wrist_3_joint\n"
            "1,0.1,-1.5,1.4,-1.5,-1.5,0.2\n2,0.5,-1.1,1.0,-1.6,-1.5,0.3\n"
            "3,0.9,-0.9,0.7,-1.7,-1.5,0.4\n4,1.3,-0.5,0.4,-1.8,-1.5,0.5\n");
  r = RunKincal("compensate --robot " + robot + " --targets " + dir +
                "/rad.csv --out " + dir + "/q3.csv --json");
  EXPECT_THAT(r.out + r.err, HasSubstr("joint_units_radians"));
}

// docs/COMPENSATE.md's first block, as written (run from the source tree,
// outputs in a temporary folder).
TEST(CompensateCli, DocsExampleRuns) {
  const std::string dir = testing::MakeTempDir("compensate_docs");
  const std::string cd = "cd " + testing::SourceDir() + " && ";
  const std::string k = testing::KincalBinary();
  RunResult r =
      testing::RunShell(cd + k +
                        " diagnose model --robot data/robots/bh7.yaml --obs "
                        "data/sessions/bh7_demo/observations.csv --out " +
                        dir + "/extended.yaml");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  r = testing::RunShell(cd + k +
                        " plan --robot data/robots/bh7.yaml --n 20 --seed 3 "
                        "--out " +
                        dir + "/poses.csv");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  r = testing::RunShell(cd + k + " compensate --robot " + dir +
                        "/extended.yaml --targets " + dir +
                        "/poses.csv --out " + dir + "/compensated.csv --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["n"], 20);
  EXPECT_EQ(j["reached"], 20);
  // The demo's hidden clearance: the nominal program misses by it.
  EXPECT_GT(j["uncompensated_rms_mm"].get<double>(),
            5 * j["predicted_rms_mm"].get<double>());
  std::ifstream doc(testing::SourceDir() + "/docs/COMPENSATE.md");
  std::stringstream text;
  text << doc.rdbuf();
  EXPECT_THAT(text.str(),
              HasSubstr("kincal compensate --robot extended.yaml --targets "
                        "poses.csv --out compensated.csv --json"));
}

}  // namespace
}  // namespace kincal
