// End to end, 1..N cameras (../shared/spec/formats.md v3): sessions rendered
// with one folder per camera of a three-camera and a one-camera rig, run
// through build/bin/kincal track with --session and --camera NAME=GLOB, the
// tips compared with the rendered truth; a camera that never sees the
// target (track, and bundle on a rendered robot session), and camcal's
// cameras that share no board view, are refused naming the camera (exit 2,
// nothing written).

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "camcal/rig.h"
#include "data/atomic_file.h"
#include "synth/recorded_session.h"
#include "synth/render.h"
#include "tests/testing/csv_rows.h"
#include "tests/testing/paths.h"
#include "tests/testing/run.h"

namespace kincal {
namespace {

using testing::ReadCsvRows;
using testing::RunKincal;
using testing::RunResult;

// ExampleStereoRig and a third camera "top" 120 mm above the first, turned
// down towards the tool (about 450 mm away).
Rig ThreeCameraRig() {
  Rig rig = ExampleStereoRig(640, 512);
  Camera top = rig.cameras[0];
  top.intrinsics.name = "top";
  top.intrinsics.cx += 4.0;
  top.cam_from_rig.R =
      Eigen::AngleAxisd(std::atan2(120.0, 450.0), Eigen::Vector3d::UnitX())
          .toRotationMatrix();
  top.cam_from_rig.t = -(top.cam_from_rig.R * Eigen::Vector3d(60, -120, 0));
  rig.cameras.push_back(top);
  return rig;
}

Rig OnlyFirstCamera(const Rig& rig) {
  Rig mono;
  mono.cameras.push_back(rig.cameras[0]);
  return mono;
}

RenderOptions Effects() {
  RenderOptions o;
  o.blur_sigma_px = 0.7;
  o.noise_sigma = 1.5;
  o.exposure_jitter = 0.05;
  return o;
}

class CamerasCli : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = testing::MakeTempDir("cameras_cli");
    const Rig rig = ThreeCameraRig();
    WriteRigYaml(dir_ + "/rig3.yaml", rig);
    WriteRigYaml(dir_ + "/rig1.yaml", OnlyFirstCamera(rig));
    WriteTargetYaml(dir_ + "/target.yaml", ExampleTarget());
    RecordedSessionInput in;
    for (int i = 0; i < 6; ++i) in.rig_from_tool.push_back(ExampleToolPose(i));
    RenderRecordedSession(rig, ExampleTarget(), in, Effects(), 3,
                          dir_ + "/three");
    RenderRecordedSession(OnlyFirstCamera(rig), ExampleTarget(), in, Effects(),
                          4, dir_ + "/mono");
  }
  static Eigen::Vector3d Truth(int f) {
    return ExampleToolPose(f) * ExampleTarget().tip_in_tool;
  }
  static std::string dir_;
};
std::string CamerasCli::dir_;

// The session's folders are the rig's camera names and frames.csv holds
// t_<name>, seq_<name> for each.
TEST_F(CamerasCli, SessionHasOneFolderPerCameraNamedAsInTheRig) {
  for (const char* cam : {"left", "right", "top"}) {
    EXPECT_TRUE(std::filesystem::is_directory(dir_ + "/three/" + cam)) << cam;
  }
  const std::string frames = ReadFile(dir_ + "/three/frames.csv");
  EXPECT_NE(frames.find("frame,t_left,t_right,t_top,seq_left,seq_right,"
                        "seq_top\n"),
            std::string::npos)
      << frames;
}

