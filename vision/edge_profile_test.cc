#include "vision/edge_profile.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

namespace kincal {
namespace {

// A blurred pattern sampled at 0.25 px: data bit (white) | black ring |
// white border | outside, with the edge at `edge` and a cell of `cell` px.
EdgeProfile Synthetic(double edge, double cell, double sigma, double black,
                      double white, double outside, double noise,
                      std::mt19937_64* rng) {
  EdgeProfile p;
  // The pattern as the caller believes it placed (edge at 0).
  p.breaks = {-cell, 0.0, cell};
  p.classes = {1, 0, 1, 2};
  std::normal_distribution<double> n(0, noise);
  const double levels[3] = {black, white, outside};
  for (double o = -1.5 * cell; o <= 1.5 * cell; o += 0.25) {
    double v = 0, prev = 1.0;
    for (size_t i = 0; i <= p.breaks.size(); ++i) {
      const double phi =
          i < p.breaks.size()
              ? 0.5 * std::erfc(-(o - edge - p.breaks[i]) / (sigma * M_SQRT2))
              : 0.0;
      v += levels[p.classes[i]] * (prev - phi);
      prev = phi;
    }
    p.offsets.push_back(o);
    p.values.push_back(v + (noise > 0 ? n(*rng) : 0.0));
  }
  return p;
}

TEST(EdgeProfile, FastPhiMatchesErfc) {
  for (double x = -7; x <= 7; x += 0.013) {
    EXPECT_NEAR(FastPhi(x), 0.5 * std::erfc(-x / M_SQRT2), 2e-5) << x;
  }
}

TEST(EdgeProfile, RecoversTheShiftUnderWideBlurWithNeighbours) {
  std::mt19937_64 rng(3);
  // A cell of 3 px under sigma 1.4 px: the white data bit and the dark
  // outside both reach the edge; the model holds them.
  for (double edge : {-0.7, -0.2, 0.0, 0.35, 0.9}) {
    const EdgeProfile p = Synthetic(edge, 3.0, 1.4, 30, 220, 60, 0, &rng);
    const EdgeProfileFit f = FitEdgeProfile(p, 1.4);
    ASSERT_TRUE(f.ok);
    EXPECT_NEAR(f.shift_px, edge, 1e-3);
    EXPECT_NEAR(f.levels[0], 30, 0.05);
    EXPECT_NEAR(f.levels[1], 220, 0.05);
    EXPECT_NEAR(f.levels[2], 60, 0.05);
  }
}

// Pixel values across an edge at `edge` (pattern of Synthetic, cell 4 px)
// read at pixel centres o = k + 0.3, alternating between two Bayer phases
// (0 and 3) blurred by sigma[0] and sigma[3]; each averaged over a pixel
// box of `box` px along the normal (0: none) by a 64-point midpoint rule.
EdgeProfile PhasedPixels(double edge, const PhaseSigmas& sigma, double box) {
  EdgeProfile p;
  p.breaks = {-4.0, 0.0, 4.0};
  p.classes = {1, 0, 1, 2};
  const EdgeProfile point = p;  // the model at a point, no box
  p.box_px = box;
  for (int k = -6; k <= 6; ++k) {
    const double o = k + 0.3;
    const int phase = (k & 1) ? 3 : 0;
    double v = 0;
    const int n = box > 0 ? 64 : 1;
    for (int j = 0; j < n; ++j) {
      const double u = box > 0 ? box * ((j + 0.5) / n - 0.5) : 0.0;
      v += EdgeProfileModel(point, {o + u}, edge, sigma[phase],
                            {30, 220, 60})[0];
    }
    p.offsets.push_back(o);
    p.values.push_back(v / n);
    p.phases.push_back(phase);
  }
  return p;
}

TEST(EdgeProfile, BlurPerPhaseRecoversTheShiftOneBlurDoesNot) {
  // A demosaic's phases: one sharp (0.6 px), one blunt (1.1 px), each
  // symmetric about its pixel. One blur for both skews the profile.
  const PhaseSigmas sigma = {0.6, 1.0, 1.0, 1.1};
  double worst_one_blur = 0;
  for (double edge : {-0.4, -0.1, 0.2, 0.45}) {
    const EdgeProfile p = PhasedPixels(edge, sigma, 0);
    const EdgeProfileFit f = FitEdgeProfile(p, sigma);
    ASSERT_TRUE(f.ok);
    EXPECT_NEAR(f.shift_px, edge, 1e-3);
    EdgeProfile unphased = p;
    unphased.phases.clear();
    const EdgeProfileFit one = FitEdgeProfile(unphased, 0.85);
    ASSERT_TRUE(one.ok);
    worst_one_blur = std::max(worst_one_blur, std::abs(one.shift_px - edge));
  }
  EXPECT_GT(worst_one_blur, 0.02);
}

TEST(EdgeProfile, PixelBoxIsInTheModel) {
  const PhaseSigmas sigma = {0.4, 0.4, 0.4, 0.4};
  for (double edge : {-0.3, 0.0, 0.25}) {
    const EdgeProfile p = PhasedPixels(edge, sigma, 1.0);
    const EdgeProfileFit f = FitEdgeProfile(p, sigma);
    ASSERT_TRUE(f.ok);
    EXPECT_NEAR(f.shift_px, edge, 2e-3);
    EXPECT_LT(f.rms, 0.2);  // gray levels, of a contrast of 190
  }
}

// Beside a data bit's edge along the side, the blur mixes the line through
// the white bit with the line through the black ring's continuation: a
// profile that is 60 % the one and 40 % the other. Its own line's pattern
// alone moves the edge; the mixture in the model puts it back.
TEST(EdgeProfile, MixtureOfTheLinesBesideRecoversTheShift) {
  const double cell = 3.0, sigma = 1.1;
  PatternLine bit{{-cell, 0.0, cell}, {1, 0, 1, 2}, 0.6};
  PatternLine ring{{0.0, cell}, {0, 1, 2}, 0.4};
  for (double edge : {-0.4, 0.0, 0.3}) {
    EdgeProfile p;
    p.breaks = bit.breaks;
    p.classes = bit.classes;
    for (double o = -1.5 * cell; o <= 1.5 * cell + 1e-9; o += 0.25) {
      p.offsets.push_back(o);
    }
    for (const PatternLine& line : {bit, ring}) {
      EdgeProfile one;
      one.breaks = line.breaks;
      one.classes = line.classes;
      const std::vector<double> v =
          EdgeProfileModel(one, p.offsets, edge, sigma, {30, 220, 60});
      p.values.resize(v.size());
      for (size_t i = 0; i < v.size(); ++i) p.values[i] += line.weight * v[i];
    }
    const EdgeProfileFit alone = FitEdgeProfile(p, sigma);
    ASSERT_TRUE(alone.ok);
    EXPECT_GT(std::abs(alone.shift_px - edge), 0.05) << edge;
    p.mixture = {bit, ring};
    const EdgeProfileFit mixed = FitEdgeProfile(p, sigma);
    ASSERT_TRUE(mixed.ok);
    EXPECT_NEAR(mixed.shift_px, edge, 1e-3);
    EXPECT_NEAR(mixed.levels[0], 30, 0.05);
    EXPECT_NEAR(mixed.levels[1], 220, 0.05);
  }
}

TEST(EdgeProfile, ModelReproducesTheProfileItWasFittedTo) {
  std::mt19937_64 rng(5);
  const EdgeProfile p = Synthetic(0.3, 3.0, 0.9, 30, 220, 60, 0, &rng);
  const EdgeProfileFit f = FitEdgeProfile(p, 0.9);
  ASSERT_TRUE(f.ok);
  const std::vector<double> m =
      EdgeProfileModel(p, p.offsets, f.shift_px, 0.9, f.levels);
  ASSERT_EQ(m.size(), p.values.size());
  for (size_t i = 0; i < m.size(); ++i) {
    EXPECT_NEAR(m[i], p.values[i], 0.01) << p.offsets[i];
  }
  // A different shift moves the model's edge: the value at the edge
  // changes by about the slope times the shift.
  const std::vector<double> moved =
      EdgeProfileModel(p, {0.3}, f.shift_px + 0.1, 0.9, f.levels);
  EXPECT_GT(std::abs(moved[0] -
                     EdgeProfileModel(p, {0.3}, f.shift_px, 0.9, f.levels)[0]),
            5.0);
}

TEST(EdgeProfile, ModelAreaIsTheIntegralOfTheModel) {
  std::mt19937_64 rng(5);
  const EdgeProfile p = Synthetic(0.3, 3.0, 0.6, 30, 220, 60, 0, &rng);
  const std::array<double, 3> levels = {30, 220, 60};
  for (const double shift : {-0.4, 0.0, 0.25}) {
    // Midpoint rule on a 1e-4 px grid.
    const double lo = -1.7, hi = 2.1, h = 1e-4;
    std::vector<double> o;
    for (double x = lo + h / 2; x < hi; x += h) o.push_back(x);
    double numeric = 0;
    for (double v : EdgeProfileModel(p, o, shift, 0.6, levels)) {
      numeric += v * h;
    }
    EXPECT_NEAR(EdgeProfileModelArea(p, lo, hi, shift, 0.6, levels), numeric,
                0.01)
        << shift;
  }
}

TEST(EdgeProfile, LevelsDoNotMoveTheEdge) {
  std::mt19937_64 rng(4);
  // A dim, low-contrast tag (paper at 60, black at 20) in a bright
  // surround, and noise: the shift stays unbiased.
  double sum = 0, sum_sq = 0;
  const int n = 200;
  for (int i = 0; i < n; ++i) {
    const EdgeProfile p = Synthetic(0.3, 4.0, 1.0, 20, 60, 150, 1.5, &rng);
    const EdgeProfileFit f = FitEdgeProfile(p, 1.0);
    ASSERT_TRUE(f.ok);
    sum += f.shift_px - 0.3;
    sum_sq += (f.shift_px - 0.3) * (f.shift_px - 0.3);
  }
  EXPECT_LT(std::abs(sum / n), 0.01);
  EXPECT_LT(std::sqrt(sum_sq / n), 0.1);
}

// A sharp edge as a pixel-integrated step sampled between pixel centres
// looks: a ramp one pixel wide, not centred on a sample. The area rule
// puts it exactly.
TEST(EdgeProfile, AreaRuleIsExactForASharpRamp) {
  for (double edge : {-0.37, 0.0, 0.21, 0.5}) {
    EdgeProfile p;
    for (double o = -4; o <= 4; o += 0.25) {
      p.offsets.push_back(o);
      p.values.push_back(30 + 190 * std::clamp(o - (edge - 0.5), 0.0, 1.0));
    }
    EXPECT_NEAR(AreaRuleShift(p, 30, 220, 0.1, 2.5), edge, 1e-9) << edge;
  }
}

TEST(EdgeProfile, RefusesAFlatProfile) {
  EdgeProfile p;
  p.breaks = {0.0};
  p.classes = {0, 1};
  for (double o = -3; o <= 3; o += 0.25) {
    p.offsets.push_back(o);
    p.values.push_back(100);
  }
  EXPECT_FALSE(FitEdgeProfile(p, 1.0).ok);
}

}  // namespace
}  // namespace kincal
