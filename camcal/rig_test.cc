#include "camcal/rig.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>
#include <ostream>

#include "data/atomic_file.h"
#include "data/error.h"
#include "data/provenance.h"
#include "tests/testing/paths.h"

namespace kincal {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

const char* kSpecExample = R"(kincal_rig: 1
cameras:
  - name: left
    width: 1280
    height: 1024
    fx: 1800.0
    fy: 1800.0
    cx: 639.5
    cy: 511.5
    distortion: [-0.1, 0.05, 0.001, -0.002, 0.01]
    cam_from_rig: {R: [1,0,0, 0,1,0, 0,0,1], t: [0, 0, 0]}
  - name: right
    width: 1280
    height: 1024
    fx: 1805.5
    fy: 1801.0
    cx: 640.25
    cy: 512.0
    distortion: []
    cam_from_rig: {R: [0.99500417,0,-0.09983342, 0,1,0, 0.09983342,0,0.99500417], t: [-120, 0.5, 1]}
)";

TEST(RigYaml, ReadsSpecExample) {
  const Rig rig = ParseRigYaml(kSpecExample, "rig.yaml");
  ASSERT_EQ(rig.cameras.size(), 2u);
  const CameraIntrinsics& l = rig.cameras[0].intrinsics;
  EXPECT_EQ(l.name, "left");
  EXPECT_EQ(l.width, 1280);
  EXPECT_EQ(l.height, 1024);
  EXPECT_EQ(l.cx, 639.5);
  EXPECT_EQ(l.distortion.size(), 5u);
  EXPECT_EQ(l.distortion[3], -0.002);
  const Camera& r = rig.cameras[1];
  EXPECT_TRUE(r.intrinsics.distortion.empty());
  EXPECT_NEAR(r.cam_from_rig.R(0, 2), -0.09983342, 1e-7);  // row-major
  EXPECT_NEAR(r.cam_from_rig.R(2, 0), 0.09983342, 1e-7);
  EXPECT_NEAR((r.cam_from_rig.R.transpose() * r.cam_from_rig.R -
               Eigen::Matrix3d::Identity())
                  .norm(),
              0.0, 1e-14);
  EXPECT_EQ(r.cam_from_rig.t.x(), -120);
  // Right camera centre in rig = -R^T t.
  EXPECT_NEAR(rig.BaselineMm(), std::sqrt(120 * 120 + 0.25 + 1), 1e-5);
}

TEST(RigYaml, WriteReadRoundTripIsExact) {
  SetCommandLine("kincal camcal --test");
  Rig rig;
  Camera a;
  a.intrinsics = {
      "left", 640,    480,   811.123456789,
      806.5,  361.99, 214.4, {-0.12821, -0.39441, -0.00435, -0.00732}};
  Camera b;
  b.intrinsics = {
      "my cam: 2", 640, 480, 1e3 / 3,
      2e3 / 3,     320, 240, {0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8}};
  b.cam_from_rig.R =
      Eigen::AngleAxisd(0.1, Eigen::Vector3d(0.3, 1, 0.2).normalized())
          .toRotationMatrix();
  b.cam_from_rig.t = Eigen::Vector3d(-3.34, 0.0123, 0.1 / 3);
  b.valid_intrinsics_region = {
      {10.5, 20}, {600, 1.0 / 3}, {320, 470}, {10.5, 20}};
  rig.cameras = {a, b};
  const std::string dir = testing::MakeTempDir("rig");
  const std::string path = dir + "/rig.yaml";
  WriteRigYaml(path, rig);
  const std::string text = ReadFile(path);
  EXPECT_THAT(text, HasSubstr("# written by kincal"));
  EXPECT_THAT(text, HasSubstr("kincal camcal --test"));
  const Rig back = ReadRigYaml(path);
  ASSERT_EQ(back.cameras.size(), 2u);
  for (int i = 0; i < 2; ++i) {
    const CameraIntrinsics& x = rig.cameras[i].intrinsics;
    const CameraIntrinsics& y = back.cameras[i].intrinsics;
    EXPECT_EQ(x.name, y.name);
    EXPECT_EQ(x.width, y.width);
    EXPECT_EQ(x.fx, y.fx);
    EXPECT_EQ(x.fy, y.fy);
    EXPECT_EQ(x.cx, y.cx);
    EXPECT_EQ(x.cy, y.cy);
    EXPECT_EQ(x.distortion, y.distortion);
    EXPECT_LT(
        (rig.cameras[i].cam_from_rig.R - back.cameras[i].cam_from_rig.R).norm(),
        1e-15);
    EXPECT_EQ(rig.cameras[i].cam_from_rig.t, back.cameras[i].cam_from_rig.t);
    EXPECT_EQ(rig.cameras[i].valid_intrinsics_region,
              back.cameras[i].valid_intrinsics_region);
  }
  EXPECT_THAT(text, Not(HasSubstr("valid_intrinsics_region: []")));
}

