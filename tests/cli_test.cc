// End-to-end tests of simulate, calibrate and evaluate through the public
// command line: the contract of ../shared/spec/formats.md (JSON fields, exit
// codes 0/1/2, no partial output on bad input).

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <vector>

#include "data/atomic_file.h"
#include "data/observations.h"
#include "data/robot.h"
#include "tests/testing/paths.h"
#include "tests/testing/run.h"

namespace kincal::testing {
namespace {

using ::testing::HasSubstr;

class CliTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new std::string(MakeTempDir("cli"));
    const RunResult r = RunKincal(
        "simulate --robot " + SourceDir() + "/data/robots/bh7.yaml --out " +
        *dir_ + "/s --poses 120 --noise 0.03 --seed 4 --json");
    ASSERT_EQ(r.exit_code, 0) << r.err;
  }
  static std::string Dir() { return *dir_; }
  static std::string Robot() { return Dir() + "/s/robot.yaml"; }
  static std::string Obs() { return Dir() + "/s/observations.csv"; }
  static std::string* dir_;
};
std::string* CliTest::dir_ = nullptr;

void WriteText(const std::string& path, const std::string& text) {
  std::ofstream(path) << text;
}

TEST_F(CliTest, SimulateWritesSessionWithProvenance) {
  for (const char* f : {"robot.yaml", "observations.csv", "truth.json"}) {
    EXPECT_TRUE(Exists(Dir() + "/s/" + f)) << f;
  }
  const std::string obs = ReadFile(Obs());
  EXPECT_THAT(obs, HasSubstr("# written by kincal"));
  EXPECT_THAT(obs, HasSubstr("--seed 4"));
  EXPECT_THAT(obs, HasSubstr("pose,j1,j2,j3,j4,j5,x,y,z,t"));
  // Same seed, same bytes (apart from the command line with its folder).
  const RunResult again = RunKincal("simulate --robot " + SourceDir() +
                                    "/data/robots/bh7.yaml --out " + Dir() +
                                    "/s2 --poses 120 --noise 0.03 --seed 4");
  ASSERT_EQ(again.exit_code, 0);
  const std::string obs2 = ReadFile(Dir() + "/s2/observations.csv");
  EXPECT_EQ(obs.substr(obs.find("pose,")), obs2.substr(obs2.find("pose,")));
}

TEST_F(CliTest, CalibrateJsonContract) {
  const std::string out = Dir() + "/cal.yaml";
  const RunResult r = RunKincal("calibrate --robot " + Robot() + " --obs " +
                                Obs() + " --out " + out + " --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  for (const char* key : {"train_rms_mm", "heldout_rms_mm", "identifiable",
                          "unidentifiable", "seconds", "command"}) {
    EXPECT_TRUE(j.contains(key)) << key;
  }
  EXPECT_LT(j["heldout_rms_mm"].get<double>(), 0.07);
  EXPECT_GT(j["identifiable"].size(), 6u);
  EXPECT_THAT(j["unidentifiable"].dump(), HasSubstr("j1.theta"));
  // The calibrated model is a valid robot.yaml and evaluates better than the
  // nominal one.
  const kincal::Robot cal = ReadRobotYaml(out);
  EXPECT_EQ(cal.joints.size(), 5u);
  const RunResult ev =
      RunKincal("evaluate --robot " + out + " --obs " + Obs() + " --json");
  ASSERT_EQ(ev.exit_code, 0) << ev.err;
  const auto e = nlohmann::json::parse(ev.out);
  for (const char* key : {"n", "rms_mm", "mean_mm", "max_mm", "std_mm"}) {
    EXPECT_TRUE(e.contains(key)) << key;
  }
  EXPECT_EQ(e["n"].get<int>(), 120);
  const RunResult nominal =
      RunKincal("evaluate --robot " + Robot() + " --obs " + Obs() + " --json");
  EXPECT_GT(nlohmann::json::parse(nominal.out)["rms_mm"].get<double>(),
            5 * e["rms_mm"].get<double>());
}

