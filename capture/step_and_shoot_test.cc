// Tests of step and shoot (capture/step_and_shoot.cc): replayed image
// folders as the cameras and a robot on loopback.

#include "capture/step_and_shoot.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <opencv2/imgcodecs.hpp>
#include <thread>

#include "capture/frame_source.h"
#include "data/atomic_file.h"
#include "tests/testing/loopback.h"
#include "tests/testing/paths.h"

namespace kincal::capture {
namespace {

using ::kincal::testing::ConnectLoopback;
using ::kincal::testing::Exists;
using ::kincal::testing::FreeLoopbackPort;
using ::kincal::testing::MakeTempDir;
using ::kincal::testing::ReceiveLine;
using ::kincal::testing::SendLine;

TEST(StepAndShootTest, AveragePairsRoundsTheMeanAndAveragesTimes) {
  std::vector<StereoFrame> pairs(2);
  pairs[0].left.image = cv::Mat(2, 2, CV_8UC1, cv::Scalar(10));
  pairs[1].left.image = cv::Mat(2, 2, CV_8UC1, cv::Scalar(13));
  pairs[0].right.image = cv::Mat(2, 2, CV_8UC1, cv::Scalar(100));
  pairs[1].right.image = cv::Mat(2, 2, CV_8UC1, cv::Scalar(100));
  pairs[0].left.timestamp_s = 1.0;
  pairs[1].left.timestamp_s = 2.0;
  pairs[0].right.timestamp_s = 1.5;
  pairs[1].right.timestamp_s = 2.5;
  const StereoFrame mean = AveragePairs(pairs);
  EXPECT_EQ(mean.left.image.at<uint8_t>(0, 0), 12);  // 11.5 rounds up
  EXPECT_EQ(mean.right.image.at<uint8_t>(1, 1), 100);
  EXPECT_DOUBLE_EQ(mean.left.timestamp_s, 1.5);
  EXPECT_DOUBLE_EQ(mean.right.timestamp_s, 2.0);
}

// Two folders of `n` gray frames each (value 10 k for frame k).
std::string WriteStereoFolders(int n) {
  const std::string dir = MakeTempDir("step_shoot");
  for (int k = 0; k < n; ++k) {
    char name[32];
    std::snprintf(name, sizeof(name), "%03d.png", k);
    for (const char* side : {"/l", "/r"}) {
      ::mkdir((dir + side).c_str(), 0755);
      cv::imwrite(dir + side + "/" + name,
                  cv::Mat(8, 8, CV_8UC1, cv::Scalar(10 * k)));
    }
  }
  return dir;
}

struct Rig {
  std::unique_ptr<FrameSource> left, right;
  std::unique_ptr<StereoGrabber> grabber;
};

Rig OpenReplay(const std::string& dir) {
  Rig rig;
  rig.left = MakeFrameSource("folder:" + dir + "/l/*.png");
  rig.right = MakeFrameSource("folder:" + dir + "/r/*.png");
  rig.grabber = std::make_unique<StereoGrabber>(rig.left.get(), rig.right.get(),
                                                StereoGrabberOptions());
  return rig;
}

StepAndShootOptions Options(int port, const std::string& out) {
  StepAndShootOptions options;
  options.listen = "127.0.0.1:" + std::to_string(port);
  options.joint_names = {"j1", "j2"};
  options.robot_file = "robot.yaml";
  options.shots = 2;
  options.timeout_s = 10;
  options.out = out;
  options.announce = false;
  return options;
}

TEST(StepAndShootTest, RecordsOneAveragedPairPerSettledPoseUntilBye) {
  const std::string dir = WriteStereoFolders(6);
  Rig rig = OpenReplay(dir);
  ASSERT_TRUE(rig.grabber->Open().ok());
  const int port = FreeLoopbackPort();
  std::vector<std::string> answers;
  std::thread robot([port, &answers] {
    const int fd = ConnectLoopback(port, 100);
    if (fd < 0) return;
    std::string line;
    SendLine(fd, "HELLO testbot j2 j1");
    if (ReceiveLine(fd, &line)) answers.push_back(line);
    for (const char* settled : {"SETTLED 0 20 10", "SETTLED 1 21 11"}) {
      SendLine(fd, settled);
      if (ReceiveLine(fd, &line)) answers.push_back(line);
    }
    SendLine(fd, "BYE");
    ::close(fd);
  });
  const std::string out = dir + "/session";
  const StepAndShootResult r =
      RunStepAndShoot(rig.grabber.get(), false, Options(port, out));
  robot.join();
  EXPECT_EQ(r.outcome, StepAndShootResult::kOk) << r.message;
  EXPECT_TRUE(r.session_created);
  EXPECT_TRUE(r.complete);
  EXPECT_EQ(r.robot_name, "testbot");
  EXPECT_EQ(r.poses, 2);
  EXPECT_EQ(r.frames, 2);
  EXPECT_EQ(r.stop_reason, "robot_bye");
  EXPECT_EQ(answers,
            (std::vector<std::string>{"OK kincal 1", "DONE 0 2", "DONE 1 2"}));
  // HELLO's order (j2 j1) is mapped to the robot's (j1, j2).
  const std::string obs = ReadFile(out + "/observations.csv");
  EXPECT_NE(obs.find("pose,j1,j2\n0,10,20\n1,11,21\n"), std::string::npos)
      << obs;
  // Pose 0 averages replay frames 0 and 1 (values 0 and 10).
  const cv::Mat first =
      cv::imread(out + "/left/000000.png", cv::IMREAD_UNCHANGED);
  ASSERT_FALSE(first.empty());
  EXPECT_EQ(first.at<uint8_t>(0, 0), 5);
}

TEST(StepAndShootTest, AnUnknownJointInHelloWritesNothing) {
  const std::string dir = WriteStereoFolders(2);
  Rig rig = OpenReplay(dir);
  ASSERT_TRUE(rig.grabber->Open().ok());
  const int port = FreeLoopbackPort();
  std::thread robot([port] {
    const int fd = ConnectLoopback(port, 100);
    if (fd < 0) return;
    SendLine(fd, "HELLO testbot j1 elbow");
    std::string line;
    ReceiveLine(fd, &line);
    ::close(fd);
  });
  const std::string out = dir + "/session";
  const StepAndShootResult r =
      RunStepAndShoot(rig.grabber.get(), false, Options(port, out));
  robot.join();
  EXPECT_EQ(r.outcome, StepAndShootResult::kBadInput);
  EXPECT_NE(r.message.find("unknown or repeated joint 'elbow'"),
            std::string::npos)
      << r.message;
  EXPECT_NE(r.message.find("(nothing written)"), std::string::npos);
  EXPECT_FALSE(r.session_created);
  EXPECT_FALSE(Exists(out));
}

}  // namespace
}  // namespace kincal::capture
