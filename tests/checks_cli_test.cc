// End to end: inputs that parse but cannot be right are refused (exit 2,
// nothing written) and inputs that look wrong are warned about (stderr, and
// `warnings` in the JSON): observations in radians or metres, a reading
// outside a joint's limits, a joint log whose estimated clock offset agrees
// with the images only by chance, a camera solve that did not converge.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <random>
#include <sstream>

#include "data/atomic_file.h"
#include "tests/testing/joint_log_session.h"
#include "tests/testing/paths.h"
#include "tests/testing/run.h"

namespace kincal {
namespace {

using testing::RunKincal;
using testing::RunResult;

// --- observations.csv against the robot file --------------------------------

const std::string kDemo = testing::SourceDir() + "/data/sessions/bh7_demo";

// The demo's observations with each data row passed through `edit` (row
// index from 0, cells split at commas) into DIR/NAME; returns the path.
std::string EditedDemo(
    const std::string& dir, const std::string& name,
    const std::function<void(int, std::vector<std::string>*)>& edit) {
  std::istringstream in(ReadFile(kDemo + "/observations.csv"));
  std::ostringstream out;
  std::string line;
  int row = -1;
  while (std::getline(in, line)) {
    if (row < 0) {
      out << line << "\n";
      if (line.rfind("pose,", 0) == 0) row = 0;
      continue;
    }
    std::vector<std::string> cells;
    std::stringstream ss(line);
    std::string cell;
    while (std::getline(ss, cell, ',')) cells.push_back(cell);
    edit(row++, &cells);
    for (size_t k = 0; k < cells.size(); ++k) out << (k ? "," : "") << cells[k];
    out << "\n";
  }
  const std::string path = dir + "/" + name;
  WriteFileAtomic(path, out.str());
  return path;
}

std::string Scaled(double v, double factor) {
  std::ostringstream os;
  os.precision(17);
  os << v * factor;
  return os.str();
}

// Columns of the demo: pose,j1 (prismatic),j2..j5 (revolute),x,y,z,t.
void ToRadians(int, std::vector<std::string>* c) {
  for (int k = 2; k <= 5; ++k)
    (*c)[k] = Scaled(std::stod((*c)[k]), M_PI / 180.0);
}

void ToMetres(int, std::vector<std::string>* c) {
  for (int k = 6; k <= 8; ++k) (*c)[k] = Scaled(std::stod((*c)[k]), 1e-3);
}

std::string Robot() { return kDemo + "/robot.yaml"; }

TEST(ChecksCli, DemoDataRaisesNoWarning) {
  const RunResult r = RunKincal("evaluate --robot " + Robot() + " --obs " +
                                kDemo + "/observations.csv --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_FALSE(nlohmann::json::parse(r.out).contains("warnings"));
  EXPECT_EQ(r.err.find("warning"), std::string::npos) << r.err;
}

TEST(ChecksCli, RadiansAreNamedInTheJsonAndOnStderr) {
  const std::string dir = testing::MakeTempDir("checks_rad");
  const std::string obs = EditedDemo(dir, "rad.csv", ToRadians);
  const RunResult r =
      RunKincal("evaluate --robot " + Robot() + " --obs " + obs + " --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  ASSERT_TRUE(j.contains("warnings"));
  ASSERT_EQ(j["warnings"].size(), 1u);
  EXPECT_EQ(j["warnings"][0]["code"], "joint_units_radians");
  EXPECT_NE(j["warnings"][0]["message"].get<std::string>().find("radians"),
            std::string::npos);
  // calibrate fails on these data; its stderr now says why first.
  const RunResult c = RunKincal("calibrate --robot " + Robot() + " --obs " +
                                obs + " --out " + dir + "/cal.yaml");
  EXPECT_NE(c.err.find("warning [joint_units_radians]"), std::string::npos)
      << c.err;
  EXPECT_NE(c.err.find("180/pi"), std::string::npos) << c.err;
}

TEST(ChecksCli, AReadingOutsideTheLimitsIsRefusedNamingRowAndJoint) {
  const std::string dir = testing::MakeTempDir("checks_limit");
  const std::string obs =
      EditedDemo(dir, "j2.csv", [](int row, std::vector<std::string>* c) {
        if (row == 10) (*c)[2] = "500";
      });
  // Two comment lines and the header, then data rows: row 10 is line 14.
  for (const std::string command :
       {"calibrate", "evaluate", "diagnose model", "diagnose clearance"}) {
    const std::string out = dir + "/out.yaml";
    const RunResult r =
        RunKincal(command + " --robot " + Robot() + " --obs " + obs +
                  (command == "calibrate" ? " --out " + out : "") + " --json");
    EXPECT_EQ(r.exit_code, 2) << command << ": " << r.err;
    EXPECT_NE(r.err.find("j2.csv:14:"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("joint j2 reads 500 deg"), std::string::npos) << r.err;
    EXPECT_TRUE(r.out.empty()) << command;
    EXPECT_FALSE(testing::Exists(out)) << command;
  }
}

TEST(ChecksCli, PointsInMetresAreRefusedWithTheFix) {
  const std::string dir = testing::MakeTempDir("checks_m");
  const std::string obs = EditedDemo(dir, "m.csv", ToMetres);
  const std::string out = dir + "/cal.yaml";
  const RunResult r = RunKincal("calibrate --robot " + Robot() + " --obs " +
                                obs + " --out " + out + " --json");
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("metres"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("multiply x,y,z by 1000"), std::string::npos) << r.err;
  EXPECT_FALSE(testing::Exists(out));
}

// --- capture --joints: the clock offset's agreement ------------------------

using testing::JointLogSessionOptions;
using Program = testing::StopAndGo;
using Fixture = testing::JointLogSession;

Fixture MakeCapture(const std::string& tag,
                    const std::function<void(int, double*, double*)>& edit = {},
                    bool distractor = false) {
  JointLogSessionOptions options;
  options.edit = edit;
  options.distractor = distractor;
  return testing::MakeJointLogSession(tag, Program(5), Program(5), options);
}

std::string Capture(const Fixture& f, const std::string& out,
                    const std::string& extra = "") {
  return "capture --left 'folder:" + f.dir +
         "/l_*.png' --right 'folder:" + f.dir + "/r_*.png' --out " + out +
         " --joints " + f.log + " --robot " + f.robot + " " + extra;
}

TEST(ChecksCli, CaptureTextShowsTheEstimatedOffsetAndItsAgreement) {
  const Fixture f = MakeCapture("checks_cap_ok");
  const RunResult r = RunKincal(Capture(f, f.dir + "/session"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("clock offset -5002.2"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("estimated (agreement with the images"),
            std::string::npos)
      << r.out;
}

TEST(ChecksCli, AChanceLevelOffsetIsRefusedUnlessGiven) {
  // Something else moves in view most of the time: the robot's stops still
  // fix an offset, but the images' moving/still state agrees with the log's
  // only about as often as chance.
  const Fixture f = MakeCapture("checks_cap_weak", {}, true);
  const std::string out = f.dir + "/session";
  const RunResult r = RunKincal(Capture(f, out, "--json"));
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("estimated clock offset"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("% of the frames"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("--joints-offset"), std::string::npos) << r.err;
  EXPECT_TRUE(r.out.empty() || r.out.find("\"joints\"") == std::string::npos);
  EXPECT_FALSE(testing::Exists(out + "/frames.csv") &&
               ReadFile(out + "/frames.csv").find("j1") != std::string::npos);
  // With the offset given the user takes responsibility: merged.
  const std::string out2 = f.dir + "/session2";
  const RunResult g =
      RunKincal(Capture(f, out2, "--joints-offset -5002.266 --json"));
  ASSERT_EQ(g.exit_code, 0) << g.err;
  const auto j = nlohmann::json::parse(g.out);
  EXPECT_FALSE(j["joints"]["offset_estimated"].get<bool>());
  EXPECT_NEAR(j["joints"]["offset_s"].get<double>(), -5002.266, 1e-9);
}

TEST(ChecksCli, ALogReadingOutsideTheLimitsIsRefusedBeforeRecording) {
  // Line 2 + 300 of joints.csv reads j2 = 500 deg (limits [-200, 90]).
  const Fixture f =
      MakeCapture("checks_cap_limit", [](int i, double*, double* j2) {
        if (i == 300) *j2 = 500;
      });
  const std::string out = f.dir + "/session";
  const RunResult r = RunKincal(Capture(f, out, "--json"));
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("joints.csv:302:"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("joint j2 reads 500 deg"), std::string::npos) << r.err;
  EXPECT_FALSE(testing::Exists(out));
}

// --- camcal: a solve that did not converge ----------------------------------

TEST(ChecksCli, CamcalThatDoesNotConvergeFailsAndWritesNothing) {
  KINCAL_REQUIRE_SHARED_DATA("opencv-stereo-left-right");
  const std::string d = testing::SharedDataDir() + "/opencv-stereo-left-right";
  const std::string out = testing::MakeTempDir("checks_camcal") + "/rig.yaml";
  const RunResult r =
      RunKincal("camcal --left '" + d + "/left*.jpg' --right '" + d +
                "/right*.jpg' --target chessboard:9x6:1 "
                "--distortion 8 --regularize 0 --regularize-lens 0 --out " +
                out + " --json");
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find("did not converge"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("--distortion 5"), std::string::npos) << r.err;
  EXPECT_TRUE(r.out.empty());
  EXPECT_FALSE(testing::Exists(out));
}

}  // namespace
}  // namespace kincal
