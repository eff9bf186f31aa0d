#include "data/svg_plot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <sstream>

#include "data/provenance.h"

namespace kincal {
namespace {

const char* kColors[] = {"#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd",
                         "#8c564b", "#e377c2", "#7f7f7f", "#bcbd22", "#17becf"};

// "Nice" tick step for a range (1, 2, 5 x 10^k).
double TickStep(double range) {
  if (!(range > 0)) return 1.0;
  const double raw = range / 6.0;
  const double mag = std::pow(10.0, std::floor(std::log10(raw)));
  const double f = raw / mag;
  return (f < 1.5 ? 1 : f < 3.5 ? 2 : f < 7.5 ? 5 : 10) * mag;
}

std::string Num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.6g", std::abs(v) < 1e-12 ? 0.0 : v);
  return buf;
}

// Pixel coordinate with 2 decimals (keeps inline reports small).
std::string Px(double v) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.2f", std::isfinite(v) ? v : 0.0);
  return buf;
}

// Blue (0) -> light -> red (1), a diverging scale readable in print.
std::string ColorScale(double t) {
  t = std::clamp(std::isfinite(t) ? t : 0.0, 0.0, 1.0);
  const double stops[3][3] = {{49, 54, 149}, {255, 255, 191}, {165, 0, 38}};
  const int k = t < 0.5 ? 0 : 1;
  const double u = t < 0.5 ? t / 0.5 : (t - 0.5) / 0.5;
  char buf[16];
  std::snprintf(
      buf, sizeof(buf), "#%02x%02x%02x",
      static_cast<int>(stops[k][0] + u * (stops[k + 1][0] - stops[k][0])),
      static_cast<int>(stops[k][1] + u * (stops[k + 1][1] - stops[k][1])),
      static_cast<int>(stops[k][2] + u * (stops[k + 1][2] - stops[k][2])));
  return buf;
}

// One type scale for every figure (px at 1:1; report/html.cc shows plots at
// their own width when the page has room, so these are screen pixels).
constexpr int kTitleFont = 15, kLabelFont = 13, kTickFont = 12;
constexpr double kLegendRow = 18;  // legend line height (px)

// Legend entries below the x-axis label: series with a label and the
// reference lines (dashed), laid out left to right in rows.
struct LegendEntry {
  std::string label, color;
  bool dashed = false;
};

std::vector<LegendEntry> LegendEntries(const Plot& plot) {
  std::vector<LegendEntry> out;
  for (size_t k = 0; k < plot.series.size(); ++k) {
    const PlotSeries& s = plot.series[k];
    if (s.label.empty()) continue;
    out.push_back(
        {s.label, kColors[(s.color_index >= 0 ? s.color_index : k) % 10]});
  }
  for (const auto& l : plot.lines) {
    if (!l.label.empty()) out.push_back({l.label, "black", true});
  }
  return out;
}

// Text width estimate for the legend layout (sans-serif, ~0.6 em a char).
double TextWidth(const std::string& text, int font) {
  return 0.6 * font * static_cast<double>(text.size());
}

// Legend rows needed in `width` px.
int LegendRows(const std::vector<LegendEntry>& entries, double width) {
  if (entries.empty()) return 0;
  int rows = 1;
  double x = 0;
  for (const auto& e : entries) {
    const double w = 22 + TextWidth(e.label, kTickFont) + 14;
    if (x > 0 && x + w > width) ++rows, x = 0;
    x += w;
  }
  return rows;
}

// Where the data go on the canvas and which data range they span.
struct Frame {
  double left = 70, top = 40, w = 0, h = 0;
  double xmin = 0, xmax = 1, ymin = 0, ymax = 1, cmin = 0, cmax = 1;
  bool colorbar = false;
  int legend_rows = 0;
};

