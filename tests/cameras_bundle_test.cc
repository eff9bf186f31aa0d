// `kincal bundle` end to end with one, two and three cameras on a stand
// (format v3): sessions rendered by `simulate --render --render-cameras N`
// with a hidden true robot (same seed: same truth and poses), each bundle
// judged on noise-free true tips at fresh poses (`kincal evaluate`), the
// one- and three-camera figures against the stereo one on the same poses.

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

std::string Bh7() { return SourceDir() + "/data/robots/bh7.yaml"; }

constexpr int kPoses = 120;
constexpr int kSeed = 7;

// The session with `cameras` cameras on a stand, bundled, at fresh poses
// (RenderedBundleAtFreshPoses).
double BundleAtFreshPoses(const std::string& dir, int cameras,
                          nlohmann::json* json, const std::string& extra = "",
                          const std::string& bundle_extra = "") {
  return RenderedBundleAtFreshPoses(Bh7(), dir, kPoses, kSeed, cameras, json,
                                    std::string("") + extra, bundle_extra);
}

TEST(CamerasBundle, OneAndThreeCamerasWithinTwiceStereoAtFreshPoses) {
  const std::string dir = MakeTempDir("cameras_bundle");
  nlohmann::json j1, j2, j3;
  const double stereo = BundleAtFreshPoses(dir, 2, &j2);
  const double mono = BundleAtFreshPoses(dir, 1, &j1);
  const double three = BundleAtFreshPoses(dir, 3, &j3);
  std::printf(
      "fresh true tips: 1 camera %.4f mm, 2 cameras %.4f mm, 3 cameras %.4f "
      "mm\n",
      mono, stereo, three);
  EXPECT_LE(mono, 0.10);
  EXPECT_LE(three, 0.10);
  EXPECT_LE(mono, 2 * stereo);
  EXPECT_LE(three, 2 * stereo);
  EXPECT_EQ(j1["cameras"], 1);
  EXPECT_EQ(j3["cameras"], 3);
  // One camera: the held-out tips are one-camera tips, compared all the
  // same (a one-camera rig has no better ones).
  EXPECT_GT(j1["heldout_tips"].get<int>(), 0);
}

TEST(CamerasBundle, OneCameraNamesAHiddenBacklash) {
  const std::string dir = MakeTempDir("cameras_bundle_bl");
  nlohmann::json j;
  BundleAtFreshPoses(dir, 1, &j, "--effect backlash:j3:0.05",
                     "--extensions backlash");
  ASSERT_EQ(j["findings"].size(), 1u) << j["extensions"].dump();
  EXPECT_EQ(j["findings"][0]["cause"], "backlash");
  EXPECT_EQ(j["findings"][0]["joint"], "j3");
  const auto ci = j["findings"][0]["ci95"];
  EXPECT_LT(ci[0].get<double>(), 0.05);
  EXPECT_GT(ci[1].get<double>(), 0.05);
}

}  // namespace
}  // namespace kincal::testing
