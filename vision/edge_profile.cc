#include "vision/edge_profile.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

namespace kincal {

namespace {

constexpr double kPhiRange = 6.0;
constexpr int kPhiTable = 4096;

struct PhiTable {
  std::array<double, kPhiTable + 1> v;
  PhiTable() {
    for (int i = 0; i <= kPhiTable; ++i) {
      const double x = -kPhiRange + 2 * kPhiRange * i / kPhiTable;
      v[i] = 0.5 * std::erfc(-x / std::sqrt(2.0));
    }
  }
};

struct GaussTable {
  std::array<double, kPhiTable + 1> v;
  GaussTable() {
    for (int i = 0; i <= kPhiTable; ++i) {
      const double x = -kPhiRange + 2 * kPhiRange * i / kPhiTable;
      v[i] = 0.3989422804014327 * std::exp(-0.5 * x * x);
    }
  }
};

// Standard normal density from a table, for |x| < kPhiRange.
inline double Gauss(double x) {
  static const GaussTable table;
  const double f = (x + kPhiRange) * (kPhiTable / (2 * kPhiRange));
  const int i = static_cast<int>(f);
  const double t = f - i;
  return (1 - t) * table.v[i] + t * table.v[i + 1];
}

// G(x) = x Phi(x) + phi(x), the integral of Phi up to x.
inline double IntegralPhi(double x) {
  if (x <= -kPhiRange) return 0.0;
  if (x >= kPhiRange) return x;
  return x * FastPhi(x) + Gauss(x);
}

// Basis of the three classes at offset o for one line's pattern (breaks,
// classes), and its derivative with respect to e, for shift e and blur
// sigma (and the profile's box), added with `weight`.
void AddLineBasis(const EdgeProfile& p, const std::vector<double>& breaks,
                  const std::vector<int>& classes, double weight, double o,
                  double e, double sigma, Eigen::Vector3d* b,
                  Eigen::Vector3d* db_de) {
  const double inv = 1.0 / sigma;
  // Phi((o - e - break) / sigma) at each break: the class left of a break
  // contributes 1 - Phi there, the right one Phi, so each class sums
  // (Phi(lower break) - Phi(upper break)).
  double prev_phi = 1.0, prev_g = 0.0;  // at -inf: Phi = 1, density 0
  for (size_t i = 0; i <= breaks.size(); ++i) {
    double phi = 0.0, g = 0.0;  // at +inf
    if (i < breaks.size()) {
      const double x = (o - e - breaks[i]) * inv;
      if (p.box_px > 0) {
        const double h = 0.5 * p.box_px * inv;
        phi = (IntegralPhi(x + h) - IntegralPhi(x - h)) / (2 * h);
        g = (FastPhi(x + h) - FastPhi(x - h)) / (2 * h);
      } else {
        phi = FastPhi(x);
        g = x > -kPhiRange && x < kPhiRange ? Gauss(x) : 0.0;
      }
    }
    const int c = classes[i];
    (*b)(c) += weight * (prev_phi - phi);
    // d/de Phi((o - e - s) / sigma) = -g / sigma.
    (*db_de)(c) += weight * (-prev_g + g) * inv;
    prev_phi = phi;
    prev_g = g;
  }
}

// Basis of the three classes at offset o, and its derivative with respect
// to e, for shift e and blur sigma: the profile's pattern, or its mixture.
void Basis(const EdgeProfile& p, double o, double e, double sigma,
           Eigen::Vector3d* b, Eigen::Vector3d* db_de) {
  b->setZero();
  db_de->setZero();
  if (p.mixture.empty()) {
    AddLineBasis(p, p.breaks, p.classes, 1.0, o, e, sigma, b, db_de);
    return;
  }
  for (const PatternLine& line : p.mixture) {
    AddLineBasis(p, line.breaks, line.classes, line.weight, o, e, sigma, b,
                 db_de);
  }
}

// The profile's sums at shift e (EdgeProfileSums), in one pass.
EdgeProfileSums Sums(const EdgeProfile& p, double e, const PhaseSigmas& sigma) {
  EdgeProfileSums s;
  Eigen::Vector3d b, db;
  const bool phased = p.phases.size() == p.offsets.size();
  for (size_t i = 0; i < p.offsets.size(); ++i) {
    Basis(p, p.offsets[i], e, sigma[phased ? p.phases[i] : 0], &b, &db);
    s.Add(b, db, p.values[i]);
  }
  s.AddRidge();  // classes the profile does not reach
  return s;
}

}  // namespace

void EdgeProfileBasis(const EdgeProfile& profile, double offset,
                      double shift_px, double sigma_px, Eigen::Vector3d* basis,
                      Eigen::Vector3d* d_basis_d_shift) {
  Basis(profile, offset, shift_px, sigma_px, basis, d_basis_d_shift);
}

double AreaRuleShift(const EdgeProfile& p, double inside, double outside,
                     double centre, double w) {
  const double a = centre - w, b = centre + w;
  double area = 0;
  for (size_t i = 0; i + 1 < p.offsets.size(); ++i) {
    const double o0 = p.offsets[i], o1 = p.offsets[i + 1];
    const double lo = std::max(a, o0), hi = std::min(b, o1);
    if (!(hi > lo)) continue;
    // The linear interpolant's integral over [lo, hi].
    const double slope = (p.values[i + 1] - p.values[i]) / (o1 - o0);
    const double v_lo = p.values[i] + slope * (lo - o0);
    const double v_hi = p.values[i] + slope * (hi - o0);
    area += 0.5 * (v_lo + v_hi) * (hi - lo);
  }
  return AreaRuleShiftFromArea(area, inside, outside, centre, w);
}

double AreaRuleShiftFromArea(double area, double inside, double outside,
                             double centre, double w) {
  return centre + w - (area - inside * 2 * w) / (outside - inside);
}

std::vector<double> EdgeProfileModel(const EdgeProfile& profile,
                                     const std::vector<double>& offsets,
                                     double shift_px, double sigma_px,
                                     const std::array<double, 3>& levels) {
  const Eigen::Vector3d l(levels[0], levels[1], levels[2]);
  std::vector<double> values;
  values.reserve(offsets.size());
  Eigen::Vector3d b, db;
  for (const double o : offsets) {
    Basis(profile, o, shift_px, sigma_px, &b, &db);
    values.push_back(b.dot(l));
  }
  return values;
}

double EdgeProfileModelArea(const EdgeProfile& profile, double lo, double hi,
                            double shift_px, double sigma_px,
                            const std::array<double, 3>& levels) {
  // m(o) = L_0 + sum_i (L_{i+1} - L_i) Phi((o - e - b_i) / sigma), L_i the
  // level of the i-th class along the line.
  const auto g = [](double x) {
    return x * 0.5 * std::erfc(-x / std::sqrt(2.0)) +
           0.3989422804014327 * std::exp(-0.5 * x * x);
  };
  double area = levels[profile.classes.front()] * (hi - lo);
  for (size_t i = 0; i < profile.breaks.size(); ++i) {
    const double step =
        levels[profile.classes[i + 1]] - levels[profile.classes[i]];
    const double c = shift_px + profile.breaks[i];
    area += step * sigma_px * (g((hi - c) / sigma_px) - g((lo - c) / sigma_px));
  }
  return area;
}

double FastPhi(double x) {
  static const PhiTable table;
  if (x <= -kPhiRange) return 0.0;
  if (x >= kPhiRange) return 1.0;
  const double f = (x + kPhiRange) * (kPhiTable / (2 * kPhiRange));
  const int i = static_cast<int>(f);
  const double t = f - i;
  return (1 - t) * table.v[i] + t * table.v[i + 1];
}

EdgeProfileFit FitEdgeProfile(const EdgeProfile& profile, double sigma_px,
                              int iterations, double max_shift_px) {
  return FitEdgeProfile(profile, {sigma_px, sigma_px, sigma_px, sigma_px},
                        iterations, max_shift_px);
}

EdgeProfileFit FitEdgeProfile(const EdgeProfile& profile,
                              const PhaseSigmas& sigma_px, int iterations,
                              double max_shift_px) {
  EdgeProfileFit fit;
  if (profile.offsets.size() < 6 ||
      profile.classes.size() != profile.breaks.size() + 1 ||
      !(*std::min_element(sigma_px.begin(), sigma_px.end()) > 0)) {
    return fit;
  }
  return FitShiftFromSums([&](double e) { return Sums(profile, e, sigma_px); },
                          profile.offsets.size(), iterations, max_shift_px);
}

EdgeProfileFit FitShiftFromSums(
    const std::function<EdgeProfileSums(double)>& sums_at, size_t samples,
    int iterations, double max_shift_px) {
  EdgeProfileFit fit;
  double e = 0;
  Eigen::Vector3d levels = Eigen::Vector3d::Zero();
  double sse = 0;
  for (int it = 0;; ++it) {
    const EdgeProfileSums s = sums_at(e);
    levels = s.B.ldlt().solve(s.bv);
    sse = s.vv - 2 * levels.dot(s.bv) + levels.dot(s.B * levels);
    if (it == iterations) break;
    // Gauss-Newton on e with the levels held.
    const double jtj = levels.dot(s.DD * levels);
    const double jtr = -levels.dot(s.dv) + levels.dot(s.D * levels);
    if (!(jtj > 0)) return fit;
    const double step = std::clamp(-jtr / jtj, -0.5, 0.5);
    e += step;
    if (std::abs(e) > max_shift_px) return fit;
    if (std::abs(step) < 1e-4) iterations = it + 1;
  }
  fit.shift_px = e;
  fit.levels = {levels(0), levels(1), levels(2)};
  fit.rms = std::sqrt(std::max(0.0, sse) / samples);
  fit.ok = std::isfinite(e) && std::abs(levels(1) - levels(0)) >= 5.0;
  return fit;
}

}  // namespace kincal