// Data, reference lines, cells and arrow tips all inside the ranges, padded
// so that markers at the extremes are drawn whole.
void DataRanges(const Plot& plot, Frame* f) {
  double xmin = INFINITY, xmax = -INFINITY, ymin = INFINITY, ymax = -INFINITY;
  double cmin = INFINITY, cmax = -INFINITY;
  bool bars = false;
  auto take = [&](double x, double y) {
    xmin = std::min(xmin, x), xmax = std::max(xmax, x);
    ymin = std::min(ymin, y), ymax = std::max(ymax, y);
  };
  for (const auto& s : plot.series) {
    const size_t n = std::min(s.x.size(), s.y.size());
    for (size_t i = 0; i < n; ++i) {
      if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) continue;
      take(s.x[i], s.y[i]);
      if (s.cell_w > 0 && s.cell_h > 0) {
        take(s.x[i] - s.cell_w / 2, s.y[i] - s.cell_h / 2);
        take(s.x[i] + s.cell_w / 2, s.y[i] + s.cell_h / 2);
      }
      if (i < s.dx.size() && i < s.dy.size() && std::isfinite(s.dx[i]) &&
          std::isfinite(s.dy[i])) {
        take(s.x[i] + s.dx[i], s.y[i] + s.dy[i]);
      }
      if (i < s.color.size() && std::isfinite(s.color[i])) {
        cmin = std::min(cmin, s.color[i]);
        cmax = std::max(cmax, s.color[i]);
      }
    }
    if (s.bars) ymin = std::min(ymin, 0.0), bars = true;
    if (std::isfinite(s.color_lo)) cmin = s.color_lo;
    if (std::isfinite(s.color_hi)) cmax = s.color_hi;
  }
  for (const auto& l : plot.lines) {
    ymin = std::min(ymin, l.y);
    ymax = std::max(ymax, l.y);
  }
  if (!std::isfinite(xmin)) xmin = 0, xmax = 1, ymin = 0, ymax = 1;
  if (xmax - xmin < 1e-12) xmin -= 0.5, xmax += 0.5;
  if (ymax - ymin < 1e-12) ymin -= 0.5, ymax += 0.5;
  // 4 % each side (bars stand on 0: no pad below them).
  const double xpad = 0.04 * (xmax - xmin), ypad = 0.05 * (ymax - ymin);
  xmin -= xpad, xmax += xpad, ymax += ypad;
  if (!(bars && ymin == 0.0)) ymin -= ypad;
  if (std::isfinite(plot.y_min)) ymin = plot.y_min;
  if (std::isfinite(plot.y_max)) ymax = plot.y_max;
  if (std::isfinite(plot.x_min)) xmin = plot.x_min;
  if (std::isfinite(plot.x_max)) xmax = plot.x_max;
  if (!(xmax > xmin)) xmax = xmin + 1.0;
  if (!(ymax > ymin)) ymax = ymin + 1.0;
  if (!(cmax >= cmin)) cmin = 0, cmax = 1;
  if (cmax - cmin < 1e-12) cmax = cmin + 1e-12;
  f->xmin = xmin, f->xmax = xmax, f->ymin = ymin, f->ymax = ymax;
  f->cmin = cmin, f->cmax = cmax;
}

Frame Layout(const Plot& plot) {
  Frame f;
  f.colorbar =
      std::any_of(plot.series.begin(), plot.series.end(),
                  [](const PlotSeries& s) { return !s.color.empty(); });
  const double right = f.colorbar ? 95 : 20;
  f.legend_rows = LegendRows(LegendEntries(plot), plot.width - f.left - right);
  // The legend adds rows below the plot's own height (TotalHeight).
  const double bottom = 52;
  f.w = plot.width - f.left - right;
  f.h = std::max(40.0, plot.height - f.top - bottom);
  DataRanges(plot, &f);
  if (plot.equal_axes) {  // shrink one side so mm per pixel agree
    const double sx = (f.xmax - f.xmin) / f.w, sy = (f.ymax - f.ymin) / f.h;
    if (sx > sy) {
      f.h = (f.ymax - f.ymin) / sx;
    } else {
      f.w = (f.xmax - f.xmin) / sy;
    }
  }
  return f;
}

// The plot's height with its legend rows below.
int TotalHeight(const Plot& plot) {
  const int rows = Layout(plot).legend_rows;
  return plot.height + static_cast<int>(kLegendRow * rows) + (rows ? 6 : 0);
}