// Gross errors through the command line: three rows' x moved by 15 mm are
// listed (JSON `outliers`, text "left out") and left out of the fit;
// evaluate (of the calibrated model) lists them and adds `without_outliers`,
// keeping the spec's figures over every row.
TEST_F(CliTest, GrossRowsAreListedAndLeftOut) {
  std::istringstream in(ReadFile(Obs()));
  std::ostringstream out;
  std::string line;
  int data_row = 0;
  while (std::getline(in, line)) {
    if (!line.empty() && line[0] != '#' && line.rfind("pose,", 0) != 0) {
      if (data_row == 10 || data_row == 50 || data_row == 90) {
        // pose,j1..j5,x,...: x is the 7th field.
        std::vector<std::string> f;
        std::istringstream fields(line);
        std::string v;
        while (std::getline(fields, v, ',')) f.push_back(v);
        f[6] = std::to_string(std::stod(f[6]) + 15.0);
        line.clear();
        for (size_t k = 0; k < f.size(); ++k) line += (k ? "," : "") + f[k];
      }
      ++data_row;
    }
    out << line << "\n";
  }
  const std::string bad = Dir() + "/gross.csv";
  WriteText(bad, out.str());
  const std::string cal = Dir() + "/gross_cal.yaml";
  const RunResult r = RunKincal("calibrate --robot " + Robot() + " --obs " +
                                bad + " --holdout 0 --out " + cal + " --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  std::vector<std::string> poses;
  for (const auto& o : j["outliers"]) {
    poses.push_back(o["pose"].get<std::string>());
    EXPECT_TRUE(o["excluded"].get<bool>());
    EXPECT_GT(o["sigmas"].get<double>(), 10.0);
  }
  EXPECT_THAT(poses, ::testing::UnorderedElementsAre("10", "50", "90"));
  EXPECT_LT(j["train_rms_mm"].get<double>(), 0.07);
  EXPECT_EQ(j["train"]["n"].get<int>(), 117);
  const RunResult text =
      RunKincal("calibrate --robot " + Robot() + " --obs " + bad);
  EXPECT_THAT(text.out, HasSubstr("3 row(s) beyond 10 robust sigmas"));
  EXPECT_THAT(text.out, HasSubstr("left out"));
  const RunResult ev =
      RunKincal("evaluate --robot " + cal + " --obs " + bad + " --json");
  ASSERT_EQ(ev.exit_code, 0) << ev.err;
  const auto e = nlohmann::json::parse(ev.out);
  EXPECT_EQ(e["n"].get<int>(), 120);
  EXPECT_EQ(e["outliers"].size(), 3u);
  EXPECT_EQ(e["without_outliers"]["n"].get<int>(), 117);
  const RunResult keep =
      RunKincal("calibrate --robot " + Robot() + " --obs " + bad +
                " --holdout 0 --outlier-sigma 0 --json");
  const auto k = nlohmann::json::parse(keep.out);
  EXPECT_TRUE(k["outliers"].empty());
  EXPECT_GT(k["train_rms_mm"].get<double>(), 1.0);
}

// Subcommand names listed under "Subcommands:" in a --help text.
std::vector<std::string> SubcommandsOf(const std::string& help) {
  std::vector<std::string> names;
  const size_t at = help.find("Subcommands:");
  if (at == std::string::npos) return names;
  std::istringstream in(help.substr(at));
  std::string line;
  std::getline(in, line);
  while (std::getline(in, line)) {
    if (line.size() < 3 || line[0] != ' ' || line[2] == ' ') continue;
    std::istringstream words(line);
    std::string name;
    words >> name;
    names.push_back(name);
  }
  return names;
}

// Every command a user runs (the leaves of the command tree) teaches in its
// --help: a worked example and the units.
TEST(CliHelp, EveryCommandHasAnExampleAndUnits) {
  std::vector<std::string> todo = {""}, leaves;
  while (!todo.empty()) {
    const std::string cmd = todo.back();
    todo.pop_back();
    const RunResult r = RunKincal(cmd + " --help");
    ASSERT_EQ(r.exit_code, 0) << cmd << ": " << r.err;
    const std::vector<std::string> subs = SubcommandsOf(r.out);
    for (const std::string& s : subs) todo.push_back(cmd + " " + s);
    if (!subs.empty()) continue;
    leaves.push_back(cmd);
    EXPECT_THAT(r.out, HasSubstr("Example")) << "kincal" << cmd << " --help";
    EXPECT_THAT(r.out, HasSubstr("Units:")) << "kincal" << cmd << " --help";
  }
  EXPECT_GE(leaves.size(), 15u);  // the tree was walked
}

// --version names the version and the commit built from (git describe of
// the source tree: a hex hash, "-dirty" with uncommitted changes).
TEST(CliVersion, NamesTheCommit) {
  const RunResult r = RunKincal("--version");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(r.out, ::testing::MatchesRegex(
                         "kincal [0-9.]+ \\(commit ([0-9a-f]{7,}(-dirty)?|"
                         "unknown)\\)\n"));
}

TEST_F(CliTest, HumanReadableOutputWithoutJson) {
  const RunResult r =
      RunKincal("calibrate --robot " + Robot() + " --obs " + Obs());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("held-out RMS"));
  EXPECT_THAT(r.out, HasSubstr("held at nominal"));
}

