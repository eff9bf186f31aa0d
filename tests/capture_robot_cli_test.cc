// End to end: step-and-shoot with a fake robot on the loopback interface
// and two fake cameras (`kincal capture --robot-listen`): every settled
// pose gives one averaged pair with the robot's readings; a link dropping
// mid-session keeps the session (exit 1, clear message); an unknown joint
// name exits 2 writing nothing; a malformed line exits 2 keeping what was
// recorded.

#include <gtest/gtest.h>
#include <time.h>
#include <unistd.h>
#include <yaml-cpp/yaml.h>

#include <chrono>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <thread>
#include <vector>

#include "data/atomic_file.h"
#include "data/csv.h"
#include "tests/testing/loopback.h"
#include "tests/testing/paths.h"
#include "tests/testing/run.h"

namespace kincal {
namespace {

using testing::RunKincal;
using testing::RunResult;

// A robot controller's side of the protocol: connects (retrying while
// kincal starts), sends lines, and reads kincal's answer after each line
// that expects one. `drop_after` closes the link after that many SETTLED.
class FakeRobot {
 public:
  void Run(int port, const std::vector<std::string>& lines) {
    fd_ = testing::ConnectLoopback(port, 200);
    if (fd_ < 0) return;
    for (const std::string& line : lines) {
      if (line == "<drop>") break;
      if (!testing::SendLine(fd_, line)) break;
      if (line == "BYE") break;
      if (line.rfind("J ", 0) == 0) continue;  // no answer to a reading
      std::string reply;
      if (!testing::ReceiveLine(fd_, &reply)) break;
      replies.push_back(reply);
      if (reply.rfind("ERROR", 0) == 0) break;
    }
    ::close(fd_);
  }
  std::vector<std::string> replies;