struct BadCase {
  const char* what;
  const char* text;
  int line;
  const char* message;
};

// Names the case in test output and in ctest's test names (which otherwise
// show the struct's bytes, different in every build).
void PrintTo(const BadCase& c, std::ostream* os) { *os << c.what; }

class RigYamlRejects : public ::testing::TestWithParam<BadCase> {};

TEST_P(RigYamlRejects, WithFileLineColumn) {
  const BadCase& c = GetParam();
  try {
    ParseRigYaml(c.text, "bad.yaml");
    FAIL() << c.what << ": accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), "bad.yaml");
    EXPECT_EQ(e.line(), c.line) << e.what();
    EXPECT_GT(e.column(), 0) << e.what();
    EXPECT_THAT(e.what(), HasSubstr(c.message));
  }
}

#define CAM0                                                                 \
  "  - {name: left, width: 640, height: 480, fx: 800, fy: 800, cx: "         \
  "320, cy: 240, distortion: [], cam_from_rig: {R: [1,0,0,0,1,0,0,0,1], t: " \
  "[0,0,0]}}\n"

INSTANTIATE_TEST_SUITE_P(
    Cases, RigYamlRejects,
    ::testing::Values(
        BadCase{"version", "kincal_rig: 2\ncameras: []\n", 1, "version 1"},
        BadCase{"unknown top key", "kincal_rig: 1\ncamera: []\n", 2,
                "unknown key 'camera'"},
        BadCase{"no cameras", "kincal_rig: 1\ncameras: []\n", 2,
                "at least one camera"},
        BadCase{"distortion count",
                "kincal_rig: 1\ncameras:\n  - {name: l, width: 640, height: "
                "480, fx: 800, fy: 800, cx: 320, cy: 240, distortion: [1,2,3], "
                "cam_from_rig: {R: [1,0,0,0,1,0,0,0,1], t: [0,0,0]}}\n",
                3, "0, 4, 5 or 8"},
        BadCase{"region pair",
                "kincal_rig: 1\ncameras:\n  - {name: l, width: 640, height: "
                "480, fx: 800, fy: 800, cx: 320, cy: 240, distortion: [], "
                "cam_from_rig: {R: [1,0,0,0,1,0,0,0,1], t: [0,0,0]},\n"
                "     valid_intrinsics_region: [[1, 2], [3, 4, 5]]}\n",
                4, "valid_intrinsics_region"},
        BadCase{"negative fx",
                "kincal_rig: 1\ncameras:\n  - {name: l, width: 640, height: "
                "480, fx: -800, fy: 800, cx: 320, cy: 240, distortion: [], "
                "cam_from_rig: {R: [1,0,0,0,1,0,0,0,1], t: [0,0,0]}}\n",
                3, "positive"},
        BadCase{"missing fy",
                "kincal_rig: 1\ncameras:\n  - {name: l, width: 640, height: "
                "480, fx: 800, cx: 320, cy: 240, distortion: [], "
                "cam_from_rig: {R: [1,0,0,0,1,0,0,0,1], t: [0,0,0]}}\n",
                3, "missing required key 'fy'"},
        BadCase{"text number",
                "kincal_rig: 1\ncameras:\n  - {name: l, width: 640, height: "
                "480, fx: abc, fy: 800, cx: 320, cy: 240, distortion: [], "
                "cam_from_rig: {R: [1,0,0,0,1,0,0,0,1], t: [0,0,0]}}\n",
                3, "expected a number"},
        BadCase{"not a rotation",
                "kincal_rig: 1\ncameras:\n" CAM0
                "  - {name: r, width: 640, height: 480, fx: 800, fy: 800, cx: "
                "320, cy: 240, distortion: [], cam_from_rig: {R: "
                "[1,0,0,0,1,0,0,0,-1], t: [1,0,0]}}\n",
                4, "rotation"},
        BadCase{"first camera not identity",
                "kincal_rig: 1\ncameras:\n  - {name: l, width: 640, height: "
                "480, fx: 800, fy: 800, cx: 320, cy: 240, distortion: [], "
                "cam_from_rig: {R: [1,0,0,0,1,0,0,0,1], t: [5,0,0]}}\n",
                3, "first camera"},
        BadCase{"duplicate name", "kincal_rig: 1\ncameras:\n" CAM0 CAM0, 4,
                "duplicate"},
        BadCase{"R count",
                "kincal_rig: 1\ncameras:\n  - {name: l, width: 640, height: "
                "480, fx: 800, fy: 800, cx: 320, cy: 240, distortion: [], "
                "cam_from_rig: {R: [1,0,0,0,1,0,0,0], t: [0,0,0]}}\n",
                3, "expected 9 numbers"},
        BadCase{"mount", "kincal_rig: 1\nmount: wrist\ncameras:\n" CAM0, 2,
                "mount: expected world"},
        BadCase{"yaml syntax", "kincal_rig: 1\ncameras: [\n", 3,
                "invalid YAML"}));