// Ticks on [lo, hi] at a nice step.
std::vector<double> Ticks(double lo, double hi, double range_for_step) {
  std::vector<double> out;
  const double step = TickStep(range_for_step);
  const double first = std::ceil(lo / step) * step;
  for (int k = 0; k < 40; ++k) {  // at most 40 (guards a step below 1 ulp)
    const double t = first + k * step;
    if (t > hi + 1e-9 * step) break;
    out.push_back(std::abs(t) < 1e-9 * step ? 0.0 : t);
  }
  return out;
}

void DrawAxes(const Plot& plot, const Frame& f, int y0,
              const std::function<double(double)>& X,
              const std::function<double(double)>& Y, std::ostringstream& os) {
  const double left = f.left, top = y0 + f.top, w = f.w, h = f.h;
  os << "<text x='" << plot.width / 2 << "' y='" << y0 + 22
     << "' text-anchor='middle' font-size='" << kTitleFont << "'>"
     << XmlEscape(plot.title) << "</text>\n";
  os << "<rect x='" << Px(left) << "' y='" << Px(top) << "' width='" << Px(w)
     << "' height='" << Px(h) << "' fill='none' stroke='black'/>\n";
  for (double t : Ticks(f.xmin, f.xmax, f.xmax - f.xmin)) {
    os << "<line x1='" << Px(X(t)) << "' y1='" << Px(top + h) << "' x2='"
       << Px(X(t)) << "' y2='" << Px(top + h + 5) << "' stroke='black'/>"
       << "<text x='" << Px(X(t)) << "' y='" << Px(top + h + 18)
       << "' text-anchor='middle' font-size='" << kTickFont << "'>" << Num(t)
       << "</text>\n";
  }
  for (double t : Ticks(f.ymin, f.ymax, f.ymax - f.ymin)) {
    os << "<line x1='" << Px(left - 5) << "' y1='" << Px(Y(t)) << "' x2='"
       << Px(left + w) << "' y2='" << Px(Y(t)) << "' stroke='#ddd'/>"
       << "<text x='" << Px(left - 8) << "' y='" << Px(Y(t) + 4)
       << "' text-anchor='end' font-size='" << kTickFont << "'>" << Num(t)
       << "</text>\n";
  }
  os << "<text x='" << Px(left + w / 2) << "' y='" << Px(top + h + 38)
     << "' text-anchor='middle' font-size='" << kLabelFont << "'>"
     << XmlEscape(plot.x_label) << "</text>\n";
  os << "<text transform='translate(16," << Px(top + h / 2)
     << ") rotate(-90)' text-anchor='middle' font-size='" << kLabelFont << "'>"
     << XmlEscape(plot.y_label) << "</text>\n";
}

