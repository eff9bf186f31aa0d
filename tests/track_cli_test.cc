// End to end: render a few stereo frames with the library's renderer, run
// build/bin/kincal track on them, and compare points.csv with the truth.

#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "camcal/rig.h"
#include "data/atomic_file.h"
#include "synth/render.h"
#include "tests/testing/csv_rows.h"
#include "tests/testing/paths.h"
#include "tests/testing/run.h"

namespace kincal {
namespace {

using testing::ReadCsvRows;
using testing::RunKincal;
using testing::RunResult;

class TrackCli : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = testing::MakeTempDir("track_cli");
    const Rig rig = ExampleStereoRig(640, 512);
    RenderOptions o;
    o.blur_sigma_px = 0.7;
    o.noise_sigma = 1.5;
    o.exposure_jitter = 0.05;
    o.draw_needle = true;
    o.needle_base_in_tool = Eigen::Vector3d(0, 35, 10);
    poses_ = {ExampleToolPose(0), ExampleToolPose(1), ExampleToolPose(2),
              ExampleToolPose(3)};
    // Frame 4: the tool turned away (tags seen from behind): not found.
    Rigid3 away = ExampleToolPose(0);
    away.R =
        away.R *
        Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitY()).toRotationMatrix();
    poses_.push_back(away);
    RenderSession(rig, ExampleTarget(), poses_, o, 1, dir_ + "/session");
  }
  static std::string dir_;
  static std::vector<Rigid3> poses_;
};
std::string TrackCli::dir_;
std::vector<Rigid3> TrackCli::poses_;

std::string Args(const std::string& s, const std::string& out) {
  return "track --rig " + s + "/rig.yaml --target " + s +
         "/target.yaml --left '" + s + "/left_*.png' --right '" + s +
         "/right_*.png' --out " + out;
}

