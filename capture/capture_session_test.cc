// Tests of the recording workflow (capture/capture_session.cc) with image
// folders replayed as the cameras.

#include "capture/capture_session.h"

#include <gtest/gtest.h>
#include <sys/stat.h>

#include <cstdio>
#include <opencv2/imgcodecs.hpp>

#include "data/atomic_file.h"
#include "data/error.h"
#include "tests/testing/paths.h"

namespace kincal::capture {
namespace {

using ::kincal::testing::Exists;
using ::kincal::testing::MakeTempDir;

// l/000.png.. and r/000.png.. with `n` gray frames each.
std::string WriteStereoFolders(int n) {
  const std::string dir = MakeTempDir("capture_session");
  for (const char* side : {"/l", "/r"}) ::mkdir((dir + side).c_str(), 0755);
  for (int k = 0; k < n; ++k) {
    char name[32];
    std::snprintf(name, sizeof(name), "%03d.png", k);
    for (const char* side : {"/l/", "/r/"}) {
      cv::imwrite(dir + side + name,
                  cv::Mat(8, 8, CV_8UC1, cv::Scalar(20 * k)));
    }
  }
  return dir;
}

CaptureOptions Replay(const std::string& dir) {
  CaptureOptions options;
  options.cameras = {{"left", "folder:" + dir + "/l/*.png?fps=10"},
                     {"right", "folder:" + dir + "/r/*.png?fps=10"}};
  options.out = dir + "/session";
  options.announce = false;
  return options;
}

// The InputError text of recording with `options` ("" when none).
std::string InputErrorOf(const CaptureOptions& options) {
  try {
    RunCaptureSession(options);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(CaptureSessionTest, ReplaysTwoFoldersToTheEndIntoASession) {
  const std::string dir = WriteStereoFolders(5);
  const CaptureOptions options = Replay(dir);
  bool called = false;
  CaptureOptions with_hook = options;
  with_hook.before_recording = [&called] { called = true; };
  const CaptureResult r = RunCaptureSession(with_hook);
  EXPECT_EQ(r.outcome, CaptureResult::kOk) << r.message;
  EXPECT_TRUE(called);
  EXPECT_FALSE(r.step_and_shoot);
  ASSERT_TRUE(r.recorded);
  EXPECT_EQ(r.frames, 5);
  EXPECT_EQ(r.stop_reason, "end_of_stream");
  EXPECT_TRUE(r.complete);
  EXPECT_EQ(r.pairing, "lockstep");
  EXPECT_EQ(r.dropped_sets, 0);
  EXPECT_FALSE(r.length_mismatch);
  EXPECT_FALSE(r.has_joints);
  EXPECT_GT(r.bytes, 0u);
  const cv::Mat last =
      cv::imread(options.out + "/right/000004.png", cv::IMREAD_UNCHANGED);
  ASSERT_FALSE(last.empty());
  EXPECT_EQ(last.at<uint8_t>(0, 0), 80);  // lossless
  EXPECT_TRUE(Exists(options.out + "/frames.csv"));
  EXPECT_TRUE(Exists(options.out + "/session.yaml"));
}

TEST(CaptureSessionTest, RecordsOneAndThreeCamerasUnderTheirNames) {
  const std::string dir = WriteStereoFolders(4);
  CaptureOptions three = Replay(dir);
  three.cameras = {{"a", "folder:" + dir + "/l/*.png"},
                   {"b", "folder:" + dir + "/r/*.png"},
                   {"c", "folder:" + dir + "/l/00[0-2].png"}};  // shorter
  CaptureResult r = RunCaptureSession(three);
  EXPECT_EQ(r.outcome, CaptureResult::kOk) << r.message;
  EXPECT_EQ(r.frames, 3);
  EXPECT_TRUE(r.length_mismatch);
  ASSERT_EQ(r.cameras.size(), 3u);
  EXPECT_EQ(r.cameras[2].name, "c");
  EXPECT_EQ(r.cameras[2].uri, three.cameras[2].uri);
  EXPECT_EQ(r.cameras[0].dropped, 1);  // a's and b's fourth frames
  EXPECT_EQ(r.cameras[1].dropped, 1);
  EXPECT_EQ(r.cameras[2].dropped, 0);
  for (const char* cam : {"a", "b", "c"}) {
    const cv::Mat image =
        cv::imread(three.out + "/" + cam + "/000002.png", cv::IMREAD_UNCHANGED);
    ASSERT_FALSE(image.empty()) << cam;
    EXPECT_EQ(image.at<uint8_t>(0, 0), 40) << cam;
    EXPECT_FALSE(Exists(three.out + "/" + cam + "/000003.png"));
  }
  const std::string csv = ReadFile(three.out + "/frames.csv");
  EXPECT_NE(csv.find("\nframe,t_a,t_b,t_c,seq_a,seq_b,seq_c\n"),
            std::string::npos)
      << csv;

  CaptureOptions one = Replay(dir);
  one.out = dir + "/mono";
  one.cameras = {{"cam0", "folder:" + dir + "/r/*.png"}};
  r = RunCaptureSession(one);
  EXPECT_EQ(r.outcome, CaptureResult::kOk) << r.message;
  EXPECT_EQ(r.frames, 4);
  EXPECT_FALSE(r.length_mismatch);
  EXPECT_TRUE(Exists(one.out + "/cam0/000003.png"));
  EXPECT_NE(ReadFile(one.out + "/frames.csv").find("\nframe,t_cam0,seq_cam0\n"),
            std::string::npos);
}

TEST(CaptureSessionTest, StopsAfterTheRequestedPairs) {
  const std::string dir = WriteStereoFolders(5);
  CaptureOptions options = Replay(dir);
  options.frames = 3;
  const CaptureResult r = RunCaptureSession(options);
  EXPECT_EQ(r.outcome, CaptureResult::kOk) << r.message;
  EXPECT_EQ(r.frames, 3);
  EXPECT_EQ(r.stop_reason, "frames");
  EXPECT_NE(ReadFile(options.out + "/session.yaml").find("frames"),
            std::string::npos);
}

TEST(CaptureSessionTest, BadInputIsRefusedBeforeAnythingIsWritten) {
  const std::string dir = WriteStereoFolders(2);
  CaptureOptions same = Replay(dir);
  same.cameras[1].uri = same.cameras[0].uri;
  EXPECT_NE(InputErrorOf(same).find(
                "cameras 'left' and 'right' name the same source"),
            std::string::npos);

  CaptureOptions twice = Replay(dir);
  twice.cameras[1].name = "left";
  EXPECT_NE(InputErrorOf(twice).find("camera 'left' is given twice"),
            std::string::npos);

  CaptureOptions bad_name = Replay(dir);
  bad_name.cameras[1].name = "my cam";
  EXPECT_NE(InputErrorOf(bad_name).find("my cam"), std::string::npos);

  CaptureOptions none = Replay(dir);
  none.cameras.clear();
  EXPECT_NE(InputErrorOf(none).find("required"), std::string::npos);

  CaptureOptions mixed = Replay(dir);
  mixed.cameras.push_back({"top", "fake:cam"});
  EXPECT_NE(InputErrorOf(mixed).find("cannot pair a camera with a recording"),
            std::string::npos);

  CaptureOptions offset_alone = Replay(dir);
  offset_alone.joints_offset = 0.5;
  EXPECT_NE(InputErrorOf(offset_alone).find("--joints-offset with --joints"),
            std::string::npos);

  CaptureOptions missing = Replay(dir);
  missing.cameras[0].uri = "folder:" + dir + "/none/*.png";
  EXPECT_EQ(InputErrorOf(missing).rfind("capture: ", 0), 0u);
  EXPECT_FALSE(Exists(missing.out));

  CaptureOptions stream = Replay(dir);
  stream.stream = true;
  EXPECT_NE(InputErrorOf(stream).find("--stream needs --robot-listen"),
            std::string::npos);
  EXPECT_FALSE(Exists(stream.out));
}

TEST(CaptureSessionTest, NeverOverwritesASession) {
  const std::string dir = WriteStereoFolders(2);
  const CaptureOptions options = Replay(dir);
  ASSERT_EQ(RunCaptureSession(options).outcome, CaptureResult::kOk);
  EXPECT_NE(InputErrorOf(options).find("exists and is not empty"),
            std::string::npos);
}

TEST(CaptureSessionTest, MergesAJointLogWithAGivenOffset) {
  const std::string dir = WriteStereoFolders(4);
  std::string log = "t,j1,j2\n";
  for (int k = -5; k <= 10; ++k) {
    log += std::to_string(0.1 * k) + "," + std::to_string(k) + ",7\n";
  }
  WriteFileAtomic(dir + "/joints.csv", log);
  CaptureOptions options = Replay(dir);
  options.joints = dir + "/joints.csv";
  options.joints_offset = 0;
  options.max_joint_speed = 100;  // j1 moves 10 units/s
  const CaptureResult r = RunCaptureSession(options);
  EXPECT_EQ(r.outcome, CaptureResult::kOk) << r.message;
  ASSERT_TRUE(r.has_joints);
  EXPECT_FALSE(r.joints.from_stream);
  EXPECT_FALSE(r.joints.offset_estimated);
  EXPECT_DOUBLE_EQ(r.joints.offset_s, 0);
  EXPECT_EQ(r.joints.frames_with_reading, 4);
  EXPECT_EQ(r.joints.frames_too_fast, 0);
  const std::string frames = ReadFile(options.out + "/frames.csv");
  EXPECT_NE(frames.find("j1,j2"), std::string::npos) << frames;
}

TEST(CaptureSessionTest, AJointLogThatCannotBeMergedKeepsThePairs) {
  const std::string dir = WriteStereoFolders(4);
  WriteFileAtomic(dir + "/joints.csv", "t,j1\n5.0,1\n5.5,1\n");
  CaptureOptions options = Replay(dir);
  options.joints = dir + "/joints.csv";
  options.joints_offset = 0;  // the log covers 5.0 .. 5.5 s, frames 0 .. 0.3
  const CaptureResult r = RunCaptureSession(options);
  EXPECT_EQ(r.outcome, CaptureResult::kBadInput);
  EXPECT_NE(r.message.find("does not cover the session"), std::string::npos)
      << r.message;
  EXPECT_NE(r.message.find("(the 4 pairs recorded are kept in " + options.out +
                           ", without joint readings)"),
            std::string::npos)
      << r.message;
  EXPECT_TRUE(r.recorded);
  EXPECT_FALSE(r.has_joints);
}

}  // namespace
}  // namespace kincal::capture
