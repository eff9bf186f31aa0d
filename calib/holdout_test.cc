#include "calib/holdout.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <set>

#include "calib/chain.h"
#include "data/robot.h"
#include "synth/simulate.h"
#include "tests/testing/paths.h"

namespace kincal {
namespace {

std::vector<int> Range(int n) {
  std::vector<int> v(n);
  for (int i = 0; i < n; ++i) v[i] = i;
  return v;
}

TEST(HoldoutTest, ShuffleIsSeededPermutation) {
  std::mt19937_64 a(1), b(1), c(2);
  const std::vector<int> x = ShuffledIndices(Range(30), &a);
  EXPECT_EQ(x, ShuffledIndices(Range(30), &b));
  EXPECT_NE(x, ShuffledIndices(Range(30), &c));
  EXPECT_EQ(std::set<int>(x.begin(), x.end()).size(), 30u);
  EXPECT_NE(x, Range(30));
}

TEST(HoldoutTest, HoldOutFirstTakesTheShuffledHead) {
  std::mt19937_64 rng(4), same(4);
  const HoldoutSplit s = HoldOutFirst(Range(20), 5, &rng);
  std::vector<int> order = ShuffledIndices(Range(20), &same);
  std::vector<int> head(order.begin(), order.begin() + 5);
  std::sort(head.begin(), head.end());
  EXPECT_EQ(s.heldout, head);
  EXPECT_EQ(s.train.size(), 15u);
  EXPECT_TRUE(std::is_sorted(s.train.begin(), s.train.end()));
  std::mt19937_64 r2(4);
  EXPECT_TRUE(HoldOutFirst(Range(4), -3, &r2).heldout.empty());
  EXPECT_EQ(HoldOutFirst(Range(4), 9, &r2).heldout.size(), 4u);
}

TEST(HoldoutTest, FoldsPartitionTheIndices) {
  std::multiset<int> held;
  for (int f = 0; f < 4; ++f) {
    const HoldoutSplit s = HoldOutFold(Range(22), 4, f, 7);
    EXPECT_EQ(s.heldout.size(), f < 2 ? 6u : 5u);
    EXPECT_EQ(s.train.size() + s.heldout.size(), 22u);
    held.insert(s.heldout.begin(), s.heldout.end());
  }
  const std::vector<int> all = Range(22);
  EXPECT_EQ(held, std::multiset<int>(all.begin(), all.end()));
}

TEST(HoldoutTest, MeasurementSplitIsSeededAndKeepsGroups) {
  SimulateOptions opt;
  opt.poses = 50;
  opt.noise_mm = 0.03;
  opt.seed = 9;
  const SimulatedSession s = Simulate(
      ReadRobotYaml(testing::SourceDir() + "/data/robots/bh7.yaml"), opt);
  ModelState state;
  state.chain = Chain::FromRobot(s.nominal);
  const auto ms = MakeMeasurements(state.chain, s.observations, &state);
  const HoldoutSplit a = SplitHoldout(ms, 0.2, 1);
  const HoldoutSplit b = SplitHoldout(ms, 0.2, 1);
  const HoldoutSplit c = SplitHoldout(ms, 0.2, 2);
  EXPECT_EQ(a.heldout, b.heldout);
  EXPECT_NE(a.heldout, c.heldout);
  EXPECT_EQ(a.heldout.size(), 10u);
  EXPECT_EQ(a.train.size() + a.heldout.size(), ms.size());
  // At least 10 measured training poses stay, whatever the fraction.
  EXPECT_EQ(SplitHoldout(ms, 0.89, 1).train.size(), 10u);
}

TEST(HoldoutTest, FixedPointGroupsKeepThreeTrainingPoses) {
  std::vector<Measurement> ms;
  for (int g = 0; g < 2; ++g) {
    for (int i = 0; i < 5; ++i) {
      Measurement m;
      m.kind = Measurement::kFixedPoint;
      m.point = g;
      ms.push_back(m);
    }
  }
  const HoldoutSplit s = SplitHoldout(ms, 0.8, 3);
  ASSERT_EQ(s.heldout.size(), 4u);
  int first_group = 0;
  for (int i : s.heldout) first_group += i < 5;
  EXPECT_EQ(first_group, 2);
}

}  // namespace
}  // namespace kincal
