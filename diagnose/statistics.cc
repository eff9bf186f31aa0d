#include "diagnose/statistics.h"

#include <Eigen/Cholesky>
#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <set>

#include "calib/exact_jacobian.h"

namespace kincal {
namespace {

// sin(angle) of a candidate column against the span of the model's columns
// below which the candidate is structurally equivalent to the model.
constexpr double kIdentifiableSine = 1e-5;

// Log of the regularized incomplete beta I_x(a, b) (Numerical Recipes'
// continued fraction, evaluated where it converges fast).
double BetaContinuedFraction(double a, double b, double x) {
  const double tiny = 1e-300;
  double c = 1.0, d = 1.0 - (a + b) * x / (a + 1.0);
  if (std::abs(d) < tiny) d = tiny;
  d = 1.0 / d;
  double h = d;
  for (int m = 1; m <= 500; ++m) {
    const double m2 = 2.0 * m;
    double aa = m * (b - m) * x / ((a + m2 - 1.0) * (a + m2));
    d = 1.0 + aa * d;
    if (std::abs(d) < tiny) d = tiny;
    c = 1.0 + aa / c;
    if (std::abs(c) < tiny) c = tiny;
    d = 1.0 / d;
    h *= d * c;
    aa = -(a + m) * (a + b + m) * x / ((a + m2) * (a + m2 + 1.0));
    d = 1.0 + aa * d;
    if (std::abs(d) < tiny) d = tiny;
    c = 1.0 + aa / c;
    if (std::abs(c) < tiny) c = tiny;
    d = 1.0 / d;
    const double del = d * c;
    h *= del;
    if (std::abs(del - 1.0) < 1e-15) break;
  }
  return h;
}

double LogIncompleteBeta(double a, double b, double x) {
  if (x <= 0.0) return -std::numeric_limits<double>::infinity();
  if (x >= 1.0) return 0.0;
  const double log_front = std::lgamma(a + b) - std::lgamma(a) -
                           std::lgamma(b) + a * std::log(x) +
                           b * std::log1p(-x);
  if (x < (a + 1.0) / (a + b + 2.0)) {
    return log_front + std::log(BetaContinuedFraction(a, b, x)) - std::log(a);
  }
  const double rest = std::exp(
      log_front + std::log(BetaContinuedFraction(b, a, 1.0 - x)) - std::log(b));
  return std::log1p(-std::min(rest, 1.0));
}

}  // namespace

// log P(F > f) for F(d1, d2).
double LogFUpperTail(double f, double d1, double d2) {
  if (!(f > 0)) return 0.0;
  return LogIncompleteBeta(0.5 * d2, 0.5 * d1, d2 / (d2 + d1 * f));
}

double FDistributionUpperTail(double f, double d1, double d2) {
  return std::exp(LogFUpperTail(f, d1, d2));
}

// Column-normalised Jacobian columns; zero columns stay zero.
Eigen::MatrixXd Normalized(Eigen::MatrixXd j) {
  for (int c = 0; c < j.cols(); ++c) {
    const double n = j.col(c).norm();
    if (n > 0) j.col(c) /= n;
  }
  return j;
}

// Orthonormal basis of the column span of `a`. CholeskyQR2 first (Fukaya et
// al. 2014: R1 = chol(A^T A), Q1 = A R1^-1, then once more on Q1; stable to
// rounding for condition numbers below ~1e8, and all of it products over
// blocks of rows, shared among `threads`): R1's diagonal is each column's
// distance from the span of the columns before it (Householder QR's |R_kk|),
// so when every one exceeds 1e-6 of the largest column norm the columns are
// independent and Q spans them. Otherwise (or when a Cholesky fails) the
// rank-revealing QR (column pivoting, threshold 1e-10) decides which
// directions count.
Eigen::MatrixXd Basis(const Eigen::MatrixXd& a, int threads) {
  if (a.cols() == 0) return Eigen::MatrixXd(a.rows(), 0);
  constexpr double kIndependent = 1e-6;
  const int rows = static_cast<int>(a.rows());
  const std::vector<std::pair<int, int>> blocks = EvenRanges(rows, threads);
  // q <- q R^-1 (R = L^T upper triangular), block by block.
  const auto solve_right = [&](const Eigen::LLT<Eigen::MatrixXd>& llt,
                               Eigen::MatrixXd* q) {
    ParallelFor(static_cast<int>(blocks.size()), threads, [&](int b) {
      auto part =
          q->middleRows(blocks[b].first, blocks[b].second - blocks[b].first);
      llt.matrixU().solveInPlace<Eigen::OnTheRight>(part);
    });
  };
  const double largest = a.colwise().norm().maxCoeff();
  if (a.cols() <= a.rows() && largest > 0) {
    const Eigen::LLT<Eigen::MatrixXd> first(NormalMatrix(a, threads));
    const Eigen::MatrixXd r1 = first.matrixU();
    if (first.info() == Eigen::Success && r1.diagonal().allFinite() &&
        r1.diagonal().minCoeff() > kIndependent * largest) {
      Eigen::MatrixXd q = a;
      solve_right(first, &q);
      const Eigen::LLT<Eigen::MatrixXd> second(NormalMatrix(q, threads));
      if (second.info() == Eigen::Success) {
        solve_right(second, &q);
        if (q.allFinite()) return q;
      }
    }
  }
  Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(a);
  qr.setThreshold(1e-10);
  const int rank = static_cast<int>(qr.rank());
  Eigen::MatrixXd q =
      qr.householderQ() * Eigen::MatrixXd::Identity(a.rows(), rank);
  return q;
}

// The columns of `cand`, normalised, minus their part in the span of the
// orthonormal `basis`, blocks of columns on `threads` threads. One pass:
// with `basis` orthonormal to rounding the rest keeps a part in its span of
// the order of the rounding (1e-15), far below the 1e-5 sine that decides
// identifiability.
Eigen::MatrixXd ProjectedOffBasis(const Eigen::MatrixXd& basis,
                                  const Eigen::MatrixXd& cand, int threads) {
  Eigen::MatrixXd rest = Normalized(cand);
  if (basis.cols() == 0) return rest;
  const std::vector<std::pair<int, int>> blocks =
      EvenRanges(static_cast<int>(rest.cols()), threads);
  ParallelFor(static_cast<int>(blocks.size()), threads, [&](int b) {
    auto part =
        rest.middleCols(blocks[b].first, blocks[b].second - blocks[b].first);
    part -= basis * (basis.transpose() * part);
  });
  return rest;
}

// Which of the projected columns keep a part outside the span of the
// earlier accepted ones (Gram-Schmidt, two passes).
std::vector<bool> IndependentProjectedColumns(const Eigen::MatrixXd& rest) {
  Eigen::MatrixXd accepted_cols(rest.rows(), rest.cols());
  int accepted = 0;
  std::vector<bool> out(rest.cols(), false);
  for (int c = 0; c < rest.cols(); ++c) {
    Eigen::VectorXd r = rest.col(c);
    for (int pass = 0; pass < 2 && accepted > 0; ++pass) {
      const auto q = accepted_cols.leftCols(accepted);
      r -= q * (q.transpose() * r);
    }
    if (r.norm() < kIdentifiableSine) continue;
    out[c] = true;
    accepted_cols.col(accepted++) = r / r.norm();
  }
  return out;
}

// Which columns of `cand` (normalised) keep a part outside the span of
// `basis` and of the candidate's earlier accepted columns.
std::vector<bool> IndependentColumns(const Eigen::MatrixXd& basis,
                                     const Eigen::MatrixXd& cand) {
  return IndependentProjectedColumns(ProjectedOffBasis(basis, cand));
}

// True when every column of `cand` is independent of `basis`.
bool IdentifiableAgainst(const Eigen::MatrixXd& basis,
                         const Eigen::MatrixXd& cand) {
  const std::vector<bool> ok = IndependentColumns(basis, cand);
  return std::all_of(ok.begin(), ok.end(), [](bool b) { return b; });
}

// The per-axis noise from rows with identical joint readings; 0 when there
// are too few repeats (fewer than 6 degrees of freedom).
double RepeatedPoseNoise(const std::vector<Measurement>& ms) {
  std::map<std::vector<double>, std::vector<int>> groups;
  for (size_t i = 0; i < ms.size(); ++i) {
    groups[ms[i].input.q].push_back(static_cast<int>(i));
  }
  double sum = 0.0;
  int dof = 0;
  for (const auto& kv : groups) {
    if (kv.second.size() < 2) continue;
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (int i : kv.second) mean += ms[i].p_in_meas;
    mean /= static_cast<double>(kv.second.size());
    for (int i : kv.second) sum += (ms[i].p_in_meas - mean).squaredNorm();
    dof += 3 * (static_cast<int>(kv.second.size()) - 1);
  }
  return dof >= 6 ? std::sqrt(sum / dof) : 0.0;
}

// An upper bound on the per-axis noise from the model residuals of pose
// pairs that are nearest neighbours in joint space (each joint scaled by its
// spread): 0.5 E|r_i - r_j|^2 / 3 over the closest quarter of the pairs. A
// systematic error that varies smoothly with the pose adds to it, so it
// bounds the noise from above.
double NearestPoseNoise(const ModelState& state,
                        const std::vector<Measurement>& ms) {
  const int n = static_cast<int>(ms.size());
  if (n < 8) return 0.0;
  const int nj = static_cast<int>(ms[0].input.q.size());
  std::vector<double> scale(nj, 1.0);
  for (int j = 0; j < nj; ++j) {
    double mean = 0, sq = 0;
    for (const Measurement& m : ms) mean += m.input.q[j];
    mean /= n;
    for (const Measurement& m : ms) sq += std::pow(m.input.q[j] - mean, 2);
    const double sd = std::sqrt(sq / n);
    scale[j] = sd > 1e-12 ? 1.0 / sd : 0.0;
  }
  std::vector<Eigen::Vector3d> r(n);
  for (int i = 0; i < n; ++i) r[i] = Residual(state, ms[i]);
  std::vector<std::pair<double, double>> pairs;  // distance, half sq diff
  // Mutual nearest neighbours give one pair, not two (with 45 poses the
  // closest quarter of the 45 entries held ~6 distinct pairs; the estimate
  // then fell below the true noise in 4 of 40 null sessions and named an
  // `unexplained` rest, bench --only cv-sim).
  std::set<std::pair<int, int>> seen;
  for (int i = 0; i < n; ++i) {
    double best = std::numeric_limits<double>::infinity();
    int arg = -1;
    for (int k = 0; k < n; ++k) {
      if (k == i) continue;
      double d = 0;
      for (int j = 0; j < nj; ++j) {
        d += std::pow((ms[i].input.q[j] - ms[k].input.q[j]) * scale[j], 2);
      }
      if (d < best) {
        best = d;
        arg = k;
      }
    }
    if (arg >= 0 && best > 0 &&
        seen.insert({std::min(i, arg), std::max(i, arg)}).second) {
      pairs.emplace_back(best, 0.5 * (r[i] - r[arg]).squaredNorm() / 3.0);
    }
  }
  if (pairs.size() < 4) return 0.0;
  std::sort(pairs.begin(), pairs.end());
  // The closest quarter, but at least 15 pairs (45 degrees of freedom) when
  // there are that many: fewer make the estimate scatter below the noise.
  const size_t use =
      std::max(std::min<size_t>(15, pairs.size()), pairs.size() / 4);
  double sum = 0;
  for (size_t i = 0; i < use; ++i) sum += pairs[i].second;
  return std::sqrt(sum / use);
}

}  // namespace kincal
