#include "data/session.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "data/error.h"
#include "tests/testing/paths.h"

namespace kincal {
namespace {

using ::testing::HasSubstr;

void Write(const std::string& path, const std::string& text) {
  std::ofstream(path) << text;
}

// A session folder with `n` pairs (image files are placeholders: the reader
// locates images, it does not decode them).
std::string MakeSession(const std::string& tag, const std::string& csv, int n,
                        const std::string& status = "complete") {
  const std::string dir = testing::MakeTempDir(tag);
  std::filesystem::create_directories(dir + "/left");
  std::filesystem::create_directories(dir + "/right");
  for (int i = 0; i < n; ++i) {
    char name[32];
    std::snprintf(name, sizeof(name), "%06d.png", i);
    Write(dir + "/left/" + name, "x");
    Write(dir + "/right/" + name, "x");
  }
  Write(dir + "/frames.csv", csv);
  Write(dir + "/session.yaml",
        "kincal_session: 1\nstatus: " + status + "\nframes: 3\n");
  return dir;
}

const char kCsv[] =
    "# written by a test\n"
    "frame,t_left,t_right,seq_left,seq_right,j1,j2\n"
    "0,0.0,0.001,10,20,1.5,-3\n"
    "1,0.1,0.101,11,21,,\n"
    "2,0.2,0.201,12,22,2.5,4\n";

std::string ErrorOf(const std::string& dir, const SessionReadOptions& o) {
  try {
    ReadSession(dir, o);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(Session, ReadsFramesJointsAndImagePairs) {
  const std::string dir = MakeSession("ok", kCsv, 3);
  SessionReadOptions o;
  o.joint_names = {"j2", "j1"};  // robot order differs from the file's
  const Session s = ReadSession(dir, o);
  EXPECT_EQ(s.status, "complete");
  ASSERT_EQ(s.frames.size(), 3u);
  EXPECT_EQ(s.CountWithJoints(), 2);
  EXPECT_EQ(s.frames[0].q, (std::vector<double>{-3, 1.5}));
  EXPECT_FALSE(s.frames[1].HasJoints());
  EXPECT_EQ(s.frames[2].seq_right, 22);
  EXPECT_DOUBLE_EQ(s.frames[2].t_left, 0.2);
  EXPECT_EQ(s.frames[1].left_image, dir + "/left/000001.png");
  EXPECT_EQ(s.frames[1].right_image, dir + "/right/000001.png");
  // Without a robot the joint columns are listed but not read.
  const Session plain = ReadSession(dir);
  EXPECT_EQ(plain.joint_columns, (std::vector<std::string>{"j1", "j2"}));
  EXPECT_FALSE(plain.frames[0].HasJoints());
}

TEST(Session, MissingJointColumnIsReportedWithPosition) {
  const std::string dir = MakeSession("missing", kCsv, 3);
  SessionReadOptions o;
  o.joint_names = {"j1", "j2", "j3"};
  const std::string e = ErrorOf(dir, o);
  EXPECT_THAT(e, HasSubstr("frames.csv:2:"));
  EXPECT_THAT(e, HasSubstr("missing: j3"));
}

TEST(Session, SessionOfAnotherRobotIsRejected) {
  const std::string dir = MakeSession("other", kCsv, 3);
  SessionReadOptions o;
  o.joint_names = {"shoulder", "elbow"};
  const std::string e = ErrorOf(dir, o);
  EXPECT_THAT(e, HasSubstr("another robot"));
  EXPECT_THAT(e, HasSubstr("shoulder"));
}

TEST(Session, FrameWithoutPairIsRejectedInACompleteSession) {
  const std::string dir = MakeSession("nopair", kCsv, 3);
  std::filesystem::remove(dir + "/right/000001.png");
  const std::string e = ErrorOf(dir, {});
  EXPECT_THAT(e, HasSubstr("frames.csv:4:1"));
  EXPECT_THAT(e, HasSubstr("no right image"));
  // An image without a row is also bad input.
  const std::string dir2 = MakeSession("extra", kCsv, 4);
  EXPECT_THAT(ErrorOf(dir2, {}), HasSubstr("000003.png: image without a row"));
}

TEST(Session, UnfinishedSessionIsReadUpToItsLastCompletePair) {
  const std::string csv =
      "frame,t_left,t_right,seq_left,seq_right,j1,j2\n"
      "0,0.0,0.001,10,20,1.5,-3\n"
      "1,0.1,0.101,11,21,1,2\n"
      "2,0.2,0.201,12,22,2.5,4\n"
      "3,0.3,0.3";  // truncated last row
  const std::string dir = MakeSession("rec", csv, 2, "recording");
  std::filesystem::rename(dir + "/frames.csv", dir + "/frames.csv.part");
  SessionReadOptions o;
  o.joint_names = {"j1", "j2"};
  const Session s = ReadSession(dir, o);
  EXPECT_EQ(s.status, "recording");
  ASSERT_EQ(s.frames.size(), 2u);
  EXPECT_EQ(s.dropped_tail, 1);
  // The same truncation in a complete session is an error.
  const std::string dir2 = MakeSession("trunc", csv, 4);
  EXPECT_THAT(ErrorOf(dir2, o), HasSubstr("frames.csv:5:"));
}

TEST(Session, ImagesNamedOtherwisePairInSortedOrder) {
  const std::string csv =
      "frame,t_left,t_right,seq_left,seq_right,j1,j2\n"
      "1,,,,,1,2\n"
      "2,,,,,3,4\n";
  const std::string dir = MakeSession("order", csv, 0);
  for (const char* side : {"/left/", "/right/"}) {
    Write(dir + side + "img_a.png", "x");
    Write(dir + side + "img_b.png", "x");
  }
  SessionReadOptions o;
  o.joint_names = {"j1", "j2"};
  const Session s = ReadSession(dir, o);
  ASSERT_EQ(s.frames.size(), 2u);
  EXPECT_EQ(s.frames[1].left_image, dir + "/left/img_b.png");
  EXPECT_EQ(s.frames[1].q, (std::vector<double>{3, 4}));
  // Different names in left/ and right/ are frames without pairs.
  std::filesystem::rename(dir + "/right/img_b.png", dir + "/right/img_c.png");
  EXPECT_THAT(ErrorOf(dir, o), HasSubstr("no left image"));
}

TEST(Session, BadCellsAndHeaderAndStatus) {
  SessionReadOptions o;
  o.joint_names = {"j1", "j2"};
  EXPECT_THAT(
      ErrorOf(MakeSession("h", "frame,t_left,t_right,seq_left\n", 0), o),
      HasSubstr("frames.csv:1:"));
  EXPECT_THAT(
      ErrorOf(MakeSession("partial",
                          "frame,t_left,t_right,seq_left,seq_right,j1,j2\n"
                          "0,0,0,1,1,5,\n",
                          1),
              o),
      HasSubstr("frames.csv:2:13: joint 'j2' is empty"));
  EXPECT_THAT(
      ErrorOf(MakeSession("nan",
                          "frame,t_left,t_right,seq_left,seq_right,j1,j2\n"
                          "0,0,0,1,1,nan,1\n",
                          1),
              o),
      HasSubstr("frames.csv:2:11: joint 'j1': expected a finite number"));
  EXPECT_THAT(
      ErrorOf(MakeSession("dup",
                          "frame,t_left,t_right,seq_left,seq_right,j1,j2\n"
                          "0,0,0,1,1,1,1\n0,0,0,1,1,1,1\n",
                          1),
              o),
      HasSubstr("appears twice"));
  EXPECT_THAT(ErrorOf(MakeSession("st", kCsv, 3, "done"), o),
              HasSubstr("session.yaml:2:"));
  o.require_joint_readings = true;
  EXPECT_THAT(
      ErrorOf(MakeSession("noread",
                          "frame,t_left,t_right,seq_left,seq_right,j1,j2\n"
                          "0,0,0,1,1,,\n",
                          1),
              o),
      HasSubstr("no frame has joint readings"));
  EXPECT_THAT(ErrorOf(testing::MakeTempDir("empty"), o),
              HasSubstr("session.yaml: missing"));
}

}  // namespace
}  // namespace kincal