// Bad input: exit 2, a message with file:line:column, and no output file.
TEST_F(CliTest, BadInputExitsTwoAndWritesNothing) {
  const std::string out = Dir() + "/never.yaml";
  std::string obs = ReadFile(Obs());
  const std::string bad_obs = Dir() + "/bad.csv";
  // Corrupt the first data row's j3 cell.
  const size_t row = obs.find('\n', obs.find("pose,")) + 1;
  size_t cell = row;
  for (int k = 0; k < 3; ++k) cell = obs.find(',', cell) + 1;
  obs.replace(cell, obs.find(',', cell) - cell, "nan");
  WriteText(bad_obs, obs);
  RunResult r = RunKincal("calibrate --robot " + Robot() + " --obs " + bad_obs +
                          " --out " + out + " --json");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.err, HasSubstr(bad_obs + ":"));
  EXPECT_THAT(r.err, HasSubstr("column 'j3'"));
  EXPECT_TRUE(r.out.empty());
  EXPECT_FALSE(Exists(out));

  r = RunKincal("calibrate --robot " + Dir() + "/missing.yaml --obs " + Obs() +
                " --out " + out);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.err, HasSubstr("missing.yaml: cannot open"));
  EXPECT_FALSE(Exists(out));

  WriteText(Dir() + "/bad_robot.yaml", "kincal_robot: 1\njoints: 3\n");
  r = RunKincal("calibrate --robot " + Dir() + "/bad_robot.yaml --obs " +
                Obs() + " --out " + out);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.err, HasSubstr("bad_robot.yaml:2:9: joints: expected a list"));

  r = RunKincal("calibrate --robot " + Robot() + " --obs " + Obs() +
                " --no-such-option");
  EXPECT_EQ(r.exit_code, 2);

  r = RunKincal("evaluate --robot " + Robot() + " --obs " + bad_obs +
                " --json");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_TRUE(r.out.empty());
  EXPECT_FALSE(Exists(out));
}

