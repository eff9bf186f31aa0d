// End to end: `kincal plan --iso9283 --cube MM` writes POSES.csv (pose, one
// column per joint in the robot's units, fixed_point = P1..P5, rows in
// visiting order over all cycles) that reads as an observations.csv, and
// the spec's JSON fields (n, cube_center_mm, poses); the joints of every row
// put the nominal tip on its position (and, on a 6-joint arm, at the one
// tool orientation); a cube that does not fit is bad input naming the
// position.

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "calib/chain.h"
#include "calib/inverse_kinematics.h"
#include "data/atomic_file.h"
#include "data/observations.h"
#include "data/rigid3.h"
#include "data/robot.h"
#include "tests/testing/paths.h"
#include "tests/testing/run.h"

namespace kincal {
namespace {

using testing::RunKincal;
using testing::RunResult;

std::string RobotPath(const std::string& name) {
  return testing::SourceDir() + "/data/robots/" + name;
}

Eigen::Vector3d Vec3(const nlohmann::json& j) {
  return Eigen::Vector3d(j[0].get<double>(), j[1].get<double>(),
                         j[2].get<double>());
}

// Runs the plan and checks the file against the JSON: 5 x cycles rows in
// the order P5 P4 P3 P2 P1, each row's joints reaching its label's position
// (and orientation). Returns the JSON.
nlohmann::json PlanAndCheck(const std::string& robot_file,
                            const std::string& options, int cycles) {
  const std::string dir = testing::MakeTempDir("plan_iso9283");
  const std::string out = dir + "/poses.csv";
  const RunResult r =
      RunKincal("plan --robot " + RobotPath(robot_file) + " --iso9283 " +
                options + " --out " + out + " --json");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  if (r.exit_code != 0) return {};
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["n"].get<int>(), 5 * cycles);
  EXPECT_EQ(j["cycles"].get<int>(), cycles);
  EXPECT_EQ(j["cube_center_mm"].size(), 3u);
  EXPECT_TRUE(j["seconds"].is_number());
  const auto& poses = j["poses"];
  EXPECT_EQ(poses.size(), 5u);

  const Robot robot = ReadRobotYaml(RobotPath(robot_file));
  const Chain chain = Chain::FromRobot(robot);
  std::vector<std::string> names;
  for (const RobotRow& row : robot.joints) names.push_back(row.name);
  EXPECT_EQ(ReadFile(out).rfind("# ", 0), 0u);  // provenance
  const Observations obs = ReadObservationsCsv(out, names);
  EXPECT_EQ(static_cast<int>(obs.rows.size()), 5 * cycles);
  const bool oriented = !j["orientation_deg"].is_null();
  const Eigen::Matrix3d rotation =
      oriented
          ? RotationMatrixFromVector(Vec3(j["orientation_deg"]) * M_PI / 180)
          : Eigen::Matrix3d::Identity();
  const char* order[5] = {"P5", "P4", "P3", "P2", "P1"};
  for (size_t row = 0; row < obs.rows.size(); ++row) {
    const Observation& o = obs.rows[row];
    EXPECT_EQ(o.fixed_point, order[row % 5]) << row;
    const int label = o.fixed_point[1] - '1';
    EXPECT_EQ(poses[label]["pose"], o.fixed_point);
    const Eigen::Matrix4d at = ModelPoseAtReadings(chain, o.q, {}, false);
    // 9 decimals of a degree in the file: 2e-8 mm at 1.5 m.
    EXPECT_LT((at.block<3, 1>(0, 3) - Vec3(poses[label]["position_mm"])).norm(),
              1e-6)
        << row;
    if (oriented) {
      const Eigen::AngleAxisd off(at.block<3, 3>(0, 0) * rotation.transpose());
      EXPECT_LT(off.angle() * 180 / M_PI, 1e-6) << row;
    }
    for (size_t k = 0; k < names.size(); ++k) {
      EXPECT_NEAR(o.q[k], poses[label]["joints"][k].get<double>(), 1e-8);
      EXPECT_GE(o.q[k], robot.joints[k].lower);
      EXPECT_LE(o.q[k], robot.joints[k].upper);
    }
  }
  return j;
}

TEST(PlanIso9283Cli, Ur10CubeHoldsOneOrientation) {
  const auto j = PlanAndCheck("ur10.yaml", "--cube 400", 30);
  ASSERT_FALSE(j.is_null());
  EXPECT_EQ(j["cube_mm"].get<double>(), 400.0);
  EXPECT_TRUE(j["orientation_deg"].is_array());
}

TEST(PlanIso9283Cli, Ur10GivenCentreAndOrientation) {
  const auto j = PlanAndCheck(
      "ur10.yaml",
      "--cube 300 --cycles 4 --cube-center -600,-300,400 --orientation "
      "180,0,0",
      4);
  ASSERT_FALSE(j.is_null());
  EXPECT_LT(
      (Vec3(j["cube_center_mm"]) - Eigen::Vector3d(-600, -300, 400)).norm(),
      1e-9);
  EXPECT_LT((Vec3(j["orientation_deg"]) - Eigen::Vector3d(180, 0, 0)).norm(),
            1e-6);
  // P1 is the centre.
  EXPECT_LT(
      (Vec3(j["poses"][0]["position_mm"]) - Eigen::Vector3d(-600, -300, 400))
          .norm(),
      1e-9);
}

TEST(PlanIso9283Cli, Bh7CubePositionsOnly) {
  const auto j = PlanAndCheck("bh7.yaml", "--cube 100 --cycles 2", 2);
  ASSERT_FALSE(j.is_null());
  EXPECT_TRUE(j["orientation_deg"].is_null());
}

TEST(PlanIso9283Cli, CubeTooLargeIsBadInputNamingThePosition) {
  const std::string dir = testing::MakeTempDir("plan_iso9283_large");
  const RunResult r =
      RunKincal("plan --robot " + RobotPath("ur10.yaml") +
                " --iso9283 --cube 3000 --out " + dir + "/poses.csv --json");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("does not fit: P2 at ("), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("unreachable"), std::string::npos) << r.err;
  EXPECT_FALSE(testing::Exists(dir + "/poses.csv"));
}

