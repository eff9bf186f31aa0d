// `kincal bundle` end to end on rendered recorded sessions (the spec's
// contract: flags, JSON fields, exit codes, nothing written on bad input),
// compared with the two-step pipeline (track -> calibrate) on the same
// images, both judged on noise-free true tips at fresh poses.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "tests/testing/fresh_poses.h"
#include "tests/testing/paths.h"
#include "tests/testing/run.h"

namespace kincal::testing {
namespace {

using ::testing::HasSubstr;

std::string Bh7() { return SourceDir() + "/data/robots/bh7.yaml"; }

std::string Simulate(const std::string& dir, int poses, int seed,
                     const std::string& extra = "") {
  const RunResult r = RunKincal(
      "simulate --robot " + Bh7() + " --out " + dir + " --poses " +
      std::to_string(poses) + " --noise 0 --seed " + std::to_string(seed) +
      " --render --render-noise 1.5 --render-blur 0.5 --render-width 640 "
      "--render-height 512 " +
      extra);
  EXPECT_EQ(r.exit_code, 0) << r.err;
  return dir;
}

std::string BundleArgs(const std::string& s, const std::string& robot) {
  return "bundle --robot " + robot + " --rig " + s + "/rig.yaml --target " + s +
         "/target.yaml --session " + s + "/session --quiet ";
}

TEST(BundleCli, BeatsTrackThenCalibrateOnTheSameImages) {
  const std::string dir = MakeTempDir("bundle");
  const std::string s = Simulate(dir + "/s", 120, 7);
  RunResult r = RunKincal(BundleArgs(s, s + "/robot.yaml") + "--out " + dir +
                          "/bcal.yaml --out-rig " + dir +
                          "/brig.yaml --out-obs " + dir + "/bobs.csv --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  for (const char* field :
       {"frames", "used_frames", "reproj_rms_px", "heldout_reproj_rms_px",
        "heldout_tip_rms_mm", "identifiable", "unidentifiable", "seconds"}) {
    EXPECT_TRUE(j.contains(field)) << field;
  }
  EXPECT_EQ(j["frames"].get<int>(), 120);
  EXPECT_GT(j["used_frames"].get<int>(), 30);
  // Corner noise of these renders is ~0.05-0.1 px.
  EXPECT_LT(j["reproj_rms_px"].get<double>(), 0.15);
  EXPECT_LT(j["heldout_reproj_rms_px"].get<double>(), 0.2);
  // Evenly lit tags: none weighed down as dim (side light: 0.15-0.18).
  std::printf("dim corner share %.3f\n", j["dim_corner_share"].get<double>());
  EXPECT_LT(j["dim_corner_share"].get<double>(), 0.05);
  EXPECT_TRUE(Exists(dir + "/brig.yaml"));

  // The two-step pipeline on the same images.
  r = RunKincal("track --rig " + s + "/rig.yaml --target " + s +
                "/target.yaml --session " + s + "/session --robot " + s +
                "/robot.yaml --out " + dir + "/pts.csv --out-obs " + dir +
                "/tracked.csv --quiet");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  r = RunKincal("calibrate --robot " + s + "/robot.yaml --obs " + dir +
                "/tracked.csv --out " + dir + "/tcal.yaml --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;

  // Fresh poses of the same true robot (same seed: same truth, the first
  // 120 poses are the rendered ones), noise-free tips.
  r = RunKincal("simulate --robot " + Bh7() + " --out " + dir +
                "/fresh --poses 320 --noise 0 --seed 7");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  KeepRowsFrom(dir + "/fresh/observations.csv", dir + "/fresh.csv", 120);
  const double bundle_rms = EvaluateRms(dir + "/bcal.yaml", dir + "/fresh.csv");
  const double two_step = EvaluateRms(dir + "/tcal.yaml", dir + "/fresh.csv");
  const double nominal = EvaluateRms(s + "/robot.yaml", dir + "/fresh.csv");
  std::printf(
      "fresh true tips: bundle %.4f mm, track+calibrate %.4f mm, nominal "
      "%.4f mm\n",
      bundle_rms, two_step, nominal);
  EXPECT_LT(bundle_rms, two_step);
  EXPECT_LT(bundle_rms, 0.1 * nominal);
  // The observations of what the cameras saw feed diagnose.
  r = RunKincal("diagnose model --robot " + s + "/robot.yaml --obs " + dir +
                "/bobs.csv --json");
  EXPECT_EQ(r.exit_code, 0) << r.err;
}

TEST(BundleCli, NamesAHiddenBacklashFromImages) {
  const std::string dir = MakeTempDir("bundle_bl");
  const std::string s =
      Simulate(dir + "/s", 160, 11, "--effect backlash:j3:0.05");
  const RunResult r =
      RunKincal(BundleArgs(s, s + "/robot.yaml") + "--out " + dir +
                "/bcal.yaml --extensions backlash --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j["findings"].size(), 1u) << j["extensions"].dump();
  EXPECT_EQ(j["findings"][0]["cause"], "backlash");
  EXPECT_EQ(j["findings"][0]["joint"], "j3");
  const auto ci = j["findings"][0]["ci95"];
  EXPECT_LT(ci[0].get<double>(), 0.05);
  EXPECT_GT(ci[1].get<double>(), 0.05);
}

// Progress on a terminal (forced with KINCAL_PROGRESS=1, stderr is a file
// here): tag detection per frame and the solve; --json keeps stderr clean.
TEST(BundleCli, ProgressOnStderrNotWithJson) {
  const std::string dir = MakeTempDir("bundle_progress");
  const std::string s = Simulate(dir + "/s", 24, 5);
  const std::string cmd =
      "KINCAL_PROGRESS=1 " + testing::KincalBinary() + " bundle --robot " + s +
      "/robot.yaml --rig " + s + "/rig.yaml --target " + s +
      "/target.yaml --session " + s + "/session --out " + dir + "/cal.yaml";
  RunResult r = RunShell(cmd);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(r.err, HasSubstr("kincal bundle: frames (detecting tags) 24/24"));
  EXPECT_THAT(r.err, HasSubstr("kincal bundle: solving the bundle"));
  r = RunShell(cmd + " --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(r.err, ::testing::Not(HasSubstr("kincal bundle:")));
}

// A target without a tip on a stand calibrates the target frame's origin:
// allowed (a board), but said, with what to do.
TEST(BundleCli, TargetWithoutTipOnAStandIsAWarning) {
  const std::string dir = MakeTempDir("bundle_notip");
  const std::string s = Simulate(dir + "/s", 12, 3);
  RunShell("grep -v '^tip_in_tool\\|^tip_sigma' " + s + "/target.yaml > " +
           dir + "/notip.yaml");
  const RunResult r =
      RunKincal("bundle --robot " + s + "/robot.yaml --rig " + s +
                "/rig.yaml --target " + dir + "/notip.yaml --session " + s +
                "/session --out " + dir + "/cal.yaml --quiet --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  bool found = false;
  for (const auto& w : j.at("warnings")) {
    found = found || w.at("code") == "target_without_tip";
  }
  EXPECT_TRUE(found) << r.out;
  EXPECT_THAT(r.err, HasSubstr("kincal target --pivot"));
}

TEST(BundleCli, BadInputExitsTwoAndWritesNothing) {
  const std::string dir = MakeTempDir("bundle_bad");
  const std::string s = Simulate(dir + "/s", 12, 3);
  const std::string out = dir + "/cal.yaml";
  auto run = [&](const std::string& robot, const std::string& session) {
    return RunKincal("bundle --robot " + robot + " --rig " + s +
                     "/rig.yaml --target " + s + "/target.yaml --session " +
                     session + " --out " + out + " --out-obs " + dir +
                     "/obs.csv --quiet --json");
  };
  // A session of another robot (joint names differ).
  RunShell("sed 's/name: j3/name: elbow/' " + s + "/robot.yaml > " + dir +
           "/other.yaml");
  RunResult r = run(dir + "/other.yaml", s + "/session");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.err, HasSubstr("another robot"));
  // Missing joint column.
  RunShell("cp -r " + s + "/session " + dir +
           "/nocol && sed -i "
           "'/^[^#]/s/,[^,]*$//' " +
           dir + "/nocol/frames.csv");
  r = run(s + "/robot.yaml", dir + "/nocol");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.err, HasSubstr("missing: j5"));
  // A frame without its pair.
  RunShell("cp -r " + s + "/session " + dir + "/nopair && rm " + dir +
           "/nopair/right/000004.png");
  r = run(s + "/robot.yaml", dir + "/nopair");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.err, HasSubstr("no right image"));
  // An unreadable image.
  RunShell("cp -r " + s + "/session " + dir + "/broken && echo x > " + dir +
           "/broken/left/000002.png");
  r = run(s + "/robot.yaml", dir + "/broken");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.err, HasSubstr("left/000002.png: cannot read"));
  EXPECT_FALSE(Exists(out));
  EXPECT_FALSE(Exists(dir + "/obs.csv"));
}

}  // namespace
}  // namespace kincal::testing
