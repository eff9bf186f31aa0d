#include "diagnose/compare.h"

#include <gtest/gtest.h>

#include "data/error.h"
#include "synth/simulate.h"
#include "tests/testing/iso9283_cycles.h"
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
  EXPECT_FALSE(j.contains("iso9283"));  // no fixed_point labels
  EXPECT_EQ(CompareIso9283Text(r), "");
}

TEST(CompareTest, SameClearanceIsUnchanged) {
  const CompareResult r = CompareClearance(
      Bh7(), Session("backlash:j3:0.2", 23), Session("backlash:j3:0.2", 24));
  EXPECT_EQ(r.verdict, "unchanged");
}

// A session of random poses followed by ISO 9283 cycles in the same
// measuring frame; the cycles approach every pose alternately from both
// sides of j3, so its clearance b shows in RP (|d| / 2 + 3 sigma,
// diagnose/iso9283_test.cc).
Observations SessionWithIsoCycles(double j3_clearance_deg, uint64_t seed) {
  const Robot bh7 = Bh7();
  testing::IsoSimulation iso = testing::Bh7IsoSimulation();
  iso.backlash_joint = 2;
  iso.backlash_deg = j3_clearance_deg;
  iso.via_delta_deg = 5.0;
  iso.noise_mm = 0.03;
  iso.seed = seed;
  SimulateOptions so;
  so.poses = 150;
  so.noise_mm = 0.03;
  so.seed = seed;
  so.meas_from_base = PoseBlockFromRigid3(iso.meas_from_base);
  if (j3_clearance_deg > 0) {
    so.effects = {
        ParseEffect("backlash:j3:" + std::to_string(j3_clearance_deg), bh7)};
  }
  Observations obs = Simulate(bh7, so).observations;
  for (const Observation& o : testing::SimulateIsoCycles(bh7, iso).rows) {
    obs.rows.push_back(o);
  }
  return obs;
}

TEST(CompareTest, IsoFiguresBeforeAndAfterWhenBothHaveCycles) {
  const CompareResult r = CompareClearance(Bh7(), SessionWithIsoCycles(0.3, 31),
                                           SessionWithIsoCycles(0.0, 32));
  EXPECT_EQ(r.verdict, "changed");
  ASSERT_TRUE(r.has_iso9283);
  ASSERT_EQ(r.iso9283_before.poses.size(), 5u);
  ASSERT_EQ(r.iso9283_after.poses.size(), 5u);
  // b = 0.3 deg on j3 flipping every cycle: RP rises by the tip shift of
  // b / 2 (tenths of a mm); after the repair RP is the noise's, about 3.6
  // sigma = 0.11 mm.
  EXPECT_GT(r.iso9283_before.rp_max_mm, 0.3);
  EXPECT_LT(r.iso9283_after.rp_max_mm, 0.16);
  const nlohmann::json j = CompareJson(r);
  ASSERT_TRUE(j.contains("iso9283"));
  EXPECT_EQ(j["iso9283"]["poses"].size(), 5u);
  EXPECT_EQ(j["iso9283"]["poses"][0]["pose"], "P1");
  EXPECT_DOUBLE_EQ(j["iso9283"]["rp_max_before_mm"].get<double>(),
                   r.iso9283_before.rp_max_mm);
  EXPECT_DOUBLE_EQ(j["iso9283"]["poses"][0]["rp_after_mm"].get<double>(),
                   r.iso9283_after.poses[0].rp_mm);
  EXPECT_NE(CompareIso9283Text(r).find("RP before"), std::string::npos);
}

// ISO cycles alone: approached alternately from both sides of j2, the
// cycles determine j2's clearance (changed after the repair); under the
// standard's unidirectional cycle no clearance is determined and the
// comparison is the ISO figures' (verdict not_determined); without labels
// that is exit 2.
TEST(CompareTest, IsoCyclesAloneCompareTheIsoFigures) {
  const Robot bh7 = Bh7();
  testing::IsoSimulation worn = testing::Bh7IsoSimulation();
  worn.backlash_deg = 0.1;
  worn.via_delta_deg = 5.0;
  testing::IsoSimulation repaired = worn;
  repaired.backlash_deg = 0.0;
  repaired.seed = 8;
  const CompareResult flipping =
      CompareClearance(bh7, testing::SimulateIsoCycles(bh7, worn),
                       testing::SimulateIsoCycles(bh7, repaired));
  EXPECT_EQ(flipping.verdict, "changed");
  for (const JointClearanceChange& c : flipping.joints) {
    EXPECT_EQ(c.changed, c.joint == "j2") << c.joint;
  }
  ASSERT_TRUE(flipping.has_iso9283);
  EXPECT_GT(flipping.iso9283_before.rp_max_mm, 0.15);
  EXPECT_LT(flipping.iso9283_after.rp_max_mm, 0.05);

  worn.via_delta_deg = 0.0;
  repaired.via_delta_deg = 0.0;
  const Observations standard_worn = testing::SimulateIsoCycles(bh7, worn);
  const CompareResult standard = CompareClearance(
      bh7, standard_worn, testing::SimulateIsoCycles(bh7, repaired));
  EXPECT_EQ(standard.verdict, "not_determined");
  ASSERT_TRUE(standard.has_iso9283);
  EXPECT_LT(standard.iso9283_before.rp_max_mm, 0.05);
  const nlohmann::json j = CompareJson(standard);
  EXPECT_TRUE(j["z_critical"].is_null());
  for (const auto& joint : j["joints"]) EXPECT_FALSE(joint["changed"]);
  Observations unlabelled = standard_worn;
  for (Observation& o : unlabelled.rows) o.fixed_point.clear();
  EXPECT_THROW(CompareClearance(bh7, unlabelled, unlabelled), InputError);
}

}  // namespace
}  // namespace kincal
