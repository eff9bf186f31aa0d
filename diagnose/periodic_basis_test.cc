// The periodic transmission basis: orthonormal on the readings, the whole
// dictionary supported on a full revolution, and the regulariser holding in
// the gaps and beyond the travel of a joint's readings.
#include "diagnose/periodic_basis.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <random>

namespace kincal {
namespace {

constexpr double kDeg = M_PI / 180.0;

ChainRow RowWith(const PeriodicBasis& b) {
  ChainRow row;
  row.periodic_basis = b.basis;
  return row;
}

// phi_k(q) of the basis, k < supported.
Eigen::MatrixXd Functions(const PeriodicBasis& b,
                          const std::vector<double>& q) {
  const ChainRow row = RowWith(b);
  Eigen::MatrixXd phi(q.size(), b.supported);
  for (int k = 0; k < b.supported; ++k) {
    double c[kMaxTransmissionTerms] = {};
    c[k] = 1.0;
    for (size_t i = 0; i < q.size(); ++i)
      phi(i, k) = TransmissionError(c, q[i], row);
  }
  return phi;
}

std::vector<double> Readings(double from_deg, double to_deg, int n) {
  std::vector<double> q;
  for (int i = 0; i < n; ++i)
    q.push_back((from_deg + (to_deg - from_deg) * i / (n - 1)) * kDeg);
  return q;
}

TEST(PeriodicBasisTest, FunctionsAreOrthonormalOnTheReadings) {
  const std::vector<double> q = Readings(-250, -40, 400);
  const PeriodicBasis b = MakePeriodicBasis(q);
  ASSERT_GE(b.supported, 8);
  Eigen::MatrixXd phi = Functions(b, q);
  phi.rowwise() -= phi.colwise().mean();
  const Eigen::MatrixXd gram = phi.transpose() * phi / double(q.size());
  EXPECT_LT((gram - Eigen::MatrixXd::Identity(b.supported, b.supported))
                .cwiseAbs()
                .maxCoeff(),
            1e-8);
  EXPECT_EQ(PeriodicSupport(RowWith(b)), b.supported);
}

TEST(PeriodicBasisTest, WholeRevolutionSupportsEveryFunction) {
  EXPECT_EQ(MakePeriodicBasis(Readings(-180, 179, 720)).supported,
            kMaxTransmissionTerms);
  EXPECT_EQ(MakePeriodicBasis({0.1, 0.2}).supported, 0);
}

// A joint error of harmonics 3 and 5 (0.02 deg) measured with noise on two
// arcs with a 70 deg gap between them and 110 deg unmeasured beyond: the
// least-squares fit through the supported functions follows the truth on
// the readings and stays of the readings' size in the gap and beyond (the
// unregularised sine series of the travel reached 100x there on series A).
TEST(PeriodicBasisTest, RegulariserHoldsInGapsAndBeyondTheTravel) {
  std::vector<double> q = Readings(0, 110, 220);
  for (double x : Readings(180, 250, 140)) q.push_back(x);
  auto truth = [](double x) {
    return 0.02 * kDeg * (std::sin(3 * x) + 0.5 * std::cos(5 * x + 0.3));
  };
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, 0.002 * kDeg);
  Eigen::VectorXd y(q.size());
  for (size_t i = 0; i < q.size(); ++i) y[i] = truth(q[i]) + noise(rng);
  y.array() -= y.mean();
  const PeriodicBasis b = MakePeriodicBasis(q);
  ASSERT_GE(b.supported, 16);
  for (int terms : {8, 16, b.supported}) {
    Eigen::MatrixXd phi = Functions(b, q).leftCols(terms);
    const Eigen::RowVectorXd mean = phi.colwise().mean();
    phi.rowwise() -= mean;
    const Eigen::VectorXd c = phi.colPivHouseholderQr().solve(y);
    const double offset = -mean.dot(c);  // the geometry's constant
    double peak_on = 0.0, peak_off = 0.0, err_on = 0.0;
    const std::vector<std::array<double, 2>> arcs = ExtrapolatedArcs(q, 5.0);
    ASSERT_EQ(arcs.size(), 2u);
    EXPECT_NEAR(arcs[0][0], 110.0, 1e-9);
    EXPECT_NEAR(arcs[0][1], 180.0, 1e-9);
    EXPECT_NEAR(arcs[1][0], 250.0, 1e-9);
    EXPECT_NEAR(arcs[1][1], 360.0, 1e-9);
    const Eigen::MatrixXd at = Functions(b, q).leftCols(terms);
    for (size_t i = 0; i < q.size(); ++i) {
      const double p = at.row(i).dot(c) + offset;
      peak_on = std::max(peak_on, std::abs(p));
      err_on = std::max(err_on, std::abs(p - y[i]));
    }
    for (const auto& arc : arcs) {
      const Eigen::MatrixXd off =
          Functions(b, Readings(arc[0], arc[1], 200)).leftCols(terms);
      peak_off = std::max(peak_off,
                          ((off * c).array() + offset).abs().maxCoeff());
    }
    SCOPED_TRACE(terms);
    EXPECT_LT(peak_off, 2.0 * peak_on)
        << "readings peak " << peak_on / kDeg << " deg, extrapolated "
        << peak_off / kDeg << " deg";
    if (terms == b.supported) {
      EXPECT_LT(err_on, 0.01 * kDeg);
    }
  }
}

TEST(PeriodicBasisTest, ExtrapolatedArcsOfOneTurnAndMore) {
  const auto full = ExtrapolatedArcs(Readings(-180, 180, 721), 5.0);
  EXPECT_TRUE(full.empty());
  const auto multi = ExtrapolatedArcs(Readings(-300, 200, 1001), 5.0);
  EXPECT_TRUE(multi.empty());
  const auto none = ExtrapolatedArcs({}, 5.0);
  ASSERT_EQ(none.size(), 1u);
}

}  // namespace
}  // namespace kincal
