#include "diagnose/statistics.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace kincal {
namespace {

TEST(StatisticsTest, FUpperTailKnownValues) {
  // F(1, d2) is t(d2)^2: P(F > t^2) = 2 P(T > t); the 95 % points of
  // F(1, 10) = 4.9646 and F(3, 20) = 3.0984.
  EXPECT_NEAR(FDistributionUpperTail(4.9646, 1, 10), 0.05, 1e-4);
  EXPECT_NEAR(FDistributionUpperTail(3.0984, 3, 20), 0.05, 1e-4);
  EXPECT_NEAR(FDistributionUpperTail(0.0, 2, 5), 1.0, 1e-12);
  EXPECT_NEAR(std::exp(LogFUpperTail(3.0984, 3, 20)), 0.05, 1e-4);
  // Strong effects stay ordered in logs where the tail underflows.
  EXPECT_LT(LogFUpperTail(1e6, 3, 1000), LogFUpperTail(1e5, 3, 1000));
  EXPECT_LT(LogFUpperTail(1e6, 3, 1000), -300.0);
}

TEST(StatisticsTest, SpansAndIndependentColumns) {
  Eigen::MatrixXd a(4, 2);
  a << 1, 0, 0, 2, 0, 0, 0, 0;
  const Eigen::MatrixXd basis = Basis(Normalized(a));
  EXPECT_EQ(basis.cols(), 2);
  Eigen::MatrixXd cand(4, 2);
  // Row by row: column 0 = (1, 0, 1, 0) leaves the span, column 1 =
  // (0, 3, 0, 0) lies in it.
  cand << 1, 0, 0, 3, 1, 0, 0, 0;
  const std::vector<bool> ok = IndependentColumns(basis, cand);
  ASSERT_EQ(ok.size(), 2u);
  EXPECT_TRUE(ok[0]);
  EXPECT_FALSE(ok[1]);
  EXPECT_FALSE(IdentifiableAgainst(basis, cand));
  EXPECT_TRUE(IdentifiableAgainst(basis, cand.leftCols(1)));
  EXPECT_EQ(IndependentProjectedColumns(ProjectedOffBasis(basis, cand)), ok);
  // Normalized: unit columns, zero columns kept zero.
  Eigen::MatrixXd z(3, 2);
  z << 3, 0, 4, 0, 0, 0;
  const Eigen::MatrixXd n = Normalized(z);
  EXPECT_NEAR(n.col(0).norm(), 1.0, 1e-12);
  EXPECT_EQ(n.col(1).norm(), 0.0);
}

TEST(StatisticsTest, RepeatedPoseNoiseRecoversSigma) {
  std::mt19937_64 rng(3);
  std::normal_distribution<double> noise(0.0, 0.05);
  std::vector<Measurement> ms;
  for (int pose = 0; pose < 40; ++pose) {
    for (int rep = 0; rep < 3; ++rep) {
      Measurement m;
      m.input.q = {0.1 * pose, 0.2};
      m.p_in_meas = Eigen::Vector3d(10.0 * pose + noise(rng), noise(rng),
                                    5.0 + noise(rng));
      ms.push_back(m);
    }
  }
  EXPECT_NEAR(RepeatedPoseNoise(ms), 0.05, 0.008);
  ms.resize(2);  // one pose twice: too few degrees of freedom
  EXPECT_EQ(RepeatedPoseNoise(ms), 0.0);
}

// Basis: orthonormal columns spanning `a`, on one thread or two, whether
// the columns are independent (the Cholesky QR), nearly dependent (sine
// 1e-8: the rank-revealing QR keeps it) or dependent (it drops it).
TEST(StatisticsTest, BasisSpansTheColumnsAndDropsDependentOnes) {
  std::mt19937 rng(3);
  std::normal_distribution<double> n(0.0, 1.0);
  Eigen::MatrixXd a(9000, 12);
  for (int i = 0; i < a.rows(); ++i)
    for (int j = 0; j < a.cols(); ++j) a(i, j) = n(rng) * (1 + j);
  const auto check = [](const Eigen::MatrixXd& m, int rank) {
    for (int threads : {1, 2}) {
      const Eigen::MatrixXd q = Basis(Normalized(m), threads);
      ASSERT_EQ(q.cols(), rank) << threads;
      EXPECT_LT(
          (q.transpose() * q - Eigen::MatrixXd::Identity(q.cols(), q.cols()))
              .cwiseAbs()
              .maxCoeff(),
          1e-12)
          << threads;
      const Eigen::MatrixXd off = m - q * (q.transpose() * m);
      EXPECT_LT(off.norm(), 1e-10 * m.norm()) << threads;
    }
  };
  check(a, 12);
  Eigen::MatrixXd near = a;
  near.col(11) = a.col(0) + a.col(1) + 1e-8 * a.col(11);
  check(near, 12);
  Eigen::MatrixXd dependent = a;
  dependent.col(11) = a.col(0) - 2.0 * a.col(3);
  check(dependent, 11);
  // The projection off it: the same on two threads.
  const Eigen::MatrixXd q = Basis(Normalized(a.leftCols(6)));
  EXPECT_LT((ProjectedOffBasis(q, a, 2) - ProjectedOffBasis(q, a, 1)).norm(),
            1e-12);
  EXPECT_LT(ProjectedOffBasis(q, a, 2).leftCols(6).norm(), 1e-12);
}

}  // namespace
}  // namespace kincal
