#include "synth/recorded_session.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "data/error.h"

namespace kincal {
namespace {

std::string ReadText(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

int CountLines(const std::string& text, const std::string& prefix) {
  int n = 0;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) {
    n += line.rfind(prefix, 0) == 0;
  }
  return n;
}

std::string FreshDir(const std::string& name) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() /
      ("kincal_recorded_session_" + name + "_" +
       std::to_string(::testing::UnitTest::GetInstance()->random_seed()));
  std::filesystem::remove_all(dir);
  return dir.string();
}

TEST(RenderRecordedSession, WritesTheSpecLayout) {
  const Rig rig = ExampleStereoRig(320, 256);
  const Target target = ExampleTarget();
  RecordedSessionInput in;
  in.rig_from_tool = {ExampleToolPose(0), ExampleToolPose(1)};
  in.joint_names = {"j1", "j2"};
  in.joints = {{1.5, -2}, {}};
  const std::string dir = FreshDir("layout");
  EXPECT_EQ(RenderRecordedSession(rig, target, in, RenderOptions(), 3, dir), 2);
  for (const char* f : {"/left/000000.png", "/left/000001.png",
                        "/right/000000.png", "/right/000001.png"}) {
    EXPECT_TRUE(std::filesystem::exists(dir + f)) << f;
  }
  const std::string frames = ReadText(dir + "/frames.csv");
  EXPECT_NE(frames.find("frame,t_left,t_right,seq_left,seq_right,j1,j2\n"),
            std::string::npos);
  EXPECT_NE(frames.find("\n0,0,0,0,0,1.5,-2\n"), std::string::npos) << frames;
  EXPECT_NE(frames.find("\n1,0.1,0.1,1,1,,\n"), std::string::npos) << frames;
  const std::string truth = ReadText(dir + "/truth.csv");
  EXPECT_NE(truth.find("# seed 3;"), std::string::npos);
  EXPECT_EQ(CountLines(truth, "0,") + CountLines(truth, "1,"), 2);
  // Every tag of both views, four corners each, cameras named 0 and 1.
  const std::string corners = ReadText(dir + "/corners.csv");
  const int tags = static_cast<int>(target.tags.size());
  EXPECT_EQ(CountLines(corners, "0,0,") + CountLines(corners, "0,1,"),
            2 * 4 * tags);
  const std::string yaml = ReadText(dir + "/session.yaml");
  EXPECT_NE(yaml.find("status: complete"), std::string::npos);
  EXPECT_NE(yaml.find("frames: 2"), std::string::npos);
  std::filesystem::remove_all(dir);
}

TEST(RenderRecordedSession, RefusesAFolderThatHoldsASession) {
  const Rig rig = ExampleStereoRig(160, 128);
  RecordedSessionInput in;
  in.rig_from_tool = {ExampleToolPose(0)};
  const std::string dir = FreshDir("twice");
  RenderRecordedSession(rig, ExampleTarget(), in, RenderOptions(), 1, dir);
  EXPECT_THROW(
      RenderRecordedSession(rig, ExampleTarget(), in, RenderOptions(), 1, dir),
      InputError);
  std::filesystem::remove_all(dir);
}

TEST(RenderRecordedSession, JointRowsMustMatchThePoses) {
  RecordedSessionInput in;
  in.rig_from_tool = {ExampleToolPose(0), ExampleToolPose(1)};
  in.joints = {{1.0}};
  EXPECT_THROW(
      RenderRecordedSession(ExampleStereoRig(160, 128), ExampleTarget(), in,
                            RenderOptions(), 1, FreshDir("joints")),
      InputError);
}

}  // namespace
}  // namespace kincal
