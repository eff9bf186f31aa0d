// End to end: `kincal plan` writes POSES.csv (pose + one column per joint,
// in the robot's units, within limits) and the spec's JSON fields; a robot
// without joint limits is bad input (exit 2, nothing written); with a table
// plane no planned pose puts a link below it.

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "calib/chain.h"
#include "data/atomic_file.h"
#include "data/csv.h"
#include "data/robot.h"
#include "data/urdf.h"
#include "tests/testing/paths.h"
#include "tests/testing/run.h"

namespace kincal {
namespace {

using testing::RunKincal;
using testing::RunResult;

// Progress on a terminal (forced here with KINCAL_PROGRESS=1, as stderr is
// a file): the stages on stderr; --json keeps stderr clean.
TEST(PlanCli, ProgressStagesOnStderrNotWithJson) {
  const std::string dir = testing::MakeTempDir("plan_progress");
  const std::string cmd = "KINCAL_PROGRESS=1 " + testing::KincalBinary() +
                          " plan --robot " + testing::SourceDir() +
                          "/data/robots/bh7.yaml --n 20 --candidates 300 "
                          "--out " +
                          dir + "/poses.csv";
  RunResult r = testing::RunShell(cmd);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("kincal plan: choosing 20 poses"), std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("kincal plan: predicting sigma"), std::string::npos);
  r = testing::RunShell(cmd + " --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.err.find("kincal plan:"), std::string::npos) << r.err;
}

TEST(PlanCli, WritesPosesAndTheSpecFields) {
  const std::string dir = testing::MakeTempDir("plan_cli");
  const std::string robot = testing::SourceDir() + "/data/robots/bh7.yaml";
  const RunResult r = RunKincal("plan --robot " + robot + " --n 25 --out " +
                                dir + "/poses.csv --seed 3 --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["n"], 25);
  ASSERT_TRUE(j["predicted_sigma"].is_object());
  EXPECT_TRUE(j["predicted_sigma"].contains("tool.d"));
  EXPECT_GT(j["predicted_tip_rms_mm"].get<double>(), 0.0);
  EXPECT_GT(j["random_predicted_tip_rms_mm"].get<double>(),
            j["predicted_tip_rms_mm"].get<double>());
  EXPECT_TRUE(j["seconds"].is_number());

  const Robot bh7 = ReadRobotYaml(robot);
  std::istringstream in(ReadFile(dir + "/poses.csv"));
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line.rfind("# ", 0), 0u) << line;  // provenance
  std::getline(in, line);
  EXPECT_EQ(line, "pose,j1,j2,j3,j4,j5");
  int rows = 0;
  while (std::getline(in, line)) {
    std::stringstream cells(line);
    std::string cell;
    std::getline(cells, cell, ',');
    EXPECT_EQ(cell, std::to_string(rows));
    for (const RobotRow& joint : bh7.joints) {
      ASSERT_TRUE(std::getline(cells, cell, ','));
      const double v = std::stod(cell);
      EXPECT_GE(v, joint.lower);
      EXPECT_LE(v, joint.upper);
    }
    ++rows;
  }
  EXPECT_EQ(rows, 25);
}

// A campaign for the diagnosis: the JSON's coverage per joint, no wide gap
// with 40 poses; with 8 poses the gaps are wide and each joint is warned
// about (`travel_gap`, in the JSON and on stderr in text mode).
TEST(PlanCli, CoverageCampaignReportsTheGapsAndWarnsOfWideOnes) {
  const std::string dir = testing::MakeTempDir("plan_coverage");
  const std::string base = "plan --robot " + testing::SourceDir() +
                           "/data/robots/ur10.yaml --criterion coverage "
                           "--candidates 800 --out " +
                           dir + "/poses.csv";
  RunResult r = RunKincal(base + " --n 40 --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  auto j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j["coverage"]["planned"].size(), 6u);
  for (const auto& c : j["coverage"]["planned"]) {
    EXPECT_FALSE(c["wide"].get<bool>()) << c.dump();
    EXPECT_TRUE(c["circular"].get<bool>());
    EXPECT_LT(c["largest_gap"].get<double>(), 36.0) << c.dump();
  }
  EXPECT_FALSE(j.contains("warnings") && !j["warnings"].empty()) << j.dump();
  r = RunKincal(base + " --n 8 --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  j = nlohmann::json::parse(r.out);
  int gaps = 0;
  for (const auto& w : j["warnings"]) gaps += w["code"] == "travel_gap";
  EXPECT_EQ(gaps, 6) << j["warnings"].dump();
  r = RunKincal(base + " --n 8");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("warning [travel_gap]: joint 'elbow_joint'"),
            std::string::npos)
      << r.err;
  EXPECT_NE(r.out.find("travel coverage"), std::string::npos) << r.out;
  r = RunKincal("plan --robot " + testing::SourceDir() +
                "/data/robots/ur10.yaml --criterion e --n 8 --out " + dir +
                "/bad.csv");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("'coverage'"), std::string::npos) << r.err;
}

TEST(PlanCli, RobotWithoutLimitsIsBadInputAndWritesNothing) {
  const std::string dir = testing::MakeTempDir("plan_cli_nolimits");
  WriteFileAtomic(dir + "/robot.yaml",
                  "kincal_robot: 1\nname: two\nconvention: dh\njoints:\n"
                  "  - {name: a, type: revolute, d: 0, alpha: 0, a: 300, "
                  "theta: 0, limits: [-90, 90]}\n"
                  "  - {name: b, type: revolute, d: 0, alpha: 0, a: 200, "
                  "theta: 0}\n"
                  "tool: {d: 0, alpha: 0, a: 50, theta: 0}\n");
  const RunResult r =
      RunKincal("plan --robot " + dir + "/robot.yaml --n 10 --out " + dir +
                "/poses.csv --json");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("limits"), std::string::npos) << r.err;
  EXPECT_FALSE(testing::Exists(dir + "/poses.csv"));
}

// The joint values (reading units) of every row of a POSES.csv.
std::vector<std::vector<double>> ReadPoses(const std::string& path) {
  std::istringstream in(ReadFile(path));
  std::string line;
  std::getline(in, line);  // provenance
  std::getline(in, line);  // header
  std::vector<std::vector<double>> poses;
  while (std::getline(in, line)) {
    std::stringstream cells(line);
    std::string cell;
    std::getline(cells, cell, ',');
    std::vector<double> q;
    while (std::getline(cells, cell, ',')) q.push_back(std::stod(cell));
    poses.push_back(q);
  }
  return poses;
}

// The lowest height above z = 0 of the joint frames' origins past the second
// joint and of the tip, by the chain's forward kinematics (the links'
// capsules run between these points; the base and first link stand on the
// table).
double LowestLinkPoint(const Chain& chain, const std::vector<double>& q) {
  std::vector<double> qi(q.size());
  for (size_t j = 0; j < q.size(); ++j) {
    qi[j] = chain.ReadingToInternal(static_cast<int>(j), q[j]);
  }
  std::vector<Eigen::Vector3d> origins, axes;
  JointAxesInBase(chain, qi, &origins, &axes);
  double lowest = BaseFromTipAt(chain, qi)(2, 3);
  for (size_t j = 2; j < origins.size(); ++j) {
    lowest = std::min(lowest, origins[j].z());
  }
  return lowest;
}

// `plan` with a table at z = 0 (clearance 20 mm, links 40 mm thick): every
// planned pose keeps the links 60 mm above it, while random poses without
// the table go below it (so the check can fail).
void ExpectPlanClearsTheTable(const std::string& robot_args, const Robot& robot,
                              const std::string& name) {
  const std::string dir = testing::MakeTempDir("plan_table_" + name);
  WriteFileAtomic(dir + "/table.yaml",
                  "kincal_obstacles: 1\nplanes:\n"
                  "  - {name: table, point: [0, 0, 0], normal: [0, 0, 1], "
                  "clearance_mm: 20}\n");
  const std::string common =
      "plan " + robot_args + " --n 20 --candidates 400 --seed 2 --json";
  RunResult r =
      RunKincal(common + " --obstacles " + dir + "/table.yaml --out " + dir +
                "/poses.csv "
                "--random-out " +
                dir + "/random.csv");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_GT(j["rejected_collision"].get<long>(), 0);
  EXPECT_GT(j["collisions"]["plane 'table'"].get<long>(), 0);
  EXPECT_EQ(j["rejected_limits"].get<long>(), 0);  // free draws: inside
  const Chain chain = Chain::FromRobot(robot);
  for (const std::string file : {"/poses.csv", "/random.csv"}) {
    const auto poses = ReadPoses(dir + file);
    ASSERT_EQ(poses.size(), 20u);
    for (const auto& q : poses) {
      ASSERT_EQ(q.size(), robot.joints.size());
      EXPECT_GE(LowestLinkPoint(chain, q), 60.0 - 1e-6) << name << file;
      for (size_t k = 0; k < q.size(); ++k) {  // 5 % limit margin
        const double range = robot.joints[k].upper - robot.joints[k].lower;
        EXPECT_GE(q[k], robot.joints[k].lower + 0.05 * range - 1e-5);
        EXPECT_LE(q[k], robot.joints[k].upper - 0.05 * range + 1e-5);
      }
    }
  }
  r = RunKincal(common + " --out " + dir + "/free.csv --random-out " + dir +
                "/free_random.csv");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  int below = 0;
  for (const std::string file : {"/free.csv", "/free_random.csv"}) {
    for (const auto& q : ReadPoses(dir + file)) {
      below += LowestLinkPoint(chain, q) < 60.0;
    }
  }
  EXPECT_GT(below, 0) << name << ": without the table no pose met it";
}

TEST(PlanCli, Ur10TablePlaneIsNeverMet) {
  const std::string path = testing::SourceDir() + "/data/robots/ur10.yaml";
  ExpectPlanClearsTheTable("--robot " + path, ReadRobot(path), "ur10");
}

TEST(PlanCli, PandaTablePlaneIsNeverMet) {
  const std::string path =
      testing::SourceDir() + "/../shared/data/mukca/urdf/panda.urdf";
  if (!testing::Exists(path)) GTEST_SKIP() << "no " << path;
  ExpectPlanClearsTheTable("--robot " + path + " --tip panda_hand",
                           ReadRobot(path, "", "panda_hand"), "panda");
}

TEST(PlanCli, NoRoomIsBadInputNamingTheConstraint) {
  const std::string dir = testing::MakeTempDir("plan_no_room");
  WriteFileAtomic(dir + "/ceiling.yaml",
                  "kincal_obstacles: 1\nplanes:\n"
                  "  - {name: ceiling, point: [0, 0, 100], normal: [0, 0, -1]}"
                  "\n");
  const RunResult r =
      RunKincal("plan --robot " + testing::SourceDir() +
                "/data/robots/ur10.yaml --n 10 --candidates 50 --obstacles " +
                dir + "/ceiling.yaml --out " + dir + "/poses.csv --json");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("plane 'ceiling'"), std::string::npos) << r.err;
  EXPECT_FALSE(testing::Exists(dir + "/poses.csv"));
}

}  // namespace
}  // namespace kincal