TEST(PlanIso9283Cli, OptionsOfTheOtherModeAreRefused) {
  const std::string dir = testing::MakeTempDir("plan_iso9283_mixed");
  const std::string robot = " --robot " + RobotPath("bh7.yaml");
  RunResult r = RunKincal("plan" + robot + " --iso9283 --cube 100 --n 10 " +
                          "--out " + dir + "/a.csv");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("--n"), std::string::npos) << r.err;
  r = RunKincal("plan" + robot + " --out " + dir + "/b.csv");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("--n is required"), std::string::npos) << r.err;
  r = RunKincal("plan" + robot + " --n 10 --cube 100 --out " + dir + "/c.csv");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("go with --iso9283"), std::string::npos) << r.err;
  r = RunKincal("plan" + robot + " --iso9283 --out " + dir + "/d.csv");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("--cube"), std::string::npos) << r.err;
  for (const char* f : {"/a.csv", "/b.csv", "/c.csv", "/d.csv"}) {
    EXPECT_FALSE(testing::Exists(dir + f)) << f;
  }
}

// Every `kincal plan ... --iso9283` command of docs/PLAN.md runs (from the
// repository root's data, writing into a temporary folder) and exits 0.
TEST(PlanIso9283Cli, DocCommandsRun) {
  const std::string doc = ReadFile(testing::SourceDir() + "/docs/PLAN.md");
  const std::string dir = testing::MakeTempDir("plan_iso9283_doc");
  std::istringstream in(doc);
  std::string line;
  int commands = 0;
  while (std::getline(in, line)) {
    if (line.rfind("kincal plan ", 0) != 0 ||
        line.find("--iso9283") == std::string::npos) {
      continue;
    }
    ++commands;
    const std::string command = "cd " + dir + " && ln -sfn " +
                                testing::SourceDir() + "/data data && " +
                                testing::KincalBinary() + line.substr(6);
    const RunResult r = testing::RunShell(command);
    EXPECT_EQ(r.exit_code, 0) << line << "\n" << r.err;
  }
  EXPECT_EQ(commands, 2);
  EXPECT_TRUE(testing::Exists(dir + "/ur10_iso9283.csv"));
  EXPECT_TRUE(testing::Exists(dir + "/bh7_iso9283.csv"));
}

}  // namespace
}  // namespace kincal
