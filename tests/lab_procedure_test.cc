// docs/LAB.md's rehearsal as a test: rendered images of a simulated BH-7
// session replayed as the cameras, a fake robot controller (loopback TCP)
// visiting the same poses with step and shoot, then track with the
// session's observations.csv and calibrate. The tracked tips must land on
// the simulated ones pose by pose: proof that every recorded frame carries
// the readings of the pose it shows.

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <thread>

#include "data/atomic_file.h"
#include "data/csv.h"
#include "tests/testing/loopback.h"
#include "tests/testing/paths.h"
#include "tests/testing/run.h"

namespace kincal {
namespace {

using testing::RunKincal;
using testing::RunResult;

struct Row {
  std::vector<std::string> joints;
  double x = NAN, y = NAN, z = NAN;
};

// pose -> row of an observations.csv (joint cells as text).
std::map<std::string, Row> ReadObs(const std::string& path, int joints) {
  std::map<std::string, Row> rows;
  const auto lines = TokenizeCsv(ReadFile(path), path);
  const auto& h = lines.at(0).fields;
  int x = -1;
  for (size_t c = 0; c < h.size(); ++c) {
    if (h[c].text == "x") x = static_cast<int>(c);
  }
  for (size_t r = 1; r < lines.size(); ++r) {
    const auto& f = lines[r].fields;
    Row row;
    for (int j = 1; j <= joints; ++j) row.joints.push_back(f[j].text);
    if (x >= 0 && !f[x].text.empty()) {
      row.x = std::stod(f[x].text);
      row.y = std::stod(f[x + 1].text);
      row.z = std::stod(f[x + 2].text);
    }
    rows[f[0].text] = row;
  }
  return rows;
}

// Visits the rows in file order: HELLO, SETTLED <pose> <q...> / DONE, BYE.
void FakeController(int port, const std::string& obs, int* done) {
  const auto lines = TokenizeCsv(ReadFile(obs), obs);
  const int fd = testing::ConnectLoopback(port, 300);
  if (fd < 0) return;
  auto say = [&](const std::string& s) { testing::SendLine(fd, s); };
  auto hear = [&] {
    std::string l;
    testing::ReceiveLine(fd, &l);
    return l;
  };
  say("HELLO BH-7 j1 j2 j3 j4 j5");
  if (hear() != "OK kincal 1") return;
  for (size_t r = 1; r < lines.size(); ++r) {
    std::string msg = "SETTLED " + lines[r].fields[0].text;
    for (int j = 1; j <= 5; ++j) msg += " " + lines[r].fields[j].text;
    say(msg);
    if (hear().rfind("DONE", 0) != 0) return;
    ++*done;
  }
  say("BYE");
  ::close(fd);
}

TEST(LabProcedure, SimulateFakeRobotCaptureTrackCalibrate) {
  const std::string w = testing::MakeTempDir("lab");
  const std::string robot = testing::SourceDir() + "/data/robots/bh7.yaml";
  RunResult r = RunKincal("simulate --robot " + robot +
                          " --poses 40 --render --render-width 640 "
                          "--render-height 512 --out " +
                          w + "/sim --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;

  const int port = testing::FreeLoopbackPort();
  int done = 0;
  std::thread controller(
      [&] { FakeController(port, w + "/sim/observations.csv", &done); });
  r = RunKincal("capture --left 'folder:" + w +
                "/sim/session/left/*.png' --right 'folder:" + w +
                "/sim/session/right/*.png' --robot " + robot +
                " --robot-listen 127.0.0.1:" + std::to_string(port) +
                " --shots 1 --out " + w + "/session --json");
  controller.join();
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(done, 40);
  EXPECT_EQ(nlohmann::json::parse(r.out)["frames"], 40);

  r = RunKincal("track --rig " + w + "/sim/rig.yaml --target " + w +
                "/sim/target.yaml --left '" + w +
                "/session/left/*.png' --right '" + w +
                "/session/right/*.png' --obs " + w +
                "/session/observations.csv --robot " + robot + " --out " + w +
                "/points.csv --out-obs " + w + "/obs.csv --quiet --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const int found = nlohmann::json::parse(r.out)["found"];
  EXPECT_GE(found, 10);

  // Pose by pose: the readings are the simulated ones and the tracked tip
  // is the simulated measured tip (same rig frame).
  const auto sim = ReadObs(w + "/sim/observations.csv", 5);
  const auto got = ReadObs(w + "/obs.csv", 5);
  int compared = 0;
  std::vector<double> distances;
  for (const auto& [pose, row] : got) {
    ASSERT_TRUE(sim.count(pose)) << pose;
    const Row& truth = sim.at(pose);
    for (int j = 0; j < 5; ++j) {
      EXPECT_NEAR(std::stod(row.joints[j]), std::stod(truth.joints[j]), 1e-6);
    }
    if (std::isnan(row.x)) continue;
    const double d =
        std::hypot(row.x - truth.x, row.y - truth.y, row.z - truth.z);
    // Another pose's tip would be ~100 mm away; tracking at 640x512 with a
    // few oblique tags is good to a few mm at worst.
    EXPECT_LT(d, 10.0) << "pose " << pose;
    distances.push_back(d);
    ++compared;
  }
  EXPECT_GE(compared, 10);
  std::sort(distances.begin(), distances.end());
  EXPECT_LT(distances[distances.size() / 2], 0.5);  // median

  r = RunKincal("calibrate --robot " + robot + " --obs " + w +
                "/obs.csv --out " + w + "/cal.yaml --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(nlohmann::json::parse(r.out)["heldout_rms_mm"].is_number());
}

// The code block of docs/LAB.md whose first line starts with `prefix`.
std::string LabBlock(const std::string& prefix) {
  const std::string lab = ReadFile(testing::SourceDir() + "/docs/LAB.md");
  size_t at = 0;
  while ((at = lab.find("```\n", at)) != std::string::npos) {
    const size_t begin = at + 4;
    const size_t end = lab.find("```", begin);
    if (end == std::string::npos) break;
    if (lab.compare(begin, prefix.size(), prefix) == 0) {
      return lab.substr(begin, end - begin);
    }
    at = end + 3;
  }
  return "";
}

// LAB.md's robot-program line, run as written on plans of a 5-joint
// (BH-7) and a 7-joint (Panda URDF) robot: one list, every joint of every
// pose, no empty element.
TEST(LabProcedureTest, RobotProgramLineKeepsEveryJoint) {
  const std::string awk = LabBlock("awk ");
  ASSERT_FALSE(awk.empty()) << "docs/LAB.md has no ``` block starting 'awk '";
  const std::string dir = testing::MakeTempDir("lab_awk");
  const std::string panda = testing::SharedDataDir() + "/mukca/urdf/panda.urdf";
  struct Case {
    std::string robot_args;
    int joints;
  };
  std::vector<Case> cases = {
      {"--robot " + testing::SourceDir() + "/data/robots/bh7.yaml", 5}};
  if (testing::Exists(panda))
    cases.push_back({"--robot " + panda + " --tip panda_hand", 7});
  for (const Case& c : cases) {
    const RunResult plan = RunKincal("plan " + c.robot_args + " --n 20 --out " +
                                     dir + "/poses.csv");
    ASSERT_EQ(plan.exit_code, 0) << plan.err;
    const RunResult list =
        testing::RunShell("cd " + dir + " && " + awk.substr(0, awk.find('\n')));
    ASSERT_EQ(list.exit_code, 0) << list.err;
    const std::string& out = list.out;
    ASSERT_GE(out.size(), 4u);
    EXPECT_EQ(out.substr(0, 2), "[[");
    EXPECT_EQ(out.substr(out.size() - 3), "]]\n");
    EXPECT_EQ(out.find(",]"), std::string::npos) << out;
    EXPECT_EQ(out.find(", ,"), std::string::npos) << out;
    int poses = 0, commas = 0;
    for (char ch : out) {
      poses += ch == '[';
      commas += ch == ',';
    }
    EXPECT_EQ(poses - 1, 20) << out;
    // Inside each pose joints - 1 commas, between poses 19.
    EXPECT_EQ(commas, 20 * (c.joints - 1) + 19) << out;
  }
}

// LAB.md's camcal line gives the board in millimetres (camcal's unit): a
// tag of at least 5 mm, not a size in metres.
TEST(LabProcedureTest, CamcalBoardIsInMillimetres) {
  const std::string lab = ReadFile(testing::SourceDir() + "/docs/LAB.md");
  size_t at = 0;
  int boards = 0;
  while ((at = lab.find("--target aprilgrid:", at)) != std::string::npos) {
    const size_t begin = at + 9;
    const std::string spec =
        lab.substr(begin, lab.find_first_of(" \n", begin) - begin);
    // aprilgrid:COLSxROWS:TAG_SIZE:SPACING_RATIO
    const size_t c1 = spec.find(':', 10);
    const size_t c2 = spec.find(':', c1 + 1);
    ASSERT_NE(c2, std::string::npos) << spec;
    EXPECT_GE(std::stod(spec.substr(c1 + 1, c2 - c1 - 1)), 5.0)
        << spec << ": tag size in metres? camcal reads millimetres";
    ++boards;
    at = begin;
  }
  EXPECT_GE(boards, 1);
}

// The code blocks of docs/LAB.md's section `heading` (a "## " line), in
// order.
std::vector<std::string> LabBlocksIn(const std::string& heading) {
  const std::string lab = ReadFile(testing::SourceDir() + "/docs/LAB.md");
  std::vector<std::string> blocks;
  const size_t start = lab.find("\n" + heading + "\n");
  if (start == std::string::npos) return blocks;
  const size_t stop = lab.find("\n## ", start + heading.size() + 1);
  size_t at = start;
  while ((at = lab.find("```\n", at)) != std::string::npos && at < stop) {
    const size_t begin = at + 4;
    const size_t end = lab.find("```", begin);
    if (end == std::string::npos || end > stop) break;
    blocks.push_back(lab.substr(begin, end - begin));
    at = end + 3;
  }
  return blocks;
}

// The rehearsal of docs/LAB.md exactly as written: every command block of
// its section run by the shell in a fresh folder (the project's data/ and
// scripts/ beside it, build/bin on the PATH), each must exit 0 and the
// files the procedure goes on with must be there.
TEST(LabProcedureTest, RehearsalBlocksRunAsWritten) {
  const std::vector<std::string> blocks =
      LabBlocksIn("## Rehearsal without hardware (run here)");
  ASSERT_GE(blocks.size(), 2u) << "docs/LAB.md: rehearsal blocks missing";
  const std::string dir = testing::MakeTempDir("lab_doc");
  const std::string src = testing::SourceDir();
  const std::string bin =
      testing::KincalBinary().substr(0, testing::KincalBinary().rfind('/'));
  ASSERT_EQ(
      testing::RunShell("ln -s " + src + "/data " + dir + "/data && ln -s " +
                        src + "/scripts " + dir + "/scripts")
          .exit_code,
      0);
  for (const std::string& block : blocks) {
    std::ofstream(dir + "/block.sh") << block;
    const RunResult r = testing::RunShell("cd " + dir + " && PATH=" + bin +
                                          ":$PATH sh -e block.sh >block.out");
    EXPECT_EQ(r.exit_code, 0) << block << "\n" << r.err;
  }
  for (const char* file :
       {"sim/rig.yaml", "session/observations.csv", "points.csv", "obs.csv",
        "cal.yaml", "poses.csv", "handshake/frames.csv"}) {
    EXPECT_TRUE(testing::Exists(dir + "/" + file)) << file;
  }
}

}  // namespace
}  // namespace kincal