// Data that determine no robot parameter are bad input.
TEST_F(CliTest, DataThatDetermineNothingExitTwo) {
  const std::string one = Dir() + "/one_pose.csv";
  WriteText(one,
            "pose,j1,j2,j3,j4,j5,x,y,z\n"
            "0,10,20,30,40,50,100,200,300\n");
  RunResult r = RunKincal("calibrate --robot " + Robot() + " --obs " + one);
  EXPECT_EQ(r.exit_code, 2);
  const std::string same = Dir() + "/same_pose.csv";
  WriteText(same,
            "pose,j1,j2,j3,j4,j5,x,y,z\n"
            "0,10,20,30,40,50,100,200,300\n"
            "1,10,20,30,40,50,100.1,200,300\n"
            "2,10,20,30,40,50,100,200.1,300\n");
  r = RunKincal("calibrate --robot " + Robot() + " --obs " + same);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.err, HasSubstr("same joint readings"));
  const std::string few = Dir() + "/few.csv";
  std::string obs = ReadFile(Obs());
  size_t pos = obs.find("pose,");
  for (int k = 0; k < 5; ++k) pos = obs.find('\n', pos) + 1;
  WriteText(few, obs.substr(0, pos));
  r = RunKincal("calibrate --robot " + Robot() + " --obs " + few + " --json");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.err, HasSubstr("too few poses"));
}

