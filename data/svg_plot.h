#ifndef KINCAL_DATA_SVG_PLOT_H_
#define KINCAL_DATA_SVG_PLOT_H_

// A small line/scatter plot written as SVG (a self-contained image format that
// needs no library): axes with ticks, several series with a legend, optional
// horizontal reference lines (e.g. the seed's eta = 1 mm). Used for the
// sensitivity curves (Fig. 2/3), the clearance test (Fig. 4/5/6) and every
// figure of the report. One style for all: one type scale (title 15, axis
// labels 13, ticks and legend 12 px at 1:1), the legend below the plot
// (outside the data; its rows add to the plot's height), the data ranges
// padded so markers at the extremes are drawn whole, colour-bar ticks at
// round values.

#include <limits>
#include <string>
#include <vector>

namespace kincal {

struct PlotSeries {
  std::string label;
  std::vector<double> x, y;
  bool points = false;  // markers instead of a line
  bool bars = false;    // vertical bars from 0 (per-pose charts)
  // Optional per-point colour value (markers coloured on a blue-to-red
  // scale, with a colour bar labelled `color_label`); empty = series colour.
  std::vector<double> color = {};
  std::string color_label = "";
  // Optional per-point arrows (x, y) -> (x + dx, y + dy) in data units
  // (3D error vectors projected on a plane); empty = none.
  std::vector<double> dx = {}, dy = {};
  // Palette index of the series' colour (-1: its position in the plot), e.g.
  // to draw a trend line in the colour of the markers it summarises.
  int color_index = -1;
  // Heat-map cells: when > 0, each point is drawn as a filled rectangle of
  // this size (data units) centred on it, coloured by `color`.
  double cell_w = 0.0, cell_h = 0.0;
  // Fixed ends of the colour scale (NaN: the data's range), so that two
  // plots can share one scale.
  double color_lo = std::numeric_limits<double>::quiet_NaN();
  double color_hi = std::numeric_limits<double>::quiet_NaN();
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
  // Fixed y range (NaN = from the data). Data outside is clipped to the
  // frame, e.g. to show a minimum near zero beside curves that reach far up.
  double y_min = std::numeric_limits<double>::quiet_NaN();
  double y_max = std::numeric_limits<double>::quiet_NaN();
  // Fixed x range (NaN = from the data).
  double x_min = std::numeric_limits<double>::quiet_NaN();
  double x_max = std::numeric_limits<double>::quiet_NaN();
  // Same x and y scale (workspace views).
  bool equal_axes = false;
  // y grows downwards (image rows): the smallest y at the top.
  bool y_down = false;
};

// A standalone SVG file of the plot: XML declaration, then the command line
// and version in a <desc> element (not in a comment: a command line holds
// "--", which XML forbids inside comments). Well-formed XML.
std::string FormatSvgPlot(const Plot& plot);

// Several plots stacked vertically in one SVG file.
std::string FormatSvgPlots(const std::vector<Plot>& plots);

// The plot as an <svg> element to inline into HTML (no XML declaration, no
// provenance; viewBox set so it scales with the page). `id` names the
// element and prefixes its clip path (unique per page).
std::string FormatInlineSvg(const Plot& plot, const std::string& id);

// Text escaped for XML / HTML character data and attribute values.
std::string XmlEscape(const std::string& text);

}  // namespace kincal

#endif  // KINCAL_DATA_SVG_PLOT_H_
