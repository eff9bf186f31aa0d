#include "plan/coverage.h"

#include <gtest/gtest.h>

#include <random>

namespace kincal {
namespace {

// Two joints: a revolute one over two turns (covered on the circle) and a
// prismatic one over [0, 100] mm (ends count).
Robot TwoJoints() {
  Robot r;
  RobotRow a;
  a.name = "turn";
  a.lower = -360;
  a.upper = 360;
  RobotRow b;
  b.name = "slide";
  b.type = JointType::kPrismatic;
  b.lower = 0;
  b.upper = 100;
  r.joints = {a, b};
  return r;
}

TEST(CoverageTest, LargestGapOnTheCircleAndAlongTheTravel) {
  const Robot r = TwoJoints();
  // Readings -350 and 10 are the same angle; 90 and 180 leave 190 round.
  const std::vector<std::vector<double>> poses = {
      {-350, 20}, {10, 30}, {90, 95}, {180, 60}};
  const std::vector<JointCoverage> c = TravelCoverage(r, poses);
  ASSERT_EQ(c.size(), 2u);
  EXPECT_TRUE(c[0].circular);
  EXPECT_DOUBLE_EQ(c[0].from, 180);
  EXPECT_DOUBLE_EQ(c[0].to, 370);
  EXPECT_DOUBLE_EQ(c[0].Gap(), 190);
  EXPECT_TRUE(c[0].wide);
  EXPECT_FALSE(c[1].circular);
  EXPECT_DOUBLE_EQ(c[1].from, 60);  // 60..95 beats 30..60 and the end 0..20
  EXPECT_DOUBLE_EQ(c[1].to, 95);
  EXPECT_TRUE(c[1].wide);
  // Readings in the middle only: the longer end is the gap.
  const std::vector<JointCoverage> middle =
      TravelCoverage(r, {{0, 50}, {0, 60}});
  EXPECT_DOUBLE_EQ(middle[1].from, 0);
  EXPECT_DOUBLE_EQ(middle[1].to, 50);
  // No pose: the whole travel.
  const std::vector<JointCoverage> none = TravelCoverage(r, {});
  EXPECT_DOUBLE_EQ(none[1].Gap(), 100);
  EXPECT_DOUBLE_EQ(none[0].Gap(), 360);
}

TEST(CoverageTest, DesignSpreadsEveryJointOverItsTravel) {
  const Robot r = TwoJoints();
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> turn(-360, 360), slide(0, 100);
  std::vector<std::vector<double>> candidates;
  for (int i = 0; i < 2000; ++i) candidates.push_back({turn(rng), slide(rng)});
  const int n = 30;
  const std::vector<int> chosen = CoverageDesign(r, candidates, n);
  ASSERT_EQ(static_cast<int>(chosen.size()), n);
  std::vector<std::vector<double>> design, first;
  for (int i : chosen) design.push_back(candidates[i]);
  for (int i = 0; i < n; ++i) first.push_back(candidates[i]);
  const std::vector<JointCoverage> planned = TravelCoverage(r, design);
  const std::vector<JointCoverage> random = TravelCoverage(r, first);
  // Evenly spaced: 12 deg and 100/31 mm; the greedy choice stays within
  // twice that, and random draws leave far larger gaps.
  EXPECT_LT(planned[0].Gap(), 24.0);
  EXPECT_LT(planned[1].Gap(), 2 * 100.0 / 31);
  EXPECT_GT(random[0].Gap(), 1.5 * planned[0].Gap());
  EXPECT_GT(random[1].Gap(), 1.5 * planned[1].Gap());
  EXPECT_FALSE(planned[0].wide);
  EXPECT_FALSE(planned[1].wide);
  // Each candidate once; fewer candidates than n: all of them.
  std::vector<int> sorted = chosen;
  std::sort(sorted.begin(), sorted.end());
  EXPECT_EQ(std::unique(sorted.begin(), sorted.end()), sorted.end());
  EXPECT_EQ(CoverageDesign(r, first, 40).size(), first.size());
}

}  // namespace
}  // namespace kincal
