#include "vision/bayer.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "data/error.h"

namespace kincal {
namespace {

// A gray scene (smooth shading, bright paper with dark squares) seen
// through an RGGB mosaic with the given gains per phase, noise 1.5.
cv::Mat Mosaic(const std::array<double, 4>& gain, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0, 1.5);
  cv::Mat m(240, 320, CV_8UC1);
  for (int y = 0; y < m.rows; ++y) {
    for (int x = 0; x < m.cols; ++x) {
      const bool dark = (x / 40 + y / 40) % 3 == 0;
      const double scene = (dark ? 30.0 : 200.0) * (1.0 - 0.3 * x / m.cols);
      m.at<uint8_t>(y, x) = cv::saturate_cast<uint8_t>(
          scene * gain[BayerPhase(x, y)] + noise(rng));
    }
  }
  return m;
}

TEST(BayerBalance, MeasuresEachPhasesGainFromTheImage) {
  const std::array<double, 4> gain = {0.55, 1.0, 1.0, 0.75};  // R G / G B
  BayerBalance b;
  const cv::Mat gray =
      BalanceBayerMosaic(Mosaic(gain, 1), BayerPattern::kRggb, &b);
  EXPECT_FALSE(b.doubtful);
  EXPECT_GT(b.cells, 1000);
  for (int p = 0; p < 4; ++p) EXPECT_NEAR(b.gain[p], gain[p], 0.01) << p;
  // Balanced: neighbouring photosites of the flat paper agree (the mosaic's
  // R and G differ by 90 gray levels there).
  for (const cv::Point at : {cv::Point(50, 10), cv::Point(201, 121)}) {
    const int a = gray.at<uint8_t>(at),
              r = gray.at<uint8_t>(at + cv::Point(1, 0));
    const int d = gray.at<uint8_t>(at + cv::Point(0, 1));
    EXPECT_NEAR(a, r, 8) << at;
    EXPECT_NEAR(a, d, 8) << at;
  }
}

TEST(BayerBalance, GrayImageKeepsItsValues) {
  const cv::Mat m = Mosaic({1, 1, 1, 1}, 2);
  BayerBalance b;
  const cv::Mat gray = BalanceBayerMosaic(m, BayerPattern::kGrbg, &b);
  EXPECT_FALSE(b.doubtful);
  for (int p = 0; p < 4; ++p) EXPECT_NEAR(b.gain[p], 1.0, 0.01) << p;
  EXPECT_LE(cv::norm(gray, m, cv::NORM_INF), 3);
  EXPECT_EQ(
      cv::norm(BalanceBayerMosaic(m, BayerPattern::kNone), m, cv::NORM_INF), 0);
}

TEST(BayerBalance, WrongPatternOrNoPaperIsDoubtful) {
  // RGGB's greens named as red and blue (GRBG): its "greens" differ.
  BayerBalance b = MeasureBayerBalance(Mosaic({0.55, 1.0, 1.0, 0.75}, 3),
                                       BayerPattern::kGrbg);
  EXPECT_TRUE(b.doubtful);
  // Pure noise: no bright flat cells.
  cv::Mat noise(64, 64, CV_8UC1);
  cv::randu(noise, 0, 255);
  b = MeasureBayerBalance(noise, BayerPattern::kRggb);
  EXPECT_TRUE(b.doubtful);
  EXPECT_EQ(b.gain[0], 1.0);
}

TEST(BayerBalance, TellsARawMosaicReadAsGray) {
  EXPECT_TRUE(LooksLikeRawMosaic(Mosaic({0.55, 1.0, 1.0, 0.75}, 4)));
  EXPECT_FALSE(LooksLikeRawMosaic(Mosaic({1, 1, 1, 1}, 4)));
  EXPECT_FALSE(LooksLikeRawMosaic(Mosaic({0.95, 1.0, 1.0, 0.95}, 4)));
}

TEST(BayerBalance, PatternNames) {
  EXPECT_EQ(ParseBayerPattern("rggb"), BayerPattern::kRggb);
  EXPECT_EQ(ParseBayerPattern("BGGR"), BayerPattern::kBggr);
  EXPECT_EQ(ParseBayerPattern("none"), BayerPattern::kNone);
  EXPECT_EQ(BayerPatternName(BayerPattern::kGbrg), "GBRG");
  EXPECT_THROW(ParseBayerPattern("RGB"), InputError);
  EXPECT_THROW(MeasureBayerBalance(cv::Mat(8, 8, CV_8UC3), BayerPattern::kRggb),
               InputError);
}

}  // namespace
}  // namespace kincal
