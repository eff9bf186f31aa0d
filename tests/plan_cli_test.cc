// End to end: `kincal plan` writes POSES.csv (pose + one column per joint,
// in the robot's units, within limits) and the spec's JSON fields; a robot
// without joint limits is bad input (exit 2, nothing written).

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "data/atomic_file.h"
#include "data/csv.h"
#include "data/robot.h"
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

}  // namespace
}  // namespace kincal