// One series' marks (inside the clip group).
void DrawSeries(const PlotSeries& s, const std::string& color, const Frame& f,
                const std::function<double(double)>& X,
                const std::function<double(double)>& Y,
                std::ostringstream& os) {
  const size_t n = std::min(s.x.size(), s.y.size());
  const bool arrows = !s.dx.empty() && !s.dy.empty();
  if (s.bars) {
    const double bw = std::max(1.0, 0.8 * f.w / std::max<size_t>(n, 1));
    for (size_t i = 0; i < n; ++i) {
      if (!std::isfinite(s.y[i])) continue;
      const double top_y = std::min(Y(s.y[i]), Y(0)),
                   bot = std::max(Y(s.y[i]), Y(0));
      os << "<rect x='" << Px(X(s.x[i]) - bw / 2) << "' y='" << Px(top_y)
         << "' width='" << Px(bw) << "' height='" << Px(bot - top_y)
         << "' fill='" << color << "'/>\n";
    }
    return;
  }
  if (!s.points && !arrows) {
    os << "<polyline fill='none' stroke='" << color
       << "' stroke-width='1.5' points='";
    for (size_t i = 0; i < n; ++i) {
      if (std::isfinite(s.x[i]) && std::isfinite(s.y[i])) {
        os << Px(X(s.x[i])) << "," << Px(Y(s.y[i])) << " ";
      }
    }
    os << "'/>\n";
    return;
  }
  for (size_t i = 0; i < n; ++i) {
    if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) continue;
    const std::string c =
        i < s.color.size()
            ? ColorScale((s.color[i] - f.cmin) / (f.cmax - f.cmin))
            : color;
    if (s.cell_w > 0 && s.cell_h > 0) {
      const double x0 = X(s.x[i] - s.cell_w / 2), x1 = X(s.x[i] + s.cell_w / 2);
      const double ya = Y(s.y[i] - s.cell_h / 2), yb = Y(s.y[i] + s.cell_h / 2);
      os << "<rect x='" << Px(x0) << "' y='" << Px(std::min(ya, yb))
         << "' width='" << Px(x1 - x0) << "' height='" << Px(std::abs(ya - yb))
         << "' fill='" << c << "'/>\n";
      continue;
    }
    if (arrows && i < s.dx.size() && i < s.dy.size()) {
      os << "<line x1='" << Px(X(s.x[i])) << "' y1='" << Px(Y(s.y[i]))
         << "' x2='" << Px(X(s.x[i] + s.dx[i])) << "' y2='"
         << Px(Y(s.y[i] + s.dy[i])) << "' stroke='" << color
         << "' stroke-width='1.2'/>";
    }
    os << "<circle cx='" << Px(X(s.x[i])) << "' cy='" << Px(Y(s.y[i]))
       << "' r='" << (s.color.empty() ? "2.5" : "4") << "' fill='" << c << "'"
       << (s.color.empty() ? "" : " stroke='#555' stroke-width='0.3'")
       << "/>\n";
  }
}

// The legend below the x-axis label, outside the data.
void DrawLegend(const Plot& plot, const Frame& f, int y0,
                std::ostringstream& os) {
  const std::vector<LegendEntry> entries = LegendEntries(plot);
  double x = f.left, y = y0 + f.top + f.h + 50;
  const double right = plot.width - (f.colorbar ? 95 : 20);
  for (const auto& e : entries) {
    const double w = 22 + TextWidth(e.label, kTickFont) + 14;
    if (x > f.left && x + w > right) x = f.left, y += kLegendRow;
    if (e.dashed) {
      os << "<line x1='" << Px(x) << "' y1='" << Px(y + 5) << "' x2='"
         << Px(x + 16) << "' y2='" << Px(y + 5)
         << "' stroke='black' stroke-dasharray='4,3'/>";
    } else {
      os << "<rect x='" << Px(x + 2) << "' y='" << Px(y) << "' width='12' "
         << "height='10' fill='" << e.color << "'/>";
    }
    os << "<text x='" << Px(x + 22) << "' y='" << Px(y + 9.5) << "' font-size='"
       << kTickFont << "'>" << XmlEscape(e.label) << "</text>\n";
    x += w;
  }
}

// Vertical colour bar right of the frame with ticks at round values.
void DrawColorBar(const Plot& plot, const Frame& f, int y0,
                  std::ostringstream& os) {
  std::string label;
  for (const auto& s : plot.series) {
    if (!s.color.empty()) label = s.color_label;
  }
  // At least 200 px tall (an equal-axes frame may be flat), within the plot.
  const double bh = std::max(f.h, std::min(200.0, plot.height - f.top - 52));
  const double bx = f.left + f.w + 20, by = y0 + f.top, steps = 20;
  for (int i = 0; i < steps; ++i) {
    os << "<rect x='" << Px(bx) << "' y='" << Px(by + bh * i / steps)
       << "' width='14' height='" << Px(bh / steps + 0.5) << "' fill='"
       << ColorScale(1.0 - (i + 0.5) / steps) << "'/>";
  }
  os << "\n";
  const double range = f.cmax - f.cmin;
  for (double t : Ticks(f.cmin, f.cmax, range * 6.0 / 4.0)) {
    const double ty = by + bh * (1.0 - (t - f.cmin) / range);
    os << "<line x1='" << Px(bx + 14) << "' y1='" << Px(ty) << "' x2='"
       << Px(bx + 18) << "' y2='" << Px(ty) << "' stroke='black'/><text x='"
       << Px(bx + 20) << "' y='" << Px(ty + 4) << "' font-size='" << kTickFont
       << "'>" << Num(t) << "</text>\n";
  }
  os << "<text transform='translate(" << Px(bx + 68) << "," << Px(by + bh / 2)
     << ") rotate(-90)' text-anchor='middle' font-size='" << kLabelFont << "'>"
     << XmlEscape(label) << "</text>\n";
}

