#include "diagnose/compare.h"

#include <gtest/gtest.h>

#include "synth/simulate.h"
#include "data/error.h"
#include "tests/testing/paths.h"

namespace kincal {
namespace {

Robot Bh7() {
  return ReadRobotYaml(testing::SourceDir() + "/data/robots/bh7.yaml");
}

Observations Session(const std::string& effect, uint64_t seed) {
  const Robot bh7 = Bh7();
  SimulateOptions so;
  so.poses = 150;
  so.noise_mm = 0.03;
  so.seed = seed;
  if (!effect.empty()) so.effects = {ParseEffect(effect, bh7)};
  return Simulate(bh7, so).observations;
}

TEST(CompareTest, NormalQuantiles) {
  EXPECT_NEAR(NormalUpperQuantile(0.025), 1.959964, 1e-5);
  EXPECT_NEAR(NormalUpperQuantile(0.005), 2.575829, 1e-5);
  EXPECT_THROW(NormalUpperQuantile(0.0), InputError);
}

TEST(CompareTest, RepairedJ3IsChangedOthersNot) {
  // Before: 0.3 deg clearance in j3 (the seed's BH-7); after the repair none.
  const CompareResult r =
      CompareClearance(Bh7(), Session("backlash:j3:0.3", 21), Session("", 22));
  EXPECT_EQ(r.verdict, "changed");
  ASSERT_EQ(r.joints.size(), 5u);
  for (const JointClearanceChange& c : r.joints) {
    if (c.joint == "j3") {
      EXPECT_TRUE(c.changed);
      EXPECT_NEAR(c.before.value, 0.3, 0.05);
      EXPECT_NEAR(c.after.value, 0.0, 0.05);
      EXPECT_LT(c.before.ci_low, c.before.value);
    } else {
      EXPECT_FALSE(c.changed) << c.joint << " z " << c.z;
    }
  }
  const nlohmann::json j = CompareJson(r);
  EXPECT_EQ(j["verdict"], "changed");
  EXPECT_EQ(j["joints"][2]["joint"], "j3");
}

TEST(CompareTest, SameClearanceIsUnchanged) {
  const CompareResult r = CompareClearance(
      Bh7(), Session("backlash:j3:0.2", 23), Session("backlash:j3:0.2", 24));
  EXPECT_EQ(r.verdict, "unchanged");
}

}  // namespace
}  // namespace kincal
