#include "diagnose/periodic_basis.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

#include "data/error.h"

namespace kincal {

void PeriodicBasisOptions::Check() const {
  Require(std::isfinite(smoothness_power) && smoothness_power >= 0,
          "periodic basis: smoothness power must be >= 0");
  Require(std::isfinite(min_support) && min_support > 0,
          "periodic basis: minimum support must be > 0");
}

PeriodicBasis MakePeriodicBasis(const std::vector<double>& q_rad,
                                const PeriodicBasisOptions& options) {
  options.Check();
  PeriodicBasis out;
  out.basis.assign(kPeriodicTerms * kMaxTransmissionTerms, 0.0);
  const int n = static_cast<int>(q_rad.size());
  if (n < 3) return out;
  // A = F_c W / sqrt(n), through its Gram matrix A^T A.
  Eigen::VectorXd w(kPeriodicTerms);
  for (int t = 0; t < kPeriodicTerms; ++t)
    w[t] = std::pow(1.0 + t / 2, -options.smoothness_power);
  Eigen::MatrixXd f(n, kPeriodicTerms);
  double terms[kPeriodicTerms];
  for (int i = 0; i < n; ++i) {
    PeriodicTerms(q_rad[i], terms);
    for (int t = 0; t < kPeriodicTerms; ++t) f(i, t) = terms[t];
  }
  f.rowwise() -= f.colwise().mean();
  const Eigen::MatrixXd a = f * w.asDiagonal() / std::sqrt(double(n));
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(a.transpose() * a);
  // Eigenvalues ascending: the best supported last.
  for (int k = 0; k < kMaxTransmissionTerms; ++k) {
    const int e = kPeriodicTerms - 1 - k;
    const double s = std::sqrt(std::max(0.0, eig.eigenvalues()[e]));
    if (!(s >= options.min_support)) break;
    Eigen::VectorXd col = w.asDiagonal() * eig.eigenvectors().col(e) / s;
    // A fixed sign (the largest coefficient positive): the same readings
    // give the same basis on every platform.
    Eigen::Index big = 0;
    col.cwiseAbs().maxCoeff(&big);
    if (col[big] < 0) col = -col;
    std::copy(col.data(), col.data() + kPeriodicTerms,
              out.basis.begin() + kPeriodicTerms * k);
    out.supported = k + 1;
  }
  return out;
}

int PeriodicSupport(const ChainRow& row) {
  if (!row.periodic()) return 0;
  int k = 0;
  while (k < kMaxTransmissionTerms) {
    const auto first = row.periodic_basis.begin() + kPeriodicTerms * k;
    if (std::all_of(first, first + kPeriodicTerms,
                    [](double b) { return b == 0.0; }))
      break;
    ++k;
  }
  return k;
}

std::vector<std::array<double, 2>> ExtrapolatedArcs(
    const std::vector<double>& q_rad, double max_gap_deg) {
  std::vector<std::array<double, 2>> arcs;
  if (q_rad.empty()) return {{{-180.0, 180.0}}};
  std::vector<double> d;
  for (double q : q_rad) d.push_back(q * 180.0 / M_PI);
  std::sort(d.begin(), d.end());
  if (d.back() - d.front() >= 360.0) {  // more than a turn: modulo one
    const double first = d.front();
    for (double& x : d) x = first + std::fmod(x - first, 360.0);
    std::sort(d.begin(), d.end());
  }
  for (size_t i = 0; i + 1 < d.size(); ++i) {
    if (d[i + 1] - d[i] > max_gap_deg) arcs.push_back({d[i], d[i + 1]});
  }
  if (d.front() + 360.0 - d.back() > max_gap_deg)
    arcs.push_back({d.back(), d.front() + 360.0});
  return arcs;
}

}  // namespace kincal
