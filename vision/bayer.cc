#include "vision/bayer.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <vector>

#include "data/error.h"

namespace kincal {
namespace {

// The phases (x % 2 + 2 (y % 2)) that sampled green in `pattern`.
std::array<int, 2> GreenPhases(BayerPattern pattern) {
  return pattern == BayerPattern::kGrbg || pattern == BayerPattern::kGbrg
             ? std::array<int, 2>{0, 3}
             : std::array<int, 2>{1, 2};
}

// The median of values counted in a histogram of `bins` over [0, top).
double HistogramMedian(const std::vector<int>& histogram, double top) {
  long total = 0;
  for (int n : histogram) total += n;
  long seen = 0;
  for (size_t i = 0; i < histogram.size(); ++i) {
    seen += histogram[i];
    if (2 * seen > total) return (i + 0.5) * top / histogram.size();
  }
  return top;
}

// The four photosites of the 2x2 cell whose top-left pixel is (x, y), by
// phase.
std::array<double, 4> Cell(const cv::Mat& m, int x, int y) {
  const uint8_t* r0 = m.ptr<uint8_t>(y);
  const uint8_t* r1 = m.ptr<uint8_t>(y + 1);
  return {static_cast<double>(r0[x]), static_cast<double>(r0[x + 1]),
          static_cast<double>(r1[x]), static_cast<double>(r1[x + 1])};
}

bool Similar(const std::array<double, 4>& a, const std::array<double, 4>& b) {
  for (int p = 0; p < 4; ++p) {
    if (std::abs(a[p] - b[p]) > 0.08 * std::max(a[p], b[p])) return false;
  }
  return true;
}

}  // namespace

BayerPattern ParseBayerPattern(const std::string& name) {
  std::string n = name;
  for (char& c : n) c = static_cast<char>(std::toupper(c));
  if (n == "NONE") return BayerPattern::kNone;
  if (n == "RGGB") return BayerPattern::kRggb;
  if (n == "GRBG") return BayerPattern::kGrbg;
  if (n == "GBRG") return BayerPattern::kGbrg;
  if (n == "BGGR") return BayerPattern::kBggr;
  throw InputError("bayer pattern '" + name +
                   "': expected RGGB, GRBG, GBRG, BGGR or none (the colours "
                   "of the mosaic's top-left 2x2 cell, row by row; GenICam "
                   "BayerRG8 is RGGB)");
}

std::string BayerPatternName(BayerPattern pattern) {
  switch (pattern) {
    case BayerPattern::kRggb:
      return "RGGB";
    case BayerPattern::kGrbg:
      return "GRBG";
    case BayerPattern::kGbrg:
      return "GBRG";
    case BayerPattern::kBggr:
      return "BGGR";
    case BayerPattern::kNone:
      break;
  }
  return "none";
}

BayerBalance MeasureBayerBalance(const cv::Mat& mosaic, BayerPattern pattern) {
  if (mosaic.type() != CV_8UC1) {
    throw InputError("bayer balance: expected an 8-bit one-channel mosaic");
  }
  BayerBalance out;
  if (pattern == BayerPattern::kNone) return out;
  // Cells on the even grid, with a right and a lower neighbour cell.
  const int cx = mosaic.cols / 2 - 1, cy = mosaic.rows / 2 - 1;
  if (cx < 1 || cy < 1) {
    out.doubtful = true;
    return out;
  }
  // Every second cell in x and y (a quarter of them: the gains need far
  // fewer, and the balance runs on every image). The cells' sums of four
  // photosites (0..1020), for the percentile.
  std::vector<int> sums(4 * 255 + 1, 0);
  long cells = 0;
  for (int j = 0; j < cy; j += 2) {
    for (int i = 0; i < cx; i += 2, ++cells) {
      const auto c = Cell(mosaic, 2 * i, 2 * j);
      ++sums[static_cast<int>(c[0] + c[1] + c[2] + c[3])];
    }
  }
  const long p95 = cells * 95 / 100;
  long below = 0;
  int sum95 = 0;
  while (sum95 < 4 * 255 && below + sums[sum95] <= p95) below += sums[sum95++];
  const double bright = 0.6 * 0.25 * sum95;
  // Each phase's value over the cell's mean, binned to 1/2000 over [0, 4).
  constexpr double kTop = 4.0;
  constexpr int kBins = 8000;
  std::array<std::vector<int>, 4> ratios;
  for (auto& r : ratios) r.assign(kBins, 0);
  for (int j = 0; j < cy; j += 2) {
    for (int i = 0; i < cx; i += 2) {
      const auto c = Cell(mosaic, 2 * i, 2 * j);
      const double mean = 0.25 * (c[0] + c[1] + c[2] + c[3]);
      if (mean < bright || mean <= 0) continue;
      if (*std::max_element(c.begin(), c.end()) >= 255) continue;
      if (!Similar(c, Cell(mosaic, 2 * i + 2, 2 * j)) ||
          !Similar(c, Cell(mosaic, 2 * i, 2 * j + 2))) {
        continue;
      }
      for (int p = 0; p < 4; ++p) {
        ++ratios[p][std::min(kBins - 1,
                             static_cast<int>(c[p] / mean * kBins / kTop))];
      }
      ++out.cells;
    }
  }
  if (out.cells < BayerBalance::kMinCells) {
    out.doubtful = true;
    return out;
  }
  for (int p = 0; p < 4; ++p) out.gain[p] = HistogramMedian(ratios[p], kTop);
  const double top = *std::max_element(out.gain.begin(), out.gain.end());
  for (double& g : out.gain) g /= top;
  const auto green = GreenPhases(pattern);
  const double g0 = out.gain[green[0]], g1 = out.gain[green[1]];
  out.doubtful = std::abs(g0 - g1) > 0.1 * std::max(g0, g1);
  return out;
}

bool LooksLikeRawMosaic(const cv::Mat& gray) {
  // The pattern only names the greens; any one measures all four gains.
  const BayerBalance b = MeasureBayerBalance(gray, BayerPattern::kRggb);
  if (b.cells < BayerBalance::kMinCells) return false;
  return *std::min_element(b.gain.begin(), b.gain.end()) < 1 / 1.15;
}

cv::Mat BalanceBayerMosaic(const cv::Mat& mosaic, BayerPattern pattern,
                           BayerBalance* balance) {
  const BayerBalance b = MeasureBayerBalance(mosaic, pattern);
  if (balance != nullptr) *balance = b;
  if (pattern == BayerPattern::kNone) return mosaic;
  cv::Mat out(mosaic.size(), CV_8UC1);
  const std::array<double, 4> scale = {1 / b.gain[0], 1 / b.gain[1],
                                       1 / b.gain[2], 1 / b.gain[3]};
  for (int y = 0; y < mosaic.rows; ++y) {
    const uint8_t* in = mosaic.ptr<uint8_t>(y);
    uint8_t* o = out.ptr<uint8_t>(y);
    for (int x = 0; x < mosaic.cols; ++x) {
      o[x] = cv::saturate_cast<uint8_t>(in[x] * scale[BayerPhase(x, y)]);
    }
  }
  return out;
}

}  // namespace kincal
