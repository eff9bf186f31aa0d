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
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <random>
#include <regex>
#include <sstream>
#include <thread>

#include "camcal/rig.h"
#include "data/atomic_file.h"
#include "data/csv.h"
#include "data/urdf.h"
#include "synth/recorded_session.h"
#include "synth/render.h"
#include "tests/testing/iso9283_cycles.h"
#include "tests/testing/joint_log_session.h"
#include "tests/testing/loopback.h"
#include "tests/testing/paths.h"
#include "tests/testing/run.h"
#include "tests/testing/tilt.h"

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

// ---- docs/LAB.md, every block -------------------------------------------
//
// Every ``` block of docs/LAB.md is preceded by a marker line
// `<!-- lab-test: WORD ... -->` naming how it runs here; the command text
// itself is what the lab types. The words:
//   run             as written, in the lab folder
//   cameras         each capture's v4l2 cameras become folder cameras of
//                   rendered images, chosen by the capture's --out: grid
//                   (AprilGrid views), tool and pivot (the tool hand-held and
//                   on a divot), run1 (the simulated robot session), run2
//                   (the joint-log stand-in); run3 (streaming, which needs
//                   live cameras) fake live cameras
//   tool-tags       the rendered tool's tags are those of the simulated
//                   session (scaled to its rig distance): its edge replaces
//                   the block's `--size 25`
//   robot-step      scripts/fake_robot.py visits the simulated poses
//                   (step and shoot) on a free loopback port in place of
//                   0.0.0.0:30010
//   robot-stream    a fake controller streams J lines, then BYE
//   joint-log       runs in a folder whose robot.yaml and
//                   controller_log.csv are a two-joint robot's log whose
//                   stops the images show (tests/testing/joint_log_session.h)
//   file NAME       the block is a file: written as NAME in the lab folder
//                   (later blocks read it)
//   robot-program   a controller program (no controller here): it must
//                   speak the protocol (HELLO, SETTLED, BYE) and have a dry
//                   run switch
//   ur10            runs in a folder of a UR10 (the controller formats take
//                   revolute arms; the BH-7 has a prismatic joint and no
//                   table under it): robot.yaml the UR10, run1/obs.csv a
//                   simulated session of it (60 poses, 0.02 mm noise),
//                   poses.csv its plan, cell.yaml the lab folder's
//   job-program     program.csv is the folder's poses.csv
//   iso-measured    iso_measured.csv is iso.csv with the nominal tip of
//                   every row plus 0.02 mm noise
//   rehearsal       as written, in a fresh folder of its own
// A block without a marker, or with a word not listed, fails the test.

struct DocBlock {
  int line = 0;  // of the opening fence, 1-based
  bool has_marker = false;
  std::vector<std::string> words;
  std::string text;
};

std::vector<std::string> Lines(const std::string& text) {
  std::vector<std::string> lines;
  std::stringstream in(text);
  std::string line;
  while (std::getline(in, line)) lines.push_back(line);
  return lines;
}

std::vector<DocBlock> LabDocBlocks() {
  const std::vector<std::string> lines =
      Lines(ReadFile(testing::SourceDir() + "/docs/LAB.md"));
  const std::regex marker(R"(^<!-- lab-test: (.*) -->$)");
  std::vector<DocBlock> blocks;
  for (size_t i = 0; i < lines.size(); ++i) {
    if (lines[i].rfind("```", 0) != 0) continue;
    DocBlock block;
    block.line = static_cast<int>(i + 1);
    std::smatch m;
    if (i > 0 && std::regex_match(lines[i - 1], m, marker)) {
      block.has_marker = true;
      std::stringstream words(m[1].str());
      std::string w;
      while (words >> w) block.words.push_back(w);
    }
    size_t j = i + 1;
    for (; j < lines.size() && lines[j].rfind("```", 0) != 0; ++j) {
      block.text += lines[j] + "\n";
    }
    blocks.push_back(block);
    i = j;
  }
  return blocks;
}

// Shell lines with their `\` continuations joined.
std::string JoinContinuations(const std::string& text) {
  return std::regex_replace(text, std::regex("\\\\\n"), " ");
}

namespace fs = std::filesystem;