TEST_F(CamerasCli, ThreeCamerasTrackTheTipFromTheSessionAndFromGlobs) {
  const std::string out = dir_ + "/three.csv";
  const RunResult r = RunKincal("track --rig " + dir_ + "/rig3.yaml --target " +
                                dir_ + "/target.yaml --session " + dir_ +
                                "/three --out " + out + " --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["frames"], 6);
  EXPECT_EQ(j["cameras"], 3);
  EXPECT_EQ(j["good"], 6);
  EXPECT_EQ(j["full_searches"].size(), 3u);
  const auto rows = ReadCsvRows(out);
  ASSERT_EQ(rows.size(), 7u);
  for (int f = 0; f < 6; ++f) {
    const Eigen::Vector3d tip(std::stod(rows[f + 1][1]),
                              std::stod(rows[f + 1][2]),
                              std::stod(rows[f + 1][3]));
    EXPECT_LT((tip - Truth(f)).norm(), 0.15) << "frame " << f;
    // Up to 4 tags x 3 cameras; more than two cameras' worth used.
    EXPECT_GE(std::stoi(rows[f + 1][5]), 9) << "frame " << f;
  }
  // The same images through --camera, given in another order than the rig's:
  // the same tips.
  const std::string out2 = dir_ + "/three_globs.csv";
  const RunResult g =
      RunKincal("track --rig " + dir_ + "/rig3.yaml --target " + dir_ +
                "/target.yaml --camera top='" + dir_ +
                "/three/top/*.png' --camera left='" + dir_ +
                "/three/left/*.png' --camera right='" + dir_ +
                "/three/right/*.png' --out " + out2 + " --no-tracking");
  ASSERT_EQ(g.exit_code, 0) << g.err;
  const auto rows2 = ReadCsvRows(out2);
  ASSERT_EQ(rows2.size(), rows.size());
  for (int f = 0; f < 6; ++f) {
    for (int k = 1; k <= 3; ++k) {
      EXPECT_NEAR(std::stod(rows2[f + 1][k]), std::stod(rows[f + 1][k]), 0.02);
    }
  }
}

// One camera: the tool pose from PnP over all tags' corners; the tip passes
// the gate (nothing better exists on a one-camera rig) and carries its depth
// sigma, which must cover the actual error.
TEST_F(CamerasCli, OneCameraTipsAreValidWithAnHonestDepthSigma) {
  const std::string out = dir_ + "/mono.csv";
  const RunResult r = RunKincal("track --rig " + dir_ + "/rig1.yaml --target " +
                                dir_ + "/target.yaml --camera left='" + dir_ +
                                "/mono/left/*.png' --out " + out + " --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["cameras"], 1);
  EXPECT_EQ(j["good"], 6);
  const double sigma = j["median_depth_sigma_mm"].get<double>();
  EXPECT_GT(sigma, 0.01);
  EXPECT_LT(sigma, 2.0);
  const auto poses = ReadCsvRows(dir_ + "/mono.poses.csv");
  ASSERT_EQ(poses[0][16], "depth_sigma_mm");
  const auto rows = ReadCsvRows(out);
  double ss = 0, ss_sigma = 0;
  for (int f = 0; f < 6; ++f) {
    const Eigen::Vector3d tip(std::stod(rows[f + 1][1]),
                              std::stod(rows[f + 1][2]),
                              std::stod(rows[f + 1][3]));
    const double s = std::stod(poses[f + 1][16]);
    EXPECT_LT((tip - Truth(f)).norm(), 4 * s + 0.1) << "frame " << f;
    ss += (tip - Truth(f)).squaredNorm();
    ss_sigma += s * s;
  }
  // One camera is far weaker in depth than three: its error is larger.
  EXPECT_GT(std::sqrt(ss / 6), 0.0);
  EXPECT_GT(std::sqrt(ss_sigma / 6), 0.02);
}

// A camera whose images never show a target tag: exit 2 naming it.
TEST_F(CamerasCli, CameraThatNeverSeesTheTargetIsNamed) {
  Rig rig = ThreeCameraRig();
  // "top" turned round: it looks away from the tool.
  rig.cameras[2].cam_from_rig.R =
      Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitY()).toRotationMatrix() *
      rig.cameras[2].cam_from_rig.R;
  const std::string s = dir_ + "/blind";
  RecordedSessionInput in;
  for (int i = 0; i < 3; ++i) in.rig_from_tool.push_back(ExampleToolPose(i));
  RenderRecordedSession(rig, ExampleTarget(), in, Effects(), 5, s);
  WriteRigYaml(dir_ + "/rig_blind.yaml", rig);
  const RunResult r = RunKincal(
      "track --rig " + dir_ + "/rig_blind.yaml --target " + dir_ +
      "/target.yaml --session " + s + " --out " + dir_ + "/blind.csv");
  EXPECT_EQ(r.exit_code, 2) << r.out;
  EXPECT_NE(r.err.find("camera 'top'"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("never shows a tag"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("(" + s + "/top)"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("leave the camera out of the rig"), std::string::npos)
      << r.err;
  EXPECT_FALSE(testing::Exists(dir_ + "/blind.csv"));
}

// bundle refuses the same way before any solve: a session whose right
// camera's images show no tag (overwritten with grey of the same size).
TEST_F(CamerasCli, BundleNamesACameraThatNeverSeesTheTarget) {
  const std::string s = dir_ + "/sim";
  RunResult r = RunKincal("simulate --robot " + testing::SourceDir() +
                          "/data/robots/bh7.yaml --out " + s +
                          " --poses 12 --noise 0 --seed 3 --render "
                          "--render-width 640 --render-height 512");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  int blanked = 0;
  for (const auto& e :
       std::filesystem::directory_iterator(s + "/session/right")) {
    const cv::Mat image = cv::imread(e.path().string(), cv::IMREAD_UNCHANGED);
    ASSERT_FALSE(image.empty()) << e.path();
    cv::imwrite(e.path().string(),
                cv::Mat(image.size(), image.type(), cv::Scalar::all(128)));
    ++blanked;
  }
  ASSERT_EQ(blanked, 12);
  const std::string out = dir_ + "/sim_cal.yaml";
  r = RunKincal("bundle --robot " + s + "/robot.yaml --rig " + s +
                "/rig.yaml --target " + s + "/target.yaml --session " + s +
                "/session --out " + out + " --quiet");
  EXPECT_EQ(r.exit_code, 2) << r.out << r.err;
  EXPECT_NE(r.err.find("camera 'right'"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("never shows a tag"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("(" + s + "/session/right)"), std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("joint readings of " + s + "/session"),
            std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("leave the camera out of the rig"), std::string::npos)
      << r.err;
  EXPECT_FALSE(testing::Exists(out));
}

TEST_F(CamerasCli, CameraOptionsNameTheProblem) {
  const std::string base = "track --rig " + dir_ + "/rig3.yaml --target " +
                           dir_ + "/target.yaml --out " + dir_ + "/x.csv ";
  const std::string imgs = "='" + dir_ + "/three/left/*.png'";
  RunResult r = RunKincal(base + "--camera left" + imgs + " --camera right" +
                          imgs + " --camera side" + imgs);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("camera 'top'"), std::string::npos) << r.err;
  r = RunKincal(base + "--camera left" + imgs + " --camera right" + imgs +
                " --camera top" + imgs + " --camera side" + imgs);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("no camera 'side'"), std::string::npos) << r.err;
  r = RunKincal(base + "--camera left");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("expected NAME=GLOB"), std::string::npos) << r.err;
  r = RunKincal(base + "--left '" + dir_ + "/three/left/*.png' --right '" +
                dir_ + "/three/right/*.png'");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("3 cameras but --left/--right give 2"),
            std::string::npos)
      << r.err;
  EXPECT_FALSE(testing::Exists(dir_ + "/x.csv"));
}

// camcal with three cameras on OpenCV's stereo set: "c" sees the board
// only in views where "a" and "b" see nothing (blank images), so no shared
// view connects it: exit 2 naming it, `unconnected` in the JSON, no rig.
TEST(CamerasCamcal, CameraSharingNoBoardViewIsNamed) {
  KINCAL_REQUIRE_SHARED_DATA("opencv-stereo-left-right");
  const std::string src =
      testing::SharedDataDir() + "/opencv-stereo-left-right";
  const std::string dir = testing::MakeTempDir("camcal_unconnected");
  for (const char* cam : {"a", "b", "c"}) {
    std::filesystem::create_directories(dir + "/" + cam);
  }
  const cv::Mat sample = cv::imread(src + "/left01.jpg");
  ASSERT_FALSE(sample.empty());
  const cv::Mat blank(sample.size(), sample.type(), cv::Scalar(128, 128, 128));
  const int views[] = {1, 2, 3, 4, 5, 6, 7, 8, 9, 11, 12, 13, 14};
  int k = 0;
  for (int v : views) {
    char name[32], out[32];
    std::snprintf(name, sizeof(name), "%02d.jpg", v);
    std::snprintf(out, sizeof(out), "/%02d.png", k);
    const cv::Mat left = cv::imread(src + "/left" + name);
    const cv::Mat right = cv::imread(src + "/right" + name);
    const bool first_half = k < 7;
    cv::imwrite(dir + "/a" + out, first_half ? left : blank);
    cv::imwrite(dir + "/b" + out, first_half ? right : blank);
    cv::imwrite(dir + "/c" + out, first_half ? blank : left);
    ++k;
  }
  const RunResult r =
      RunKincal("camcal --camera a='" + dir + "/a/*.png' --camera b='" + dir +
                "/b/*.png' --camera c='" + dir +
                "/c/*.png' --target chessboard:9x6:1 "
                "--out " +
                dir + "/rig.yaml --json");
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("camera 'c' never sees the target in the same view"),
            std::string::npos)
      << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["unconnected"], nlohmann::json::array({"c"}));
  EXPECT_FALSE(testing::Exists(dir + "/rig.yaml"));
}

}  // namespace
}  // namespace kincal
