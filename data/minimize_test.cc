#include "data/minimize.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace kincal {
namespace {

TEST(GoldenSection, FindsTheMinimumOfAParabola) {
  int calls = 0;
  const auto f = [&](double x) {
    ++calls;
    return (x - 0.3) * (x - 0.3) + 2.0;
  };
  const GoldenSectionResult r = GoldenSectionMinimize(f, -1.0, 2.0, 60);
  EXPECT_NEAR(r.x, 0.3, 1e-7);  // a flat minimum: x to sqrt(eps) of f
  EXPECT_NEAR(r.f, 2.0, 1e-14);
  EXPECT_DOUBLE_EQ(r.f, f(r.x));
  EXPECT_EQ(calls, 60 + 2 + 1);
  EXPECT_LE(r.lo, 0.3 + 1e-7);
  EXPECT_GE(r.hi, 0.3 - 1e-7);
  EXPECT_LT(r.hi - r.lo, 3.0 * std::pow(0.5 * (std::sqrt(5.0) - 1), 60) * 1.01);
}

TEST(GoldenSection, BracketShrinksByTheGoldenRatioAndHoldsAKink) {
  // |x - 1.7|: a kink, no derivative at the minimum.
  const auto f = [](double x) { return std::abs(x - 1.7); };
  const double g = 0.5 * (std::sqrt(5.0) - 1);
  for (int n : {0, 1, 5, 20, 40}) {
    const GoldenSectionResult r = GoldenSectionMinimize(f, 0.0, 4.0, n);
    EXPECT_NEAR(r.hi - r.lo, 4.0 * std::pow(g, n), 1e-12) << n;
    EXPECT_LE(r.lo, 1.7) << n;
    EXPECT_GE(r.hi, 1.7) << n;
    EXPECT_GE(r.x, r.lo) << n;
    EXPECT_LE(r.x, r.hi) << n;
  }
  EXPECT_NEAR(GoldenSectionMinimize(f, 0.0, 4.0, 40).x, 1.7, 1e-7);
}

TEST(GoldenSection, MinimumAtAnEndIsApproachedFromInside) {
  // Increasing on [2, 5]: the bracket closes on a = 2, which is not evaluated.
  const GoldenSectionResult r =
      GoldenSectionMinimize([](double x) { return x * x; }, 2.0, 5.0, 50);
  EXPECT_EQ(r.lo, 2.0);
  EXPECT_NEAR(r.x, 2.0, 1e-9);
  EXPECT_GT(r.x, 2.0);
}

TEST(GoldenSection, RefusesAnEmptyInterval) {
  const auto f = [](double x) { return x; };
  EXPECT_THROW(GoldenSectionMinimize(f, 1.0, 1.0, 10), std::logic_error);
  EXPECT_THROW(GoldenSectionMinimize(f, 0.0, 1.0, -1), std::logic_error);
}

}  // namespace
}  // namespace kincal