std::string FormatShortest(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

Rigid3 BoardPose(const AprilGrid& grid, double tilt_x, double tilt_y,
                 double roll, const Eigen::Vector3d& centre_in_rig) {
  const double deg = M_PI / 180;
  const double pitch = grid.tag_size_mm * (1 + grid.spacing_ratio);
  const Eigen::Vector3d centre_in_board(
      (grid.cols * pitch - pitch + grid.tag_size_mm) / 2,
      (grid.rows * pitch - pitch + grid.tag_size_mm) / 2, 0);
  Rigid3 pose;
  pose.R = (Eigen::AngleAxisd(roll * deg, Eigen::Vector3d::UnitZ()) *
            Eigen::AngleAxisd(tilt_y * deg, Eigen::Vector3d::UnitY()) *
            Eigen::AngleAxisd(tilt_x * deg, Eigen::Vector3d::UnitX()))
               .toRotationMatrix();
  pose.t = centre_in_rig - pose.R * centre_in_board;
  return pose;
}

// The AprilGrid of LAB.md step 1 (aprilgrid:6x6:30:0.3) in 14 views filling
// both images of `rig`, as DIR/left/NNNNNN.png and DIR/right/.
void RenderGridViews(const Rig& rig, const std::string& dir) {
  const AprilGrid grid;  // 6x6 tag36h11, 30 mm, spacing 0.3
  using V = Eigen::Vector3d;
  const std::vector<Rigid3> poses = {
      BoardPose(grid, 0, 0, 0, V(38, 0, 500)),
      BoardPose(grid, 35, 0, 0, V(38, 0, 520)),
      BoardPose(grid, -35, 0, 0, V(38, 0, 520)),
      BoardPose(grid, 0, 35, 0, V(38, 0, 510)),
      BoardPose(grid, 0, -35, 0, V(38, 0, 510)),
      BoardPose(grid, 25, 25, 10, V(30, -10, 540)),
      BoardPose(grid, -25, 25, -10, V(46, 10, 540)),
      BoardPose(grid, 25, -25, 15, V(46, 10, 540)),
      BoardPose(grid, -25, -25, -15, V(30, -10, 540)),
      BoardPose(grid, 40, 10, 0, V(38, 0, 560)),
      BoardPose(grid, -10, -40, 0, V(38, 0, 560)),
      BoardPose(grid, 15, -10, 30, V(33, 5, 620)),
      BoardPose(grid, -15, 15, -30, V(43, -5, 620)),
      BoardPose(grid, 5, 5, 90, V(38, 0, 520))};
  RenderOptions options;
  options.blur_sigma_px = 0.7;
  options.noise_sigma = 1.5;
  std::mt19937_64 rng(20261125);
  const char* sides[] = {"left", "right"};
  for (size_t c = 0; c < 2; ++c) {
    fs::create_directories(dir + "/" + sides[c]);
    const ViewRenderer renderer(rig.cameras[c]);
    for (size_t v = 0; v < poses.size(); ++v) {
      char name[32];
      std::snprintf(name, sizeof name, "/%06zu.png", v);
      cv::imwrite(dir + "/" + sides[c] + name,
                  renderer.Render(grid.Planes(poses[v]), {}, options, &rng));
    }
  }
}

// LAB.md step 1b's sessions: the tool tilted in 24 views, and pivoting
// +-20 deg about its tip in 16. `target` is ExampleTarget() scaled (as
// simulate --render scales it to its rig distance): the example scene
// scaled alike gives the same images.
void RenderToolSessions(const Rig& rig, const Target& target,
                        const std::string& standin) {
  const double scale = target.tags.at(0).size_mm / 25.0;
  const auto scaled = [scale](Rigid3 pose) {
    pose.t *= scale;
    return pose;
  };
  RenderOptions o;
  o.blur_sigma_px = 0.5;
  o.noise_sigma = 1.5;
  RecordedSessionInput views, pivot;
  for (int i = 0; i < 24; ++i) {
    views.rig_from_tool.push_back(scaled(
        testing::TiltedAbout(ExampleToolPose(i), 20 * std::sin(0.9 * i),
                             25 * std::cos(0.6 * i), Eigen::Vector3d::Zero())));
  }
  for (int i = 0; i < 16; ++i) {
    const double a = 2 * M_PI * i / 16;
    pivot.rig_from_tool.push_back(scaled(
        testing::TiltedAbout(ExampleToolPose(0), 20 * std::sin(a),
                             20 * std::cos(a), target.tip_in_tool / scale)));
  }
  RenderRecordedSession(rig, target, views, o, 11, standin + "/tool");
  RenderRecordedSession(rig, target, pivot, o, 12, standin + "/pivot");
}

std::vector<std::string> SortedFiles(const std::string& dir) {
  std::vector<std::string> files;
  for (const auto& entry : fs::directory_iterator(dir)) {
    files.push_back(entry.path().string());
  }
  std::sort(files.begin(), files.end());
  return files;
}

// The stand-ins of LAB.md's hardware, made once: a simulated BH-7 session
// at 640x512 (its rig, target and images), the grid and tool images seen by
// that rig, and the joint-log session.
struct StandIns {
  std::string lab, standin, bin;
  // capture --out X: the left and right sources replacing the cameras.
  std::map<std::string, std::pair<std::string, std::string>> cameras;
  std::string joint_log_lab;  // the joint-log block's folder
  std::string tool_tag_mm;    // edge of the rendered tool's tags
  std::string ur10_lab;       // the UR10's folder
  Rig rig;
};

void LinkProjectFolders(const std::string& dir) {
  const std::string src = testing::SourceDir();
  fs::create_directories(dir);
  fs::create_directory_symlink(src + "/data", dir + "/data");
  fs::create_directory_symlink(src + "/scripts", dir + "/scripts");
}

StandIns MakeStandIns() {
  StandIns s;
  s.lab = testing::MakeTempDir("lab_all");
  s.standin = s.lab + "/standin";
  s.bin = testing::KincalBinary().substr(0, testing::KincalBinary().rfind('/'));
  LinkProjectFolders(s.lab);
  const std::string robot = testing::SourceDir() + "/data/robots/bh7.yaml";
  fs::copy_file(robot, s.lab + "/robot.yaml");
  const RunResult sim = RunKincal(
      "simulate --robot " + robot +
      " --poses 40 --render --render-width 640 --render-height 512 --out " +
      s.standin + "/sim --json");
  EXPECT_EQ(sim.exit_code, 0) << sim.err;
  s.rig = ReadRigYaml(s.standin + "/sim/rig.yaml");
  RenderGridViews(s.rig, s.standin + "/grid");
  const Target tool = ReadTargetYaml(s.standin + "/sim/target.yaml");
  RenderToolSessions(s.rig, tool, s.standin);
  s.tool_tag_mm = FormatShortest(tool.tags.at(0).size_mm);
  // Step and shoot with --shots 5: five copies of each pose's pair.
  for (const char* side : {"left", "right"}) {
    const std::string to = s.standin + "/run1/" + side;
    fs::create_directories(to);
    int n = 0;
    for (const std::string& f :
         SortedFiles(s.standin + "/sim/session/" + side)) {
      for (int k = 0; k < 5; ++k) {
        char name[32];
        std::snprintf(name, sizeof name, "/%06d.png", n++);
        fs::create_symlink(f, to + name);
      }
    }
  }
  for (const std::string out : {"grid", "tool", "pivot", "run1"}) {
    s.cameras[out] = {"folder:" + s.standin + "/" + out + "/left/*.png",
                      "folder:" + s.standin + "/" + out + "/right/*.png"};
  }
  // Streaming needs live cameras (frames on the host clock): fake ones.
  s.cameras["run3"] = {"fake:l?width=640&height=512&fps=30",
                       "fake:r?width=640&height=512&fps=30"};
  const testing::JointLogSession log = testing::MakeJointLogSession(
      "lab_joint_log", testing::StopAndGo(), testing::StopAndGo());
  s.joint_log_lab = s.lab + "/joint_log";
  fs::create_directories(s.joint_log_lab);
  fs::copy_file(log.robot, s.joint_log_lab + "/robot.yaml");
  fs::copy_file(log.log, s.joint_log_lab + "/controller_log.csv");
  s.cameras["run2"] = {"folder:" + log.dir + "/l_*.png",
                       "folder:" + log.dir + "/r_*.png"};
  s.ur10_lab = s.lab + "/ur10";
  fs::create_directories(s.ur10_lab + "/run1");
  fs::copy_file(testing::SourceDir() + "/data/robots/ur10.yaml",
                s.ur10_lab + "/robot.yaml");
  const RunResult ur10 = testing::RunShell(
      "cd " + s.ur10_lab + " && " + testing::KincalBinary() +
      " simulate --robot robot.yaml --poses 60 --noise 0.02 --out sim && " +
      "cp sim/observations.csv run1/obs.csv && " + testing::KincalBinary() +
      " plan --robot robot.yaml --n 12 --out poses.csv");
  EXPECT_EQ(ur10.exit_code, 0) << ur10.err;
  return s;
}

// The block with each capture's v4l2 cameras replaced by the stand-in
// images of its --out; adds a failure when a capture has none.
std::string WithStandInCameras(const std::string& script, const StandIns& s,
                               int line) {
  const std::regex left("'v4l2:/dev/video0[^']*'");
  const std::regex right("'v4l2:/dev/video2[^']*'");
  const std::regex out("--out ([^ ]+)");
  std::string result;
  for (const std::string& command : Lines(script)) {
    std::string c = command;
    std::smatch m;
    if (c.find("kincal capture") != std::string::npos &&
        std::regex_search(c, m, out)) {
      const auto it = s.cameras.find(m[1].str());
      if (it == s.cameras.end()) {
        ADD_FAILURE() << "docs/LAB.md:" << line << ": no stand-in images for "
                      << "capture --out " << m[1].str();
      } else {
        c = std::regex_replace(c, left, "'" + it->second.first + "'");
        c = std::regex_replace(c, right, "'" + it->second.second + "'");
      }
    }
    EXPECT_EQ(c.find("v4l2:"), std::string::npos)
        << "docs/LAB.md:" << line
        << ": a camera the stand-in cannot replace: " << c;
    result += c + "\n";
  }
  return result;
}

std::string WithLoopbackListen(const std::string& script, int port, int line) {
  const std::string lab_address = "0.0.0.0:30010";
  EXPECT_NE(script.find(lab_address), std::string::npos)
      << "docs/LAB.md:" << line << ": the robot stand-in replaces "
      << lab_address;
  return std::regex_replace(script, std::regex(lab_address),
                            "127.0.0.1:" + std::to_string(port));
}

// A controller streaming J lines (BH-7's five joints, 100 Hz for 0.5 s on
// its own clock), then BYE.
void StreamingController(int port) {
  const int fd = testing::ConnectLoopback(port, 300);
  if (fd < 0) return;
  testing::SendLine(fd, "HELLO BH-7 j1 j2 j3 j4 j5");
  std::string reply;
  testing::ReceiveLine(fd, &reply);
  for (int k = 0; k < 50 && reply == "OK kincal 1"; ++k) {
    char line[160];
    std::snprintf(line, sizeof line, "J %.3f %.3f 10 -20 30 5", 1000 + 0.01 * k,
                  0.2 * k);
    if (!testing::SendLine(fd, line)) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  testing::SendLine(fd, "BYE");
  ::close(fd);
}

// iso_measured.csv: iso.csv with the nominal tip (robot.yaml) of every row
// plus 0.02 mm of Gaussian noise per axis.
void WriteIsoMeasured(const std::string& lab) {
  const Robot robot = ReadRobot(lab + "/robot.yaml");
  const std::string path = lab + "/iso.csv";
  const auto rows = TokenizeCsv(ReadFile(path), path);
  ASSERT_FALSE(rows.empty());
  std::vector<int> joint_columns;
  std::string out;
  for (const std::string& name : robot.JointNames()) {
    for (size_t c = 0; c < rows[0].fields.size(); ++c) {
      if (rows[0].fields[c].text == name) joint_columns.push_back(int(c));
    }
  }
  ASSERT_EQ(joint_columns.size(), robot.joints.size());
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0, 0.02);
  for (size_t r = 0; r < rows.size(); ++r) {
    std::string line;
    for (const auto& f : rows[r].fields) line += f.text + ",";
    if (r == 0) {
      line += "x,y,z";
    } else {
      std::vector<double> q;
      for (int c : joint_columns)
        q.push_back(std::stod(rows[r].fields[c].text));
      const Eigen::Vector3d tip = testing::IsoNominalTip(robot, q, 0, 0.0);
      char xyz[96];
      std::snprintf(xyz, sizeof xyz, "%.4f,%.4f,%.4f", tip.x() + noise(rng),
                    tip.y() + noise(rng), tip.z() + noise(rng));
      line += xyz;
    }
    out += line + "\n";
  }
  WriteFileAtomic(lab + "/iso_measured.csv", out);
}

void CheckRobotProgram(const DocBlock& block) {
  for (const char* word : {"HELLO", "SETTLED", "BYE"}) {
    EXPECT_NE(block.text.find(word), std::string::npos)
        << "docs/LAB.md:" << block.line << ": robot program without " << word;
  }
  EXPECT_TRUE(block.text.find("dry_run") != std::string::npos ||
              block.text.find("DRY_RUN") != std::string::npos)
      << "docs/LAB.md:" << block.line << ": robot program without a dry run";
}

RunResult RunScript(const std::string& dir, const std::string& bin,
                    const std::string& script, int line) {
  const std::string name = "block_" + std::to_string(line);
  std::ofstream(dir + "/" + name + ".sh") << script;
  return testing::RunShell("cd " + dir + " && PATH=" + bin + ":$PATH sh -e " +
                           name + ".sh >" + name + ".out");
}

// Runs one block by its marker; false when a word has no stand-in.
bool RunDocBlock(const DocBlock& block, const StandIns& s) {
  std::string script = JoinContinuations(block.text);
  std::string dir = s.lab;
  bool run = true, stream = false;
  int port = 0;
  for (size_t i = 0; i < block.words.size(); ++i) {
    const std::string& w = block.words[i];
    if (w == "run") {
    } else if (w == "cameras") {
      script = WithStandInCameras(script, s, block.line);
    } else if (w == "tool-tags") {
      EXPECT_NE(script.find("--size 25 "), std::string::npos)
          << "docs/LAB.md:" << block.line << ": tool-tags replaces --size 25";
      script = std::regex_replace(script, std::regex("--size 25 "),
                                  "--size " + s.tool_tag_mm + " ");
    } else if (w == "robot-step") {
      port = testing::FreeLoopbackPort();
      script = "python3 scripts/fake_robot.py --port " + std::to_string(port) +
               " --poses standin/sim/observations.csv &\n" +
               WithLoopbackListen(script, port, block.line) + "wait\n";
    } else if (w == "robot-stream") {
      port = testing::FreeLoopbackPort();
      script = WithLoopbackListen(script, port, block.line);
      stream = true;
    } else if (w == "joint-log") {
      dir = s.joint_log_lab;
    } else if (w == "file" && i + 1 < block.words.size()) {
      WriteFileAtomic(s.lab + "/" + block.words[++i], block.text);
      run = false;
    } else if (w == "robot-program") {
      CheckRobotProgram(block);
      run = false;
    } else if (w == "ur10") {
      dir = s.ur10_lab;
      if (fs::exists(s.lab + "/cell.yaml")) {
        fs::copy_file(s.lab + "/cell.yaml", dir + "/cell.yaml",
                      fs::copy_options::overwrite_existing);
      }
    } else if (w == "job-program") {
      fs::copy_file(dir + "/poses.csv", dir + "/program.csv",
                    fs::copy_options::overwrite_existing);
    } else if (w == "iso-measured") {
      WriteIsoMeasured(dir);
    } else if (w == "rehearsal") {
      dir = s.lab + "/rehearsal";
      if (!fs::exists(dir)) LinkProjectFolders(dir);
    } else {
      return false;
    }
  }
  if (!run) return true;
  std::thread controller;
  if (stream) controller = std::thread([port] { StreamingController(port); });
  const RunResult r = RunScript(dir, s.bin, script, block.line);
  if (controller.joinable()) controller.join();
  EXPECT_EQ(r.exit_code, 0) << "docs/LAB.md:" << block.line << "\n"
                            << script << "\n"
                            << r.err;
  return true;
}

// Every block of docs/LAB.md, in order, on its stand-ins: each must exit 0
// and the files the procedure goes on with must be there.
TEST(LabProcedureTest, EveryBlockRunsOnItsStandIns) {
  const std::vector<DocBlock> blocks = LabDocBlocks();
  ASSERT_GE(blocks.size(), 15u);
  for (const DocBlock& b : blocks) {
    ASSERT_TRUE(b.has_marker && !b.words.empty())
        << "docs/LAB.md:" << b.line
        << ": a block without a <!-- lab-test: ... --> marker on the line "
           "above (tests/lab_procedure_test.cc lists the stand-ins)";
  }
  const StandIns s = MakeStandIns();
  for (const DocBlock& b : blocks) {
    EXPECT_TRUE(RunDocBlock(b, s))
        << "docs/LAB.md:" << b.line << ": marker word without a stand-in";
  }
  for (const char* file : {"grid.pdf",
                           "rig.yaml",
                           "target.yaml",
                           "poses.csv",
                           "cell.yaml",
                           "run1/observations.csv",
                           "run3/frames.csv",
                           "joint_log/run2/frames.csv",
                           "run1/points.csv",
                           "run1/obs.csv",
                           "cal.yaml",
                           "diag.json",
                           "report.html",
                           "bundle.json",
                           "ur10/extended.yaml",
                           "ur10/ur_kinematics.yaml",
                           "ur10/program_compensated.csv",
                           "ur10/iso.csv",
                           "rehearsal/cal.yaml",
                           "rehearsal/handshake/frames.csv"}) {
    EXPECT_TRUE(testing::Exists(s.lab + "/" + file)) << file;
  }
  // The rig camcal measured from the grid (board in mm) is the simulated one.
  if (testing::Exists(s.lab + "/rig.yaml")) {
    EXPECT_NEAR(ReadRigYaml(s.lab + "/rig.yaml").BaselineMm(),
                s.rig.BaselineMm(), 1.0);
  }
}
// ---- refusals: what the user sees --------------------------------------

bool HasSolverLogLine(const std::string& err) {
  return std::regex_search(err, std::regex(R"((^|\n)[IWEF]\d{4} )")) ||
         err.find("Residual and Jacobian") != std::string::npos ||
         err.find("InitGoogleLogging") != std::string::npos;
}

// A rig in metres: track refuses with its own message; Ceres's per-frame
// "Residual and Jacobian evaluation failed" lines stay out of stderr unless
// KINCAL_SOLVER_LOG asks for them.
TEST(LabProcedureTest, RefusalShowsNoSolverLog) {
  const std::string w = testing::MakeTempDir("lab_glog");
  RunResult r = RunKincal("simulate --robot " + testing::SourceDir() +
                          "/data/robots/bh7.yaml --poses 8 --render "
                          "--render-width 640 --render-height 512 --out " +
                          w + "/sim");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  Rig rig = ReadRigYaml(w + "/sim/rig.yaml");
  for (Camera& c : rig.cameras) c.cam_from_rig.t /= 1000.0;
  WriteRigYaml(w + "/rig_in_metres.yaml", rig);
  const std::string track = "track --rig " + w +
                            "/rig_in_metres.yaml --target " + w +
                            "/sim/target.yaml --session " + w +
                            "/sim/session --out " + w + "/points.csv";
  r = RunKincal(track);
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("kincal: error:"), std::string::npos) << r.err;
  EXPECT_FALSE(HasSolverLogLine(r.err)) << r.err;
  r = testing::RunShell("KINCAL_SOLVER_LOG=1 " + testing::KincalBinary() + " " +
                        track);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_TRUE(HasSolverLogLine(r.err)) << r.err;
}