// Issue 21 item 4: poses whose wrist moved over 24 deg only (simulated with
// the wrist's limits narrowed) leave a robot parameter undetermined;
// calibrate (against the robot's full limits) warns, naming the joints'
// seen travel and pointing to the bundle and to plan --rig. Poses over the
// limits give no such warning.
TEST_F(CliTest, CalibrateWarnsWhenThePosesLeaveTheRobotUndetermined) {
  std::string yaml = ReadFile(SourceDir() + "/data/robots/bh7.yaml");
  for (const std::string from : {"limits: [-180, 180]", "limits: [-90, 90]"}) {
    const size_t at = yaml.find(from);
    ASSERT_NE(at, std::string::npos) << from;
    yaml.replace(at, from.size(), "limits: [-31, -7]");
  }
  WriteText(Dir() + "/narrow.yaml", yaml);
  RunResult r = RunKincal("simulate --robot " + Dir() + "/narrow.yaml --out " +
                          Dir() + "/narrow --poses 120 --noise 0.03 --seed 4");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  r = RunKincal("calibrate --robot " + Robot() + " --obs " + Dir() +
                "/narrow/observations.csv --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  ASSERT_TRUE(j.contains("warnings"));
  bool found = false;
  for (const auto& w : j["warnings"]) {
    if (w["code"] != "poses_leave_robot_undetermined") continue;
    found = true;
    const std::string m = w["message"];
    EXPECT_THAT(m, HasSubstr("j4 2"));  // seen travel 2x deg
    EXPECT_THAT(m, HasSubstr("(small)"));
    EXPECT_THAT(m, HasSubstr("kincal bundle"));
    EXPECT_THAT(m, HasSubstr("kincal plan --rig"));
  }
  EXPECT_TRUE(found) << r.out;
  EXPECT_THAT(r.err, HasSubstr("poses_leave_robot_undetermined"));
  r = RunKincal("calibrate --robot " + Robot() + " --obs " + Obs() + " --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(r.out, ::testing::Not(HasSubstr("poses_leave_robot")));
}

TEST_F(CliTest, FailedRunKeepsExistingOutput) {
  const std::string out = Dir() + "/keep.yaml";
  WriteText(out, "previous\n");
  const RunResult r = RunKincal("calibrate --robot " + Robot() +
                                " --obs /nonexistent.csv --out " + out);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(ReadFile(out), "previous\n");
}

// Spec v3 `series`: the session twice, the second copy in a measuring frame
// turned 30 deg about z and moved 500 mm. evaluate registers one frame per
// series (each series' figures equal the single copy's), one frame for the
// unlabelled rows is far off; calibrate and diagnose model fit one frame per
// series and refuse the unlabelled rows (exit 2, no output).
TEST_F(CliTest, SeriesOneFrameEachInEvaluateCalibrateAndDiagnose) {
  const std::vector<std::string> joints = {"j1", "j2", "j3", "j4", "j5"};
  const Observations one = ReadObservationsCsv(Obs(), joints);
  Observations both = one;
  const Eigen::Matrix3d turn =
      Eigen::AngleAxisd(30.0 * M_PI / 180.0, Eigen::Vector3d::UnitZ())
          .toRotationMatrix();
  for (Observation& o : both.rows) o.series = "A";
  for (Observation o : one.rows) {
    o.pose = "b" + o.pose;
    o.series = "B";
    o.p_in_meas = turn * o.p_in_meas + Eigen::Vector3d(500, 0, 0);
    both.rows.push_back(o);
  }
  const std::string labelled = Dir() + "/series.csv";
  WriteText(labelled, FormatObservationsCsv(both));
  Observations unlabelled = both;
  for (Observation& o : unlabelled.rows) o.series.clear();
  const std::string plain = Dir() + "/series_unlabelled.csv";
  WriteText(plain, FormatObservationsCsv(unlabelled));

  RunResult r =
      RunKincal("evaluate --robot " + Robot() + " --obs " + Obs() + " --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const double single_rms = nlohmann::json::parse(r.out)["rms_mm"];
  EXPECT_FALSE(nlohmann::json::parse(r.out).contains("series"));
  r = RunKincal("evaluate --robot " + Robot() + " --obs " + labelled +
                " --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["n"], 2 * static_cast<int>(one.rows.size()));
  ASSERT_EQ(j["series"].size(), 2u);
  for (const auto& s : j["series"]) {
    EXPECT_EQ(s["n"], static_cast<int>(one.rows.size()));
    EXPECT_NEAR(s["rms_mm"].get<double>(), single_rms, 1e-6);
    for (const char* f : {"name", "mean_mm", "max_mm", "std_mm", "frame"})
      EXPECT_TRUE(s.contains(f)) << f;
  }
  EXPECT_EQ(j["series"][0]["name"], "A");
  EXPECT_EQ(j["series"][1]["name"], "B");
  // meas_B_from_base = turn * meas_A_from_base.
  const auto rotation = [&](int s) {
    const auto& v = j["series"][s]["frame"]["rotation_deg"];
    const Eigen::Vector3d w(v[0].get<double>(), v[1].get<double>(),
                            v[2].get<double>());
    return Eigen::AngleAxisd(w.norm() * M_PI / 180.0, w.normalized())
        .toRotationMatrix();
  };
  const Eigen::AngleAxisd relative(rotation(1) * rotation(0).transpose());
  EXPECT_NEAR(relative.angle() * 180.0 / M_PI, 30.0, 0.05);
  EXPECT_NEAR(relative.axis().z(), 1.0, 1e-3);
  EXPECT_NEAR(j["rms_mm"].get<double>(), single_rms, 1e-6);
  r = RunKincal("evaluate --robot " + Robot() + " --obs " + plain + " --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_GT(nlohmann::json::parse(r.out)["rms_mm"].get<double>(), 50.0);

  // calibrate and diagnose model fit one frame per series, the robot
  // shared: B's frame is fitted 30 deg from A's.
  const std::string out = Dir() + "/series_cal.yaml";
  r = RunKincal("calibrate --robot " + Robot() + " --obs " + labelled +
                " --out " + out + " --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(Exists(out));
  EXPECT_THAT(r.out, HasSubstr("\"frame.B.rz\""));
  std::remove(out.c_str());
  r = RunKincal("diagnose model --robot " + Robot() + " --obs " + labelled +
                " --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json d = nlohmann::json::parse(r.out);
  ASSERT_EQ(d["series"]["per_series"].size(), 2u);
  EXPECT_EQ(d["series"]["per_series"][1]["name"], "B");
  // The same rows without labels: the jump between the copies is found.
  r = RunKincal("calibrate --robot " + Robot() + " --obs " + plain + " --out " +
                out + " --json");
  EXPECT_EQ(r.exit_code, 2);
  // Provenance line, header, 120 rows of the first copy: line 123.
  EXPECT_THAT(r.err, HasSubstr("series_unlabelled.csv:123: the rows before "
                               "line 123 and from it on (pose 'b0')"));
  EXPECT_THAT(r.err, HasSubstr("add a `series` column"));
  EXPECT_FALSE(Exists(out));
}

}  // namespace
}  // namespace kincal::testing