 private:
  int fd_ = -1;
};

struct Rig {
  std::string dir, robot, out;
  int port = 0;
};

Rig Make(const std::string& tag) {
  Rig s;
  s.dir = testing::MakeTempDir(tag);
  s.robot = s.dir + "/robot.yaml";
  WriteFileAtomic(s.robot,
                  "kincal_robot: 1\nname: two\nconvention: dh\njoints:\n"
                  "  - {name: j1, type: revolute, d: 0, alpha: 0, a: 300, "
                  "theta: 0, limits: [-90, 90]}\n"
                  "  - {name: j2, type: prismatic, d: 0, alpha: 0, a: 200, "
                  "theta: 0, limits: [0, 100]}\n"
                  "tool: {d: 0, alpha: 0, a: 50, theta: 0}\n");
  s.out = s.dir + "/session";
  s.port = testing::FreeLoopbackPort();
  return s;
}

RunResult Capture(const Rig& s, FakeRobot* robot,
                  const std::vector<std::string>& lines) {
  std::thread t([&] { robot->Run(s.port, lines); });
  const RunResult r = RunKincal(
      "capture --left 'fake:l?width=320&height=240&fps=30' --right "
      "'fake:r?width=320&height=240&fps=30' --out " +
      s.out + " --robot " + s.robot + " --robot-listen 127.0.0.1:" +
      std::to_string(s.port) + " --shots 3 --robot-timeout 20 --json");
  t.join();
  return r;
}

std::vector<CsvLine> Frames(const std::string& out) {
  return TokenizeCsv(ReadFile(out + "/frames.csv"), "frames.csv");
}

TEST(CaptureRobotCli, StepAndShootRecordsEverySettledPose) {
  const Rig s = Make("robot_ok");
  FakeRobot robot;
  // The robot names its joints in its own order.
  const RunResult r = Capture(
      s, &robot,
      {"HELLO fake-arm j2 j1", "SETTLED 0 10 -5.5", "SETTLED 1 20 0",
       "J 12.5 20 0", "SETTLED 2 30.25 45", "SETTLED 3 40 89.5", "BYE"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::vector<std::string> expected = {
      "OK kincal 1", "DONE 0 3", "DONE 1 3", "DONE 2 3", "DONE 3 3"};
  EXPECT_EQ(robot.replies, expected);
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["poses"], 4);
  EXPECT_EQ(j["stop_reason"], "robot_bye");
  ASSERT_EQ(j["cameras"].size(), 2u);
  EXPECT_EQ(j["cameras"][1]["name"], "right");
  const auto lines = Frames(s.out);
  ASSERT_EQ(lines.size(), 5u);
  EXPECT_EQ(lines[0].fields[5].text, "j1");
  EXPECT_EQ(lines[0].fields[6].text, "j2");
  const double j1[] = {-5.5, 0, 45, 89.5}, j2[] = {10, 20, 30.25, 40};
  for (int k = 0; k < 4; ++k) {
    EXPECT_DOUBLE_EQ(std::stod(lines[k + 1].fields[5].text), j1[k]);
    EXPECT_DOUBLE_EQ(std::stod(lines[k + 1].fields[6].text), j2[k]);
    char name[32];
    std::snprintf(name, sizeof(name), "/left/%06d.png", k);
    EXPECT_EQ(cv::imread(s.out + name).cols, 320);
  }
  EXPECT_EQ(YAML::LoadFile(s.out + "/session.yaml")["status"].as<std::string>(),
            "complete");
  EXPECT_TRUE(testing::Exists(s.out + "/joints.csv"));  // the J stream
}

TEST(CaptureRobotCli, LinkDroppingMidSessionKeepsTheSession) {
  const Rig s = Make("robot_drop");
  FakeRobot robot;
  const RunResult r =
      Capture(s, &robot,
              {"HELLO arm j1 j2", "SETTLED 0 1 2", "SETTLED 1 3 4", "<drop>"});
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find("robot link lost after 2 poses"), std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("kept"), std::string::npos) << r.err;
  EXPECT_EQ(Frames(s.out).size(), 3u);
  EXPECT_EQ(YAML::LoadFile(s.out + "/session.yaml")["status"].as<std::string>(),
            "failed");
}

TEST(CaptureRobotCli, UnknownJointNameIsBadInputAndWritesNothing) {
  const Rig s = Make("robot_unknown");
  FakeRobot robot;
  const RunResult r = Capture(s, &robot, {"HELLO arm j1 wrist"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("wrist"), std::string::npos) << r.err;
  ASSERT_EQ(robot.replies.size(), 1u);
  EXPECT_EQ(robot.replies[0].rfind("ERROR", 0), 0u) << robot.replies[0];
  EXPECT_FALSE(testing::Exists(s.out));
}

TEST(CaptureRobotCli, MalformedLineIsBadInputAndKeepsWhatWasRecorded) {
  const Rig s = Make("robot_malformed");
  FakeRobot robot;
  const RunResult r = Capture(
      s, &robot, {"HELLO arm j1 j2", "SETTLED 0 1 2", "SETTLED 1 abc 2"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("line 3"), std::string::npos) << r.err;
  EXPECT_EQ(robot.replies.back().rfind("ERROR", 0), 0u);
  EXPECT_EQ(Frames(s.out).size(), 2u);
}

double HostNow() {
  timespec ts{};
  ::clock_gettime(CLOCK_MONOTONIC, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

// A controller streaming J lines at 100 Hz on its own clock (host + 500 s):
// j1 = 2 deg/s * host time (moves slowly), j2 = 7 (still); then BYE, or a
// dropped link.
void StreamingRobot(int port, double seconds, bool bye,
                    std::vector<std::string>* replies) {
  const int fd = testing::ConnectLoopback(port, 200);
  if (fd < 0) return;
  testing::SendLine(fd, "HELLO streamer j2 j1");
  std::string reply;
  testing::ReceiveLine(fd, &reply);
  replies->push_back(reply);
  const double end = HostNow() + seconds;
  while (HostNow() < end) {
    const double t = HostNow();
    char line[128];
    std::snprintf(line, sizeof(line), "J %.6f 7 %.6f", t + 500.0, 2 * t);
    testing::SendLine(fd, line);
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  if (bye) testing::SendLine(fd, "BYE");
  ::close(fd);
}

RunResult CaptureStream(const Rig& s, double seconds, bool bye,
                        std::vector<std::string>* replies) {
  std::thread t([&] { StreamingRobot(s.port, seconds, bye, replies); });
  const RunResult r = RunKincal(
      "capture --left 'fake:l?width=320&height=240&fps=30' --right "
      "'fake:r?width=320&height=240&fps=30' --out " +
      s.out + " --robot " + s.robot +
      " --robot-listen 127.0.0.1:" + std::to_string(s.port) +
      " --stream --max-joint-speed 5 --robot-timeout 20 --json");
  t.join();
  return r;
}

TEST(CaptureRobotCli, LiveJointStreamFillsEveryFrameByTime) {
  const Rig s = Make("robot_stream");
  std::vector<std::string> replies;
  const RunResult r = CaptureStream(s, 2.0, true, &replies);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  ASSERT_FALSE(replies.empty());
  EXPECT_EQ(replies[0], "OK kincal 1");
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["stop_reason"], "robot_bye");
  EXPECT_NEAR(j["joints"]["offset_s"].get<double>(), -500.0, 0.01);
  const auto lines = Frames(s.out);
  ASSERT_GT(lines.size(), 30u);
  ASSERT_EQ(lines[0].fields.size(), 7u);
  // Frames before the first and after the last J line have no reading (how
  // many depends on when the robot connects: timing, not correctness);
  // every frame between them has one.
  size_t first = 0, last = 0;
  for (size_t k = 1; k < lines.size(); ++k) {
    if (lines[k].fields[5].text.empty()) continue;
    if (first == 0) first = k;
    last = k;
  }
  ASSERT_GT(first, 0u);
  EXPECT_GE(last - first + 1, 30u);  // 2 s at 30 fps, most of it streamed
  for (size_t k = first; k <= last; ++k) {
    const auto& f = lines[k].fields;
    ASSERT_FALSE(f[5].text.empty()) << "frame " << k << " between readings";
    const double t_left = std::stod(f[1].text);
    // 2 deg/s: 0.02 deg = 10 ms of clock error (loopback latency ~0.1 ms).
    EXPECT_NEAR(std::stod(f[5].text), 2 * t_left, 0.02) << k;
    EXPECT_DOUBLE_EQ(std::stod(f[6].text), 7.0);
  }
}

TEST(CaptureRobotCli, LiveJointStreamDroppingKeepsTheSession) {
  const Rig s = Make("robot_stream_drop");
  std::vector<std::string> replies;
  const RunResult r = CaptureStream(s, 1.0, false, &replies);
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find("robot link lost"), std::string::npos) << r.err;
  const auto lines = Frames(s.out);
  EXPECT_GT(lines.size(), 10u);
  EXPECT_EQ(lines[0].fields.size(), 7u);  // readings kept for what came
  EXPECT_EQ(YAML::LoadFile(s.out + "/session.yaml")["status"].as<std::string>(),
            "failed");
}

}  // namespace
}  // namespace kincal