// A board in metres where camcal reads mm: refused before the images are
// read (square under 1 mm), on OpenCV's real stereo pairs and on rendered
// AprilGrid views, naming the board in mm; nothing written.
TEST(LabProcedureTest, CamcalBoardInMetresIsRefused) {
  const std::string w = testing::MakeTempDir("lab_metres");
  const std::string stereo =
      testing::SharedDataDir() + "/opencv-stereo-left-right";
  if (testing::Exists(stereo)) {
    const RunResult r = RunKincal(
        "camcal --left '" + stereo + "/left*.jpg' --right '" + stereo +
        "/right*.jpg' --target chessboard:9x6:0.025 --out " + w + "/cb.yaml");
    EXPECT_EQ(r.exit_code, 2) << r.err;
    EXPECT_NE(r.err.find("looks like metres"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("--target chessboard:9x6:25 "), std::string::npos)
        << r.err;
    EXPECT_FALSE(testing::Exists(w + "/cb.yaml"));
  }
  RenderGridViews(ExampleStereoRig(640, 512), w + "/grid");
  const std::string images =
      "camcal --left '" + w + "/grid/left/*.png' --right '" + w +
      "/grid/right/*.png' --out " + w + "/rig.yaml --target ";
  RunResult r = RunKincal(images + "aprilgrid:6x6:0.03:0.3");
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("--target aprilgrid:6x6:30:0.3 "), std::string::npos)
      << r.err;
  EXPECT_FALSE(testing::Exists(w + "/rig.yaml"));
  // 30 mm tags given as 1.05: every length 29 times too small, the board
  // about 19 "mm" from the camera: refused after the solve.
  r = RunKincal(images + "aprilgrid:6x6:1.05:0.3");
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("mm from the camera"), std::string::npos) << r.err;
  EXPECT_FALSE(testing::Exists(w + "/rig.yaml"));
  // The user says the board is that small: written.
  r = RunKincal(images + "aprilgrid:6x6:1.05:0.3 --tiny-board");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(testing::Exists(w + "/rig.yaml"));
}

}  // namespace
}  // namespace kincal
