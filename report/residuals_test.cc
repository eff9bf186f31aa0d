// The structure measure of the report: the share of the residual vectors'
// variance explained by a grid over two joints finds a pan x lift pattern,
// stays near its chance level on noise, and is blind to neither joint alone.

#include "report/residuals.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace kincal {
namespace {

TEST(ResidualsTest, GridShareFindsTwoJointStructureAndNotNoise) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-180.0, 180.0);
  std::normal_distribution<double> noise(0.0, 0.05);
  const int n = 2000;
  std::vector<double> a(n), b(n), c(n);
  std::vector<Eigen::Vector3d> structured(n), pure(n);
  for (int i = 0; i < n; ++i) {
    a[i] = u(rng);
    b[i] = u(rng);
    c[i] = u(rng);
    // Depends on a and b together (their product's sign), not on either
    // alone: the kind of pattern a single-joint plot cannot show.
    const double s = std::sin(a[i] * M_PI / 180) * std::sin(b[i] * M_PI / 180);
    structured[i] =
        Eigen::Vector3d(0.3 * s + noise(rng), noise(rng), noise(rng));
    pure[i] = Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
  }
  const std::vector<double> zero(n, 0.0);
  const double pair = VectorExplainedByGrid(a, b, structured, 5);
  const double a_alone = VectorExplainedByGrid(a, zero, structured, 5);
  const double other = VectorExplainedByGrid(a, c, structured, 5);
  const double chance = VectorExplainedByGrid(a, b, pure, 5);
  EXPECT_GT(pair, 0.5);
  EXPECT_LT(a_alone, 0.05);
  EXPECT_LT(other, 0.05);
  EXPECT_LT(chance, 3.0 * 24.0 / n);

  std::vector<double> cx, cy, mag;
  double w = 0, h = 0;
  MeanVectorGrid(a, b, structured, 6, 3, &cx, &cy, &mag, &w, &h);
  ASSERT_EQ(mag.size(), 36u);
  EXPECT_NEAR(w, 60.0, 1.0);
  double biggest = 0;
  for (double m : mag) biggest = std::max(biggest, m);
  EXPECT_GT(biggest, 0.15);  // cells near (+-90, +-90) carry ~0.25 mm
}

TEST(ResidualsTest, BinnedMeansFollowATrend) {
  std::vector<double> x, v;
  for (int i = 0; i < 100; ++i) {
    x.push_back(i);
    v.push_back(2.0 * i);
  }
  std::vector<double> cx, m;
  BinnedMeans(x, v, 10, &cx, &m);
  ASSERT_EQ(cx.size(), 10u);
  for (size_t k = 0; k < cx.size(); ++k) EXPECT_NEAR(m[k], 2.0 * cx[k], 1e-9);
  EXPECT_NEAR(ExplainedByBins(x, v, 10), 0.99, 0.01);
}

}  // namespace
}  // namespace kincal
