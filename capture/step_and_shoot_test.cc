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

TEST(StepAndShootTest, AverageSetsRoundsTheMeanAndAveragesTimes) {
  std::vector<FrameSet> sets(2);
  const double values[2][3] = {{10, 100, 0}, {13, 100, 255}};
  for (int s = 0; s < 2; ++s) {
    sets[s].frames.resize(3);
    for (int c = 0; c < 3; ++c) {
      sets[s].frames[c].image =
          cv::Mat(2, 2, CV_8UC1, cv::Scalar(values[s][c]));
      sets[s].frames[c].timestamp_s = 1.0 + s + 0.5 * c;
    }
  }
  const FrameSet mean = AverageSets(sets);
  ASSERT_EQ(mean.frames.size(), 3u);
  EXPECT_EQ(mean.frames[0].image.at<uint8_t>(0, 0), 12);  // 11.5 rounds up
  EXPECT_EQ(mean.frames[1].image.at<uint8_t>(1, 1), 100);
  EXPECT_EQ(mean.frames[2].image.at<uint8_t>(1, 0), 128);  // 127.5
  EXPECT_DOUBLE_EQ(mean.frames[0].timestamp_s, 1.5);
  EXPECT_DOUBLE_EQ(mean.frames[1].timestamp_s, 2.0);
  EXPECT_DOUBLE_EQ(mean.frames[2].timestamp_s, 2.5);
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
  std::unique_ptr<FrameGrabber> grabber;
};

Rig OpenReplay(const std::string& dir) {
  Rig rig;
  rig.left = MakeFrameSource("folder:" + dir + "/l/*.png");
  rig.right = MakeFrameSource("folder:" + dir + "/r/*.png");
  rig.grabber = std::make_unique<FrameGrabber>(
      std::vector<FrameSource*>{rig.left.get(), rig.right.get()});
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
  options.info.cameras = {{"left", "folder:l", "l", ""},
                          {"right", "folder:r", "r", ""}};
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

TEST(StepAndShootTest, ThreeCamerasRecordOneAveragedSetPerPose) {
  // Folders l and r as above, and a third camera "t" (value 10 k + 1).
  const std::string dir = WriteStereoFolders(4);
  ::mkdir((dir + "/t").c_str(), 0755);
  for (int k = 0; k < 4; ++k) {
    char name[32];
    std::snprintf(name, sizeof(name), "/t/%03d.png", k);
    cv::imwrite(dir + name, cv::Mat(8, 8, CV_8UC1, cv::Scalar(10 * k + 1)));
  }
  std::vector<std::unique_ptr<FrameSource>> sources;
  for (const char* folder : {"/l", "/r", "/t"}) {
    sources.push_back(MakeFrameSource("folder:" + dir + folder + "/*.png"));
  }
  FrameGrabber grabber({sources[0].get(), sources[1].get(), sources[2].get()});
  ASSERT_TRUE(grabber.Open().ok());
  const int port = FreeLoopbackPort();
  std::thread robot([port] {
    const int fd = ConnectLoopback(port, 100);
    if (fd < 0) return;
    std::string line;
    SendLine(fd, "HELLO testbot j1 j2");
    ReceiveLine(fd, &line);
    SendLine(fd, "SETTLED 0 1 2");
    ReceiveLine(fd, &line);
    SendLine(fd, "BYE");
    ::close(fd);
  });
  const std::string out = dir + "/session";
  StepAndShootOptions options = Options(port, out);
  options.info.cameras = {{"a", "folder:l", "", ""},
                          {"b", "folder:r", "", ""},
                          {"c", "folder:t", "", ""}};
  const StepAndShootResult r = RunStepAndShoot(&grabber, false, options);
  robot.join();
  EXPECT_EQ(r.outcome, StepAndShootResult::kOk) << r.message;
  EXPECT_EQ(r.frames, 1);
  // Pose 0 averages replay sets 0 and 1 of every camera.
  const int expected[] = {5, 5, 6};
  const char* names[] = {"a", "b", "c"};
  for (int c = 0; c < 3; ++c) {
    const cv::Mat image =
        cv::imread(out + "/" + names[c] + "/000000.png", cv::IMREAD_UNCHANGED);
    ASSERT_FALSE(image.empty()) << names[c];
    EXPECT_EQ(image.at<uint8_t>(0, 0), expected[c]) << names[c];
  }
  const std::string frames = ReadFile(out + "/frames.csv");
  EXPECT_NE(frames.find("\nframe,t_a,t_b,t_c,seq_a,seq_b,seq_c,j1,j2\n0,"),
            std::string::npos)
      << frames;
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
