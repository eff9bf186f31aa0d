#ifndef KINCAL_VISION_BAYER_H_
#define KINCAL_VISION_BAYER_H_

// A colour camera's raw mosaic (one photosite per pixel, each behind its
// own colour filter; GenICam BayerRG8 etc.) made a gray image without
// demosaicing: each of the four pixel phases is scaled by its own gain,
// measured on the image itself, so gray paper reads the same through every
// filter. A demosaic would instead blur the four phases differently (see
// docs/VISION.md, "Demosaiced (Bayer) images"), which skews the edges the
// corner refinement fits; balancing keeps every pixel's own sample.

#include <array>
#include <opencv2/core.hpp>
#include <string>

namespace kincal {

// The colours of the mosaic's top-left 2x2 cell, row by row (RGGB = R G /
// G B; GenICam BayerRG). kNone: the image is not a mosaic.
enum class BayerPattern { kNone, kRggb, kGrbg, kGbrg, kBggr };

// "RGGB", "GRBG", "GBRG", "BGGR" (any case) or "none"; InputError otherwise.
BayerPattern ParseBayerPattern(const std::string& name);
std::string BayerPatternName(BayerPattern pattern);

// The phase index of pixel (x, y): (x % 2) + 2 (y % 2).
inline int BayerPhase(int x, int y) { return (x & 1) + 2 * (y & 1); }

// What the balance measured. gain[phase] is the phase's response to gray
// paper relative to the brightest phase's (<= 1); the balanced image
// divides each photosite by it.
struct BayerBalance {
  std::array<double, 4> gain = {1, 1, 1, 1};
  int cells = 0;  // bright flat 2x2 cells the gains were measured on
  // The two green phases' gains differ by more than 10 %, or too few cells
  // (< kMinCells) were bright and flat (the gains are then 1): the image
  // may not be a mosaic of this pattern.
  bool doubtful = false;
  static constexpr int kMinCells = 50;
};

// Measures the four gains: over 2x2 cells (every second one in x and y)
// that are bright (mean >= 0.6 x
// the 95th percentile of the cells' means, none saturated) and flat (each
// phase within 8 % in the cells right of and below), the median of each
// phase's value over the cell's mean; normalised to the largest. Gray
// paper fills most such cells on a tag target; a coloured surface among
// them moves the medians little.
BayerBalance MeasureBayerBalance(const cv::Mat& mosaic, BayerPattern pattern);

// True when a gray image looks like a raw mosaic read as gray: over bright
// flat cells its pixel phases differ in gain by more than 15 % (a gray or
// demosaiced image's phases agree on flat paper).
bool LooksLikeRawMosaic(const cv::Mat& gray);

// The mosaic (CV_8UC1) as a balanced
// 8-bit gray image: each photosite / its phase's gain, rounded and
// saturated. `balance` (optional) receives what was measured. kNone
// returns the image as it is.
cv::Mat BalanceBayerMosaic(const cv::Mat& mosaic, BayerPattern pattern,
                           BayerBalance* balance = nullptr);

}  // namespace kincal

#endif  // KINCAL_VISION_BAYER_H_