// Format v3: 1..N cameras and `mount`; world is the default and is not
// written, flange round-trips.
TEST(RigYaml, MountAndThreeCameras) {
  const std::string cams = std::string(CAM0) +
                           "  - {name: mid, width: 640, height: 480, fx: 800, "
                           "fy: 800, cx: 320, cy: 240, distortion: [], "
                           "cam_from_rig: {R: [1,0,0,0,1,0,0,0,1], t: "
                           "[-100,0,0]}}\n"
                           "  - {name: far, width: 640, height: 480, fx: 800, "
                           "fy: 800, cx: 320, cy: 240, distortion: [], "
                           "cam_from_rig: {R: [1,0,0,0,1,0,0,0,1], t: "
                           "[-200,0,0]}}\n";
  const Rig world = ParseRigYaml("kincal_rig: 1\ncameras:\n" + cams, "a");
  EXPECT_EQ(world.mount, RigMount::kWorld);
  ASSERT_EQ(world.cameras.size(), 3u);
  EXPECT_EQ(world.FindCamera("far"), 2);
  EXPECT_EQ(world.FindCamera("nope"), -1);
  EXPECT_EQ(world.CameraNames(),
            (std::vector<std::string>{"left", "mid", "far"}));
  EXPECT_THAT(RigToYaml(world), Not(HasSubstr("mount")));
  EXPECT_EQ(
      ParseRigYaml("kincal_rig: 1\nmount: world\ncameras:\n" + cams, "b").mount,
      RigMount::kWorld);
  const Rig flange =
      ParseRigYaml("kincal_rig: 1\nmount: flange\ncameras:\n" + cams, "c");
  EXPECT_EQ(flange.mount, RigMount::kFlange);
  EXPECT_STREQ(RigMountName(flange.mount), "flange");
  const Rig back = ParseRigYaml(RigToYaml(flange), "d");
  EXPECT_EQ(back.mount, RigMount::kFlange);
  EXPECT_EQ(back.cameras.size(), 3u);
}

TEST(RigYaml, EmptyFileIsInputError) {
  EXPECT_THROW(ParseRigYaml("", "empty.yaml"), InputError);
  EXPECT_THROW(ReadRigYaml("/nonexistent/rig.yaml"), InputError);
}

}  // namespace
}  // namespace kincal
