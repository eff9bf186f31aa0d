#include "vision/demosaic_model.h"

#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/imgproc.hpp>
#include <random>

namespace kincal {
namespace {

// The gray a bilinear demosaic gives at (x, y) by the kernels.
double KernelGray(const cv::Mat& raw, const DemosaicKernels& k, int x, int y) {
  const std::array<double, 9>& w = k.weights[(x & 1) + 2 * (y & 1)];
  double v = 0;
  for (int dy = -1; dy <= 1; ++dy) {
    for (int dx = -1; dx <= 1; ++dx) {
      v += w[(dy + 1) * 3 + dx + 1] * raw.at<uint16_t>(y + dy, x + dx);
    }
  }
  return v;
}

// OpenCV's Bayer to gray is the bilinear demosaic with its gray weights as
// the shares: R at (even x, even y) for its "BG" code (RGGB), at (odd x,
// even y) for "GB" (GRBG); to OpenCV's fixed-point weights (1e-4).
TEST(DemosaicModel, KernelsAreOpenCvsBayerToGray) {
  cv::Mat raw(24, 24, CV_16UC1);
  cv::randu(raw, 0, 60000);
  struct Case {
    int code;
    bool greens_on_03;
  };
  for (const Case c : {Case{cv::COLOR_BayerBG2GRAY, false},
                       Case{cv::COLOR_BayerGB2GRAY, true}}) {
    cv::Mat gray;
    cv::cvtColor(raw, gray, c.code);
    BilinearDemosaic m;
    m.greens_on_03 = c.greens_on_03;
    m.share_a = 0.299;  // red
    m.share_b = 0.114;  // blue
    const DemosaicKernels k = m.Kernels();
    for (int p = 0; p < 4; ++p) {
      double sum = 0;
      for (const double w : k.weights[p]) sum += w;
      EXPECT_NEAR(sum, 1.0, 1e-12);
    }
    for (int y = 2; y < 22; ++y) {
      for (int x = 2; x < 22; ++x) {
        EXPECT_NEAR(gray.at<uint16_t>(y, x), KernelGray(raw, k, x, y), 4.0)
            << x << " " << y;
      }
    }
  }
}

// A straight edge across a raw mosaic (channel gains 0.55 / 1 / 0.75 on a
// blurred pattern: white data bit | black ring | white border | outside,
// 3 px cells), demosaiced by OpenCV to gray (16 bits: no rounding to
// speak of). The edge at `edge` px along `n` from (20, 20).
struct DemosaicedEdge {
  cv::Mat gray;
  EdgeProfile pattern;  // breaks and classes as placed (edge at 0)
};

DemosaicedEdge RenderEdge(const Eigen::Vector2d& n, double edge, double sigma,
                          int code) {
  DemosaicedEdge out;
  out.pattern.breaks = {-3.0, 0.0, 3.0};
  out.pattern.classes = {1, 0, 1, 2};
  out.pattern.box_px = std::max(std::abs(n.x()), std::abs(n.y()));
  const bool greens_on_03 = code == cv::COLOR_BayerGB2GRAY;
  cv::Mat raw(40, 40, CV_16UC1);
  for (int y = 0; y < 40; ++y) {
    for (int x = 0; x < 40; ++x) {
      const int phase = (x & 1) + 2 * (y & 1);
      const bool green = greens_on_03 ? (phase == 0 || phase == 3)
                                      : (phase == 1 || phase == 2);
      const bool red = greens_on_03 ? phase == 1 : phase == 0;
      const double gain = green ? 1.0 : red ? 0.55 : 0.75;
      const double o = n.dot(Eigen::Vector2d(x - 20, y - 20));
      const double v = EdgeProfileModel(out.pattern, {o}, edge, sigma,
                                        {3000, 22000, 6000})[0];
      raw.at<uint16_t>(y, x) = cv::saturate_cast<uint16_t>(gain * v);
    }
  }
  cv::cvtColor(raw, out.gray, code);
  return out;
}

// The pixels whose centres lie within 0.5 px along the side of the point
// `along` px from (20, 20), within 6 px of it across.
EdgeProfile PixelStrip(const DemosaicedEdge& e, const Eigen::Vector2d& n,
                       double along) {
  EdgeProfile p = e.pattern;
  const Eigen::Vector2d dir(-n.y(), n.x());
  const Eigen::Vector2d base = Eigen::Vector2d(20, 20) + along * dir;
  for (int y = 4; y < 36; ++y) {
    for (int x = 4; x < 36; ++x) {
      const Eigen::Vector2d d = Eigen::Vector2d(x, y) - base;
      if (std::abs(dir.dot(d)) >= 0.5 || std::abs(n.dot(d)) > 6) continue;
      p.offsets.push_back(n.dot(d));
      p.values.push_back(e.gray.at<uint16_t>(y, x));
      p.phases.push_back((x & 1) + 2 * (y & 1));
    }
  }
  return p;
}

BilinearDemosaic TrueModel(int code) {
  BilinearDemosaic m;
  m.greens_on_03 = code == cv::COLOR_BayerGB2GRAY;
  const double r = 0.299 * 0.55, g = 0.587, b = 0.114 * 0.75;
  m.share_a = r / (r + g + b);
  m.share_b = b / (r + g + b);
  return m;
}

// With the demosaic's kernels the edge is found where it is, at any
// direction and position along the side.
TEST(DemosaicModel, FitFindsTheEdgeOfADemosaicedImage) {
  const DemosaicKernels k = TrueModel(cv::COLOR_BayerBG2GRAY).Kernels();
  for (const double deg : {0.0, 20.0, 45.0, 70.0, 100.0, 200.0}) {
    const Eigen::Vector2d n(std::cos(deg * M_PI / 180),
                            std::sin(deg * M_PI / 180));
    for (const double edge : {-0.4, 0.0, 0.25, 0.6}) {
      const DemosaicedEdge e = RenderEdge(n, edge, 0.5, cv::COLOR_BayerBG2GRAY);
      for (const double along : {-1.0, 0.0, 1.25}) {
        const EdgeProfileFit f =
            FitDemosaicedProfile(PixelStrip(e, n, along), n, k, 0.5);
        ASSERT_TRUE(f.ok);
        EXPECT_NEAR(f.shift_px, edge, 0.002) << deg << " " << along;
        EXPECT_NEAR(f.levels[1] - f.levels[0], 0.837 * 19000, 20);
      }
    }
  }
}

// The shares and the green layout are found from the edges themselves.
TEST(DemosaicModel, FitFindsTheSharesAndLayout) {
  for (const int code : {cv::COLOR_BayerBG2GRAY, cv::COLOR_BayerGB2GRAY}) {
    const BilinearDemosaic truth = TrueModel(code);
    std::vector<std::vector<EdgeProfile>> profiles;
    std::vector<Eigen::Vector2d> normals;
    for (const double deg : {10.0, 100.0, 55.0, 235.0}) {
      const Eigen::Vector2d n(std::cos(deg * M_PI / 180),
                              std::sin(deg * M_PI / 180));
      const DemosaicedEdge e = RenderEdge(n, 0.2, 0.6, code);
      profiles.emplace_back();
      for (double along = -6; along <= 6; along += 1.0) {
        profiles.back().push_back(PixelStrip(e, n, along));
      }
      normals.push_back(n);
    }
    std::vector<DemosaicSide> group;
    for (size_t i = 0; i < profiles.size(); ++i) {
      group.push_back({&profiles[i], normals[i]});
    }
    const BilinearDemosaicFit fit = FitBilinearDemosaic({group});
    EXPECT_EQ(fit.model.greens_on_03, truth.greens_on_03) << code;
    EXPECT_NEAR(fit.model.share_a, truth.share_a, 0.02) << code;
    EXPECT_NEAR(fit.model.share_b, truth.share_b, 0.02) << code;
    EXPECT_NEAR(DemosaicedBlur(group, fit.model.Kernels()), 0.6, 0.05);
  }
}

}  // namespace
}  // namespace kincal