void Draw(const Plot& plot, int y0, const std::string& id,
          std::ostringstream& os) {
  const Frame f = Layout(plot);
  const std::function<double(double)> X = [&](double x) {
    return f.left + (x - f.xmin) / (f.xmax - f.xmin) * f.w;
  };
  const std::function<double(double)> Y = [&](double y) {
    return y0 + f.top +
           (plot.y_down ? y - f.ymin : f.ymax - y) / (f.ymax - f.ymin) * f.h;
  };
  const std::string clip = id + "clip" + std::to_string(y0);
  os << "<defs><clipPath id='" << clip << "'><rect x='" << Px(f.left) << "' y='"
     << Px(y0 + f.top) << "' width='" << Px(f.w) << "' height='" << Px(f.h)
     << "'/></clipPath></defs>\n";
  DrawAxes(plot, f, y0, X, Y, os);
  os << "<g clip-path='url(#" << clip << ")'>\n";
  for (const auto& l : plot.lines) {
    os << "<line x1='" << Px(f.left) << "' y1='" << Px(Y(l.y)) << "' x2='"
       << Px(f.left + f.w) << "' y2='" << Px(Y(l.y))
       << "' stroke='black' stroke-dasharray='6,4'/>\n";
  }
  for (size_t k = 0; k < plot.series.size(); ++k) {
    const PlotSeries& s = plot.series[k];
    DrawSeries(s, kColors[(s.color_index >= 0 ? s.color_index : k) % 10], f, X,
               Y, os);
  }
  os << "</g>\n";
  DrawLegend(plot, f, y0, os);
  if (f.colorbar) DrawColorBar(plot, f, y0, os);
}

}  // namespace

std::string XmlEscape(const std::string& s) {
  std::string out;
  for (char c : s) {
    if (c == '<')
      out += "&lt;";
    else if (c == '>')
      out += "&gt;";
    else if (c == '&')
      out += "&amp;";
    else if (c == '\'')
      out += "&#39;";
    else if (c == '"')
      out += "&quot;";
    else
      out += c;
  }
  return out;
}

std::string FormatSvgPlots(const std::vector<Plot>& plots) {
  int width = 0, height = 0;
  for (const auto& p : plots) {
    width = std::max(width, p.width);
    height += TotalHeight(p);
  }
  std::ostringstream os;
  os << "<?xml version='1.0' encoding='UTF-8'?>\n";
  os << "<svg xmlns='http://www.w3.org/2000/svg' width='" << width
     << "' height='" << height << "' viewBox='0 0 " << width << " " << height
     << "' font-family='sans-serif'>\n"
     << "<desc>" << XmlEscape(ToolVersion() + ": " + CommandLine())
     << "</desc>\n"
     << "<rect width='100%' height='100%' fill='white'/>\n";
  int y0 = 0;
  for (const auto& p : plots) {
    Draw(p, y0, "p", os);
    y0 += TotalHeight(p);
  }
  os << "</svg>\n";
  return os.str();
}

std::string FormatSvgPlot(const Plot& plot) { return FormatSvgPlots({plot}); }

std::string FormatInlineSvg(const Plot& plot, const std::string& id) {
  const int height = TotalHeight(plot);
  std::ostringstream os;
  os << "<svg xmlns='http://www.w3.org/2000/svg' id='" << XmlEscape(id)
     << "' class='plot' width='" << plot.width << "' height='" << height
     << "' viewBox='0 0 " << plot.width << " " << height
     << "' font-family='sans-serif' role='img'><title>" << XmlEscape(plot.title)
     << "</title>\n";
  Draw(plot, 0, id, os);
  os << "</svg>\n";
  return os.str();
}

}  // namespace kincal
