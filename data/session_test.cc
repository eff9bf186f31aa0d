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
  EXPECT_EQ(s.cameras, (std::vector<std::string>{"left", "right"}));
  EXPECT_EQ(s.frames[2].seq[1], 22);
  EXPECT_DOUBLE_EQ(s.frames[2].t[0], 0.2);
  EXPECT_EQ(s.frames[1].images[0], dir + "/left/000001.png");
  EXPECT_EQ(s.frames[1].images[1], dir + "/right/000001.png");
  // Without a robot the joint columns are listed but not read.
  const Session plain = ReadSession(dir);
  EXPECT_EQ(plain.joint_columns, (std::vector<std::string>{"j1", "j2"}));
  EXPECT_FALSE(plain.frames[0].HasJoints());
}

TEST(Session, RawMosaicPatternsComeFromSessionYamlSources) {
  const std::string dir = MakeSession("mosaic", kCsv, 3);
  EXPECT_EQ(ReadSession(dir, {}).mosaics,
            (std::vector<std::string>{"", ""}));  // gray images
  Write(dir + "/session.yaml",
        "kincal_session: 1\nstatus: complete\nsources:\n"
        "  left: {uri: 'v4l2:/dev/video0?format=RGGB&bayer=raw', mosaic: "
        "RGGB}\n  right: {uri: 'v4l2:/dev/video1'}\n");
  EXPECT_EQ(ReadSession(dir, {}).mosaics,
            (std::vector<std::string>{"RGGB", ""}));
  Write(dir + "/session.yaml",
        "kincal_session: 1\nstatus: complete\nsources:\n"
        "  left: {mosaic: RGB}\n");
  EXPECT_THAT(ErrorOf(dir, {}),
              HasSubstr("session.yaml:4:18: sources.left.mosaic: expected "
                        "RGGB, GRBG, GBRG or BGGR"));
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
  EXPECT_EQ(s.frames[1].images[0], dir + "/left/img_b.png");
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

// A session with three cameras (format v3): folders named as the cameras,
// t_/seq_ columns found by name in any order, joints between them.
std::string MakeThreeCameraSession(const std::string& tag, int n) {
  const std::string dir = testing::MakeTempDir(tag);
  for (const char* cam : {"top", "side", "wrist"}) {
    std::filesystem::create_directories(dir + "/" + cam);
    for (int i = 0; i < n; ++i) {
      char name[32];
      std::snprintf(name, sizeof(name), "/%06d.png", i);
      Write(dir + "/" + cam + name, "x");
    }
  }
  Write(dir + "/frames.csv",
        "seq_side,j1,t_top,frame,t_side,seq_wrist,j2,seq_top,t_wrist\n"
        "5,1.5,0.0,0,0.01,7,-3,3,0.02\n"
        "6,2.5,0.1,1,0.11,8,4,4,0.12\n");
  Write(dir + "/session.yaml", "kincal_session: 1\nstatus: complete\n");
  return dir;
}

TEST(Session, ThreeCamerasWithColumnsInAnyOrder) {
  const std::string dir = MakeThreeCameraSession("three", 2);
  SessionReadOptions o;
  o.joint_names = {"j1", "j2"};
  const Session s = ReadSession(dir, o);
  EXPECT_EQ(s.cameras, (std::vector<std::string>{"top", "side", "wrist"}));
  EXPECT_EQ(s.joint_columns, (std::vector<std::string>{"j1", "j2"}));
  ASSERT_EQ(s.frames.size(), 2u);
  EXPECT_EQ(s.frames[1].seq, (std::vector<long long>{4, 6, 8}));
  EXPECT_EQ(s.frames[1].t, (std::vector<double>{0.1, 0.11, 0.12}));
  EXPECT_EQ(s.frames[1].q, (std::vector<double>{2.5, 4}));
  EXPECT_EQ(s.frames[0].images[2], dir + "/wrist/000000.png");
  // The rig's order decides the cameras' order.
  o.camera_names = {"wrist", "top", "side"};
  const Session r = ReadSession(dir, o);
  EXPECT_EQ(r.cameras, o.camera_names);
  EXPECT_EQ(r.frames[1].seq, (std::vector<long long>{8, 4, 6}));
  EXPECT_EQ(r.frames[0].images[0], dir + "/wrist/000000.png");
  // A rig with another camera set is named in the message.
  o.camera_names = {"top", "side"};
  EXPECT_THAT(ErrorOf(dir, o), HasSubstr("not in the rig: wrist"));
  o.camera_names = {"top", "side", "wrist", "extra"};
  EXPECT_THAT(ErrorOf(dir, o), HasSubstr("seq_<name> columns for: extra"));
  // A camera folder missing.
  o.camera_names.clear();
  std::filesystem::remove_all(dir + "/side");
  EXPECT_THAT(ErrorOf(dir, o),
              HasSubstr("missing image folder of camera 'side'"));
}

TEST(Session, VersionTwoSessionReadsForARigNamedOtherwise) {
  const std::string dir = MakeSession("v2names", kCsv, 3);
  SessionReadOptions o;
  o.camera_names = {"cam_a", "cam_b"};
  const Session s = ReadSession(dir, o);
  EXPECT_EQ(s.cameras, o.camera_names);
  EXPECT_EQ(s.folders, (std::vector<std::string>{"left", "right"}));
  EXPECT_EQ(s.frames[2].images[1], dir + "/right/000002.png");
  // ... but not for a three-camera rig.
  o.camera_names = {"cam_a", "cam_b", "cam_c"};
  EXPECT_THAT(ErrorOf(dir, o), HasSubstr("not the rig's"));
}

TEST(Session, WriterHeaderAndCameraNames) {
  EXPECT_EQ(SessionFramesHeader({"left", "right"}, {"j1"}),
            "frame,t_left,t_right,seq_left,seq_right,j1");
  EXPECT_EQ(SessionFramesHeader({"c0"}, {}), "frame,t_c0,seq_c0");
  EXPECT_NO_THROW(CheckSessionCameraName("cam-1.a_b", "rig.yaml"));
  EXPECT_THROW(CheckSessionCameraName("my cam", "rig.yaml"), InputError);
  EXPECT_THROW(CheckSessionCameraName("a/b", "rig.yaml"), InputError);
  EXPECT_THROW(CheckSessionCameraName("..", "rig.yaml"), InputError);
  EXPECT_THROW(CheckSessionCameraName("", "rig.yaml"), InputError);
}

}  // namespace
}  // namespace kincal
