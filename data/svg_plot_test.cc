#include "data/svg_plot.h"

#include <gtest/gtest.h>

namespace kincal {
namespace {

TEST(SvgPlotTest, WritesSeriesLegendAndReferenceLine) {
  Plot p;
  p.title = "eps vs j3.a";
  p.series.push_back({"j3.a", {-5, 0, 5}, {2.0, 0.5, 2.2}});
  p.series.push_back({"poses", {1, 2, 3}, {0.3, 0.7, 0.1}, false, true});
  p.lines.push_back({1.0, "eta = 1 mm"});
  const std::string svg = FormatSvgPlot(p);
  EXPECT_NE(svg.find("<svg"), std::string::npos);
  EXPECT_NE(svg.find("<polyline"), std::string::npos);
  EXPECT_NE(svg.find("eta = 1 mm"), std::string::npos);
  EXPECT_EQ(svg.find("nan"), std::string::npos);
  EXPECT_NE(svg.rfind("</svg>"), std::string::npos);
}

TEST(SvgPlotTest, EmptyAndDegenerateDataStillValid) {
  Plot p;
  p.series.push_back({"flat", {1, 1}, {2, 2}});
  const std::string svg = FormatSvgPlots({p, Plot{}});
  EXPECT_EQ(svg.find("nan"), std::string::npos);
  EXPECT_EQ(svg.find("inf"), std::string::npos);
}

}  // namespace
}  // namespace kincal