TEST_F(TrackCli, TipsMatchRenderedTruth) {
  const std::string s = dir_ + "/session";
  const std::string out = dir_ + "/points.csv";
  const RunResult r = RunKincal(Args(s, out) + " --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["frames"], 5);
  EXPECT_EQ(j["found"], 4);
  EXPECT_TRUE(j.contains("seconds"));
  EXPECT_NE(j["command"].get<std::string>().find("track"), std::string::npos);

  const auto rows = ReadCsvRows(out);
  ASSERT_EQ(rows.size(), 6u);  // header + 5 frames
  EXPECT_EQ(rows[0], (std::vector<std::string>{"frame", "x", "y", "z",
                                               "reproj_px", "tags"}));
  const Target target = ExampleTarget();
  for (int f = 0; f < 4; ++f) {
    const auto& row = rows[f + 1];
    ASSERT_EQ(row.size(), 6u);
    EXPECT_EQ(row[0], std::to_string(f));
    const Eigen::Vector3d tip(std::stod(row[1]), std::stod(row[2]),
                              std::stod(row[3]));
    const Eigen::Vector3d truth = poses_[f] * target.tip_in_tool;
    EXPECT_LT((tip - truth).norm(), 0.15) << "frame " << f;
    EXPECT_LT(std::stod(row[4]), 0.3);
    EXPECT_EQ(row[5], "8");
  }
  // Not found: empty x, y, z.
  EXPECT_EQ(rows[5][1], "");
  EXPECT_EQ(rows[5][3], "");
  // The provenance comment and the poses file.
  EXPECT_EQ(ReadFile(out).rfind("# written by kincal", 0), 0u);
  EXPECT_TRUE(testing::Exists(dir_ + "/points.poses.csv"));
}

// The two image folders given the wrong way round: exit 2 naming the
// swap, nothing written (the tips would not be there).
TEST_F(TrackCli, SwappedCamerasAreNamedAndNothingWritten) {
  const std::string s = dir_ + "/session";
  const std::string out = dir_ + "/swapped.csv";
  const RunResult r = RunKincal(
      "track --rig " + s + "/rig.yaml --target " + s + "/target.yaml --left '" +
      s + "/right_*.png' --right '" + s + "/left_*.png' --out " + out);
  EXPECT_EQ(r.exit_code, 2) << r.out;
  EXPECT_NE(r.err.find("look swapped"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("exchange --left and --right"), std::string::npos);
  EXPECT_FALSE(testing::Exists(out));
  EXPECT_FALSE(testing::Exists(dir_ + "/swapped.poses.csv"));
}

// A rig calibrated with the board in metres (translations 1000 times too
// small) and a target.yaml in mm: tags seen, no pose fits; refused naming
// the units, nothing written.
TEST_F(TrackCli, RigInMetresIsNamedAndNothingWritten) {
  const std::string s = dir_ + "/session";
  Rig rig = ReadRigYaml(s + "/rig.yaml");
  for (Camera& c : rig.cameras) c.cam_from_rig.t /= 1000.0;
  WriteRigYaml(dir_ + "/rig_in_metres.yaml", rig);
  const std::string out = dir_ + "/metres.csv";
  const RunResult r =
      RunKincal("track --rig " + dir_ + "/rig_in_metres.yaml --target " + s +
                "/target.yaml --left '" + s + "/left_*.png' --right '" + s +
                "/right_*.png' --out " + out);
  EXPECT_EQ(r.exit_code, 2) << r.out;
  EXPECT_NE(r.err.find("disagree on units"), std::string::npos) << r.err;
  EXPECT_FALSE(testing::Exists(out));
}

TEST_F(TrackCli, FullFrameModeGivesTheSameTips) {
  const std::string s = dir_ + "/session";
  const RunResult r =
      RunKincal(Args(s, dir_ + "/full.csv") + " --no-tracking --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto a = ReadCsvRows(dir_ + "/full.csv");
  EXPECT_EQ(nlohmann::json::parse(r.out)["found"], 4);
  ASSERT_EQ(a.size(), 6u);
  const RunResult t = RunKincal(Args(s, dir_ + "/tracked.csv") + " --json");
  ASSERT_EQ(t.exit_code, 0) << t.err;
  const auto b = ReadCsvRows(dir_ + "/tracked.csv");
  ASSERT_EQ(b.size(), 6u);
  for (int f = 1; f <= 4; ++f) {
    for (int i = 1; i <= 3; ++i) {
      EXPECT_NEAR(std::stod(a[f][i]), std::stod(b[f][i]), 0.01)
          << "frame " << f - 1;
    }
  }
}

TEST_F(TrackCli, BadInputExits2AndWritesNothing) {
  const std::string s = dir_ + "/session";
  // Broken target.yaml: message with file:line:column.
  const std::string bad_target = dir_ + "/bad_target.yaml";
  {
    std::ofstream f(bad_target);
    f << "kincal_target: 1\ntags:\n  - {id: 0, size: -1, tool_from_tag: "
         "{R: [1,0,0,0,1,0,0,0,1], t: [0,0,0]}}\ntip_in_tool: [0,0,0]\n";
  }
  const std::string out1 = dir_ + "/bad1.csv";
  RunResult r = RunKincal(
      "track --rig " + s + "/rig.yaml --target " + bad_target + " --left '" +
      s + "/left_*.png' --right '" + s + "/right_*.png' --out " + out1);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("bad_target.yaml:3:"), std::string::npos) << r.err;
  EXPECT_FALSE(testing::Exists(out1));

  // No image matches.
  const std::string out2 = dir_ + "/bad2.csv";
  r = RunKincal("track --rig " + s + "/rig.yaml --target " + s +
                "/target.yaml --left '" + s + "/nothing_*.png' --right '" + s +
                "/right_*.png' --out " + out2);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_FALSE(testing::Exists(out2));

  // Different numbers of left and right images.
  const std::string out3 = dir_ + "/bad3.csv";
  r = RunKincal("track --rig " + s + "/rig.yaml --target " + s +
                "/target.yaml " + "--left '" + s +
                "/left_00000[01].png' --right '" + s + "/right_*.png' --out " +
                out3);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_FALSE(testing::Exists(out3));

  // Missing required option.
  r = RunKincal("track --rig " + s + "/rig.yaml --out " + out3);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_FALSE(testing::Exists(out3));
}

}  // namespace
}  // namespace kincal
