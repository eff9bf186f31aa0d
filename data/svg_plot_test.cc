#include "data/svg_plot.h"

#include <gtest/gtest.h>
#include <tinyxml2.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>

#include "data/provenance.h"

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

// tinyxml2's strict parse: fails on "--" inside a comment, unbalanced tags,
// unescaped '<' or '&'.
void ExpectWellFormed(const std::string& xml) {
  tinyxml2::XMLDocument doc;
  EXPECT_EQ(doc.Parse(xml.c_str(), xml.size()), tinyxml2::XML_SUCCESS)
      << doc.ErrorStr() << "\n"
      << xml.substr(0, 400);
}

TEST(SvgPlotTest, WellFormedWithDoubleHyphensAndMarkupInCommandLine) {
  const std::string saved = CommandLine();
  SetCommandLine(
      "kincal diagnose clearance --robot 'a&b<c>.yaml' --gamma 3 --plot x.svg "
      "-- ---");
  Plot p;
  p.title = "a < b & c -- \"quoted\" 'single'";
  p.x_label = "offset (deg | mm) --";
  p.series.push_back({"j3 <deg>", {-3, 0, 3}, {25, 0.1, 25}});
  const std::string svg = FormatSvgPlots({p, p});
  SetCommandLine(saved);
  ExpectWellFormed(svg);
  // No comment holds "--" (the XML rule that broke rsvg-convert and browsers).
  for (size_t at = svg.find("<!--"); at != std::string::npos;
       at = svg.find("<!--", at + 4)) {
    const size_t end = svg.find("-->", at + 4);
    ASSERT_NE(end, std::string::npos);
    EXPECT_EQ(svg.substr(at + 4, end - at - 4).find("--"), std::string::npos);
  }
  // Provenance still recorded.
  EXPECT_NE(svg.find("--gamma 3"), std::string::npos);
  // Strict outside checker when installed.
  if (std::system("command -v xmllint >/dev/null 2>&1") == 0) {
    const std::string path = ::testing::TempDir() + "kincal_svg_check.svg";
    std::ofstream(path) << svg;
    EXPECT_EQ(std::system(("xmllint --noout " + path).c_str()), 0);
    std::remove(path.c_str());
  }
}

TEST(SvgPlotTest, FixedRangeClipsAndInlineSvgIsWellFormed) {
  Plot p;
  p.title = "sweep";
  p.series.push_back({"j3", {-3, -1, 0, 1, 3}, {25, 2, 0.05, 2, 25}});
  p.y_min = 0;
  p.y_max = 1;
  PlotSeries scatter{"coloured", {0, 1, 2}, {0.2, 0.5, 0.9}, true};
  scatter.color = {0.1, 0.5, 3.0};
  scatter.color_label = "|e| (mm)";
  scatter.dx = {0.1, 0.1, -0.1};
  scatter.dy = {0.0, 0.1, 0.1};
  p.series.push_back(scatter);
  const std::string svg = FormatInlineSvg(p, "fig1");
  ExpectWellFormed(svg);
  EXPECT_EQ(svg.find("<?xml"), std::string::npos);
  EXPECT_NE(svg.find("clip-path='url(#fig1clip0)'"), std::string::npos);
  EXPECT_NE(svg.find("|e| (mm)"), std::string::npos);
  // Tick labels follow the fixed range, not the data's 25.
  EXPECT_EQ(svg.find(">25<"), std::string::npos);
  EXPECT_NE(svg.find(">0.2<"), std::string::npos);
}

// The frame (the data area): the first unfilled rectangle.
struct Box {
  double x = 0, y = 0, w = 0, h = 0;
};
Box FrameOf(tinyxml2::XMLElement* svg) {
  for (auto* e = svg->FirstChildElement("rect"); e;
       e = e->NextSiblingElement("rect")) {
    if (std::string(e->Attribute("fill") ? e->Attribute("fill") : "") ==
        "none") {
      return {e->DoubleAttribute("x"), e->DoubleAttribute("y"),
              e->DoubleAttribute("width"), e->DoubleAttribute("height")};
    }
  }
  return {};
}

TEST(SvgPlotTest, LegendSitsBelowTheDataAndAddsHeight) {
  Plot p;
  p.width = 500;
  p.height = 300;
  p.series.push_back({"first series", {0, 1, 2}, {1, 2, 3}, true});
  p.series.push_back({"second series", {0, 1, 2}, {3, 2, 1}, true});
  p.lines.push_back({2.5, "limit"});
  const std::string svg = FormatInlineSvg(p, "f");
  tinyxml2::XMLDocument doc;
  ASSERT_EQ(doc.Parse(svg.c_str()), tinyxml2::XML_SUCCESS);
  tinyxml2::XMLElement* root = doc.RootElement();
  EXPECT_GT(root->IntAttribute("height"), 300);
  const Box frame = FrameOf(root);
  ASSERT_GT(frame.h, 0);
  int found = 0;
  for (auto* t = root->FirstChildElement("text"); t;
       t = t->NextSiblingElement("text")) {
    const std::string text = t->GetText() ? t->GetText() : "";
    if (text == "first series" || text == "second series" || text == "limit") {
      ++found;
      EXPECT_GT(t->DoubleAttribute("y"), frame.y + frame.h + 30) << text;
    }
  }
  EXPECT_EQ(found, 3);
}

TEST(SvgPlotTest, MarkersAtTheEdgesAreInsideTheFrame) {
  Plot p;
  p.series.push_back({"", {0, 10}, {0, 5}, true});
  const std::string svg = FormatInlineSvg(p, "f");
  tinyxml2::XMLDocument doc;
  ASSERT_EQ(doc.Parse(svg.c_str()), tinyxml2::XML_SUCCESS);
  const Box frame = FrameOf(doc.RootElement());
  auto* g = doc.RootElement()->FirstChildElement("g");
  ASSERT_NE(g, nullptr);
  int circles = 0;
  for (auto* c = g->FirstChildElement("circle"); c;
       c = c->NextSiblingElement("circle")) {
    ++circles;
    const double cx = c->DoubleAttribute("cx"), cy = c->DoubleAttribute("cy");
    const double r = c->DoubleAttribute("r");
    EXPECT_GE(cx - r, frame.x);
    EXPECT_LE(cx + r, frame.x + frame.w);
    EXPECT_GE(cy - r, frame.y);
    EXPECT_LE(cy + r, frame.y + frame.h);
  }
  EXPECT_EQ(circles, 2);
}

TEST(SvgPlotTest, ColourBarLabelsAreRound) {
  Plot p;
  PlotSeries s{"", {0, 1, 2}, {0, 1, 2}, true};
  s.color = {0.1234567, 1.5, 2.9876543};
  s.color_label = "|e| (mm)";
  p.series.push_back(s);
  const std::string svg = FormatInlineSvg(p, "f");
  EXPECT_EQ(svg.find("2.98765"), std::string::npos);
  EXPECT_EQ(svg.find("0.123457"), std::string::npos);
  EXPECT_NE(svg.find(">0.5<"), std::string::npos);
  EXPECT_NE(svg.find(">2.5<"), std::string::npos);
}

}  // namespace
}  // namespace kincal
