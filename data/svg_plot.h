#ifndef KINCAL_DATA_SVG_PLOT_H_
#define KINCAL_DATA_SVG_PLOT_H_

// A small line/scatter plot written as SVG (a self-contained image format that
// needs no library): axes with ticks, several series with a legend, optional
// horizontal reference lines (e.g. the seed's eta = 1 mm). Used for the
// sensitivity curves (Fig. 2/3) and the clearance test (Fig. 4/5/6).

#include <string>
#include <vector>

namespace kincal {

struct PlotSeries {
  std::string label;
  std::vector<double> x, y;
  bool points = false;  // markers instead of a line
  bool bars = false;    // vertical bars from 0 (per-pose charts)
};

struct PlotLine {  // horizontal reference line
  double y = 0.0;
  std::string label;
};

struct Plot {
  std::string title, x_label, y_label;
  std::vector<PlotSeries> series;
  std::vector<PlotLine> lines;
  int width = 800, height = 500;
};

// SVG text of the plot (provenance as an XML comment).
std::string FormatSvgPlot(const Plot& plot);

// Several plots stacked vertically in one SVG.
std::string FormatSvgPlots(const std::vector<Plot>& plots);

}  // namespace kincal

#endif  // KINCAL_DATA_SVG_PLOT_H_
