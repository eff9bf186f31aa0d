#include "vision/demosaic_model.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

#include "data/minimize.h"

namespace kincal {

namespace {

// Index of the neighbour (dx, dy) in a kernel's weights.
constexpr int Tap(int dx, int dy) { return (dy + 1) * 3 + (dx + 1); }

// A colour site: its own share, green's from the four edge neighbours, the
// other colour's from the four diagonals.
std::array<double, 9> ColourSite(double own, double green, double other) {
  std::array<double, 9> w{};
  w[Tap(0, 0)] = own;
  for (const int d : {-1, 1}) {
    w[Tap(d, 0)] = w[Tap(0, d)] = green / 4;
    w[Tap(d, -1)] = w[Tap(d, 1)] = other / 4;
  }
  return w;
}

// A green site: the colour left and right from those two neighbours, the
// colour above and below from those two.
std::array<double, 9> GreenSite(double green, double horizontal,
                                double vertical) {
  std::array<double, 9> w{};
  w[Tap(0, 0)] = green;
  w[Tap(-1, 0)] = w[Tap(1, 0)] = horizontal / 2;
  w[Tap(0, -1)] = w[Tap(0, 1)] = vertical / 2;
  return w;
}

// The profile's sums at shift e (EdgeProfileSums), each sample's model
// being its phase's kernel over the blurred pattern at the 3x3 pixels.
EdgeProfileSums Sums(const EdgeProfile& p, const std::array<double, 9>& delta,
                     const DemosaicKernels& k, double e, double sigma) {
  EdgeProfileSums s;
  Eigen::Vector3d b, db, bt, dbt;
  const bool phased = p.phases.size() == p.offsets.size();
  for (size_t i = 0; i < p.offsets.size(); ++i) {
    const std::array<double, 9>& w = k.weights[phased ? p.phases[i] : 0];
    b.setZero();
    db.setZero();
    for (int t = 0; t < 9; ++t) {
      if (w[t] == 0) continue;
      EdgeProfileBasis(p, p.offsets[i] + delta[t], e, sigma, &bt, &dbt);
      b += w[t] * bt;
      db += w[t] * dbt;
    }
    s.Add(b, db, p.values[i]);
  }
  s.AddRidge();  // classes out of reach
  return s;
}

// Up to `max_profiles` of the sides' profiles, evenly spaced, each with its
// side's normal.
std::vector<std::pair<const EdgeProfile*, Eigen::Vector2d>> Sample(
    const std::vector<DemosaicSide>& sides, int max_profiles) {
  std::vector<std::pair<const EdgeProfile*, Eigen::Vector2d>> all;
  for (const DemosaicSide& s : sides) {
    for (const EdgeProfile& p : *s.profiles) all.emplace_back(&p, s.normal);
  }
  if (static_cast<int>(all.size()) <= max_profiles) return all;
  std::vector<std::pair<const EdgeProfile*, Eigen::Vector2d>> some;
  for (int i = 0; i < max_profiles; ++i) {
    some.push_back(all[(2 * i + 1) * all.size() / (2 * max_profiles)]);
  }
  return some;
}

double SampleCost(
    const std::vector<std::pair<const EdgeProfile*, Eigen::Vector2d>>& sample,
    const DemosaicKernels& kernels, double sigma) {
  double sum = 0;
  for (const auto& [p, n] : sample) {
    const EdgeProfileFit f = FitDemosaicedProfile(*p, n, kernels, sigma, 3);
    sum += f.ok ? f.rms * f.rms : 1e6;
  }
  return sum;
}

double SampleBlur(
    const std::vector<std::pair<const EdgeProfile*, Eigen::Vector2d>>& sample,
    const DemosaicKernels& kernels, double* cost) {
  const GoldenSectionResult r = GoldenSectionMinimize(
      [&](double log_sigma) {
        return SampleCost(sample, kernels, std::exp(log_sigma));
      },
      std::log(0.2), std::log(3.0), 8);
  if (cost != nullptr) *cost = r.f;
  return std::exp(r.x);
}

}  // namespace

DemosaicKernels BilinearDemosaic::Kernels() const {
  const double a = share_a, b = share_b, g = 1.0 - share_a - share_b;
  DemosaicKernels k;
  if (!greens_on_03) {
    // a at (even x, even y), b at (odd, odd): a green site in an "a" row
    // (phase 1) has a left and right, b above and below.
    k.weights[0] = ColourSite(a, g, b);
    k.weights[3] = ColourSite(b, g, a);
    k.weights[1] = GreenSite(g, a, b);
    k.weights[2] = GreenSite(g, b, a);
  } else {
    // a at (odd x, even y), b at (even, odd).
    k.weights[1] = ColourSite(a, g, b);
    k.weights[2] = ColourSite(b, g, a);
    k.weights[0] = GreenSite(g, a, b);
    k.weights[3] = GreenSite(g, b, a);
  }
  return k;
}

EdgeProfileFit FitDemosaicedProfile(const EdgeProfile& profile,
                                    const Eigen::Vector2d& normal,
                                    const DemosaicKernels& kernels,
                                    double sigma_px, int iterations,
                                    double max_shift_px) {
  EdgeProfileFit fit;
  if (profile.offsets.size() < 6 ||
      profile.classes.size() != profile.breaks.size() + 1 || !(sigma_px > 0)) {
    return fit;
  }
  std::array<double, 9> delta{};
  for (int dy = -1; dy <= 1; ++dy) {
    for (int dx = -1; dx <= 1; ++dx) {
      delta[Tap(dx, dy)] = normal.x() * dx + normal.y() * dy;
    }
  }
  return FitShiftFromSums(
      [&](double e) { return Sums(profile, delta, kernels, e, sigma_px); },
      profile.offsets.size(), iterations, max_shift_px);
}

double DemosaicedBlur(const std::vector<DemosaicSide>& sides,
                      const DemosaicKernels& kernels, int max_profiles,
                      double* cost) {
  return SampleBlur(Sample(sides, max_profiles), kernels, cost);
}

BilinearDemosaicFit FitBilinearDemosaic(
    const std::vector<std::vector<DemosaicSide>>& groups) {
  constexpr int kProfilesPerGroup = 12;
  std::vector<std::vector<std::pair<const EdgeProfile*, Eigen::Vector2d>>>
      samples;
  for (const auto& g : groups) samples.push_back(Sample(g, kProfilesPerGroup));
  std::vector<double> sigma(groups.size(), 1.0);
  // Each group's blur refitted for the model; the summed cost.
  const auto refit = [&](const BilinearDemosaic& m) {
    double total = 0;
    for (size_t i = 0; i < samples.size(); ++i) {
      double c = 0;
      sigma[i] = SampleBlur(samples[i], m.Kernels(), &c);
      total += c;
    }
    return total;
  };
  // The cost with the groups' blurs held.
  const auto held = [&](const BilinearDemosaic& m) {
    double total = 0;
    for (size_t i = 0; i < samples.size(); ++i) {
      total += SampleCost(samples[i], m.Kernels(), sigma[i]);
    }
    return total;
  };
  BilinearDemosaicFit best;
  best.cost = 1e300;
  for (const bool layout : {false, true}) {
    BilinearDemosaic m;
    m.greens_on_03 = layout;
    m.share_a = m.share_b = 0.15;
    const double c = refit(m);
    if (c < best.cost) best = {m, c};
  }
  BilinearDemosaic m = best.model;
  refit(m);
  for (int round = 0; round < 2; ++round) {
    for (const bool a : {true, false}) {
      // Green keeps at least 5 % of the gray.
      const double other = a ? m.share_b : m.share_a;
      const GoldenSectionResult r = GoldenSectionMinimize(
          [&](double share) {
            BilinearDemosaic t = m;
            (a ? t.share_a : t.share_b) = share;
            return held(t);
          },
          0.01, std::min(0.6, 0.95 - other), 7);
      (a ? m.share_a : m.share_b) = r.x;
    }
    best.cost = refit(m);
  }
  best.model = m;
  return best;
}

}  // namespace kincal
