#include "data/svg_plot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "data/provenance.h"

namespace kincal {
namespace {

const char* kColors[] = {"#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd",
                         "#8c564b", "#e377c2", "#7f7f7f", "#bcbd22", "#17becf"};

std::string Escape(const std::string& s) {
  std::string out;
  for (char c : s) {
    if (c == '<')
      out += "&lt;";
    else if (c == '>')
      out += "&gt;";
    else if (c == '&')
      out += "&amp;";
    else
      out += c;
  }
  return out;
}

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

void Draw(const Plot& plot, int y0, std::ostringstream& os) {
  const double left = 70, right = 20, top = 40, bottom = 50;
  const double w = plot.width - left - right, h = plot.height - top - bottom;
  double xmin = INFINITY, xmax = -INFINITY, ymin = INFINITY, ymax = -INFINITY;
  for (const auto& s : plot.series) {
    for (size_t i = 0; i < s.x.size() && i < s.y.size(); ++i) {
      if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) continue;
      xmin = std::min(xmin, s.x[i]);
      xmax = std::max(xmax, s.x[i]);
      ymin = std::min(ymin, s.y[i]);
      ymax = std::max(ymax, s.y[i]);
    }
    if (s.bars) ymin = std::min(ymin, 0.0);
  }
  for (const auto& l : plot.lines) {
    ymin = std::min(ymin, l.y);
    ymax = std::max(ymax, l.y);
  }
  if (!std::isfinite(xmin)) xmin = 0, xmax = 1, ymin = 0, ymax = 1;
  if (xmax - xmin < 1e-12) xmin -= 0.5, xmax += 0.5;
  if (ymax - ymin < 1e-12) ymin -= 0.5, ymax += 0.5;
  const double pad = 0.05 * (ymax - ymin);
  ymax += pad;
  if (ymin != 0.0) ymin -= pad;
  auto X = [&](double x) { return left + (x - xmin) / (xmax - xmin) * w; };
  auto Y = [&](double y) { return y0 + top + (ymax - y) / (ymax - ymin) * h; };

  os << "<text x='" << plot.width / 2 << "' y='" << y0 + 22
     << "' text-anchor='middle' font-size='16'>" << Escape(plot.title)
     << "</text>\n";
  os << "<rect x='" << left << "' y='" << y0 + top << "' width='" << w
     << "' height='" << h << "' fill='none' stroke='black'/>\n";
  const double xs = TickStep(xmax - xmin), ys = TickStep(ymax - ymin);
  for (double t = std::ceil(xmin / xs) * xs; t <= xmax + 1e-9 * xs; t += xs) {
    os << "<line x1='" << X(t) << "' y1='" << y0 + top + h << "' x2='" << X(t)
       << "' y2='" << y0 + top + h + 5 << "' stroke='black'/>"
       << "<text x='" << X(t) << "' y='" << y0 + top + h + 18
       << "' text-anchor='middle' font-size='11'>" << Num(t) << "</text>\n";
  }
  for (double t = std::ceil(ymin / ys) * ys; t <= ymax + 1e-9 * ys; t += ys) {
    os << "<line x1='" << left - 5 << "' y1='" << Y(t) << "' x2='" << left + w
       << "' y2='" << Y(t) << "' stroke='#ddd'/>"
       << "<text x='" << left - 8 << "' y='" << Y(t) + 4
       << "' text-anchor='end' font-size='11'>" << Num(t) << "</text>\n";
  }
  os << "<text x='" << left + w / 2 << "' y='" << y0 + plot.height - 10
     << "' text-anchor='middle' font-size='13'>" << Escape(plot.x_label)
     << "</text>\n";
  os << "<text transform='translate(16," << y0 + top + h / 2
     << ") rotate(-90)' text-anchor='middle' font-size='13'>"
     << Escape(plot.y_label) << "</text>\n";
  for (const auto& l : plot.lines) {
    os << "<line x1='" << left << "' y1='" << Y(l.y) << "' x2='" << left + w
       << "' y2='" << Y(l.y)
       << "' stroke='black' stroke-dasharray='6,4'/><text x='" << left + w - 4
       << "' y='" << Y(l.y) - 4 << "' text-anchor='end' font-size='11'>"
       << Escape(l.label) << "</text>\n";
  }
  for (size_t k = 0; k < plot.series.size(); ++k) {
    const PlotSeries& s = plot.series[k];
    const char* color = kColors[k % 10];
    const size_t n = std::min(s.x.size(), s.y.size());
    if (s.bars) {
      const double bw = std::max(1.0, 0.8 * w / std::max<size_t>(n, 1));
      for (size_t i = 0; i < n; ++i) {
        const double top_y = std::min(Y(s.y[i]), Y(0)),
                     bot = std::max(Y(s.y[i]), Y(0));
        os << "<rect x='" << X(s.x[i]) - bw / 2 << "' y='" << top_y
           << "' width='" << bw << "' height='" << bot - top_y << "' fill='"
           << color << "'/>\n";
      }
    } else if (s.points) {
      for (size_t i = 0; i < n; ++i) {
        if (!std::isfinite(s.y[i])) continue;
        os << "<circle cx='" << X(s.x[i]) << "' cy='" << Y(s.y[i])
           << "' r='2.5' fill='" << color << "'/>\n";
      }
    } else {
      os << "<polyline fill='none' stroke='" << color
         << "' stroke-width='1.5' points='";
      for (size_t i = 0; i < n; ++i) {
        if (std::isfinite(s.y[i])) os << X(s.x[i]) << "," << Y(s.y[i]) << " ";
      }
      os << "'/>\n";
    }
    os << "<rect x='" << left + 10 << "' y='" << y0 + top + 8 + 16 * k
       << "' width='12' height='10' fill='" << color << "'/><text x='"
       << left + 28 << "' y='" << y0 + top + 17 + 16 * k << "' font-size='11'>"
       << Escape(s.label) << "</text>\n";
  }
}

}  // namespace

std::string FormatSvgPlots(const std::vector<Plot>& plots) {
  int width = 0, height = 0;
  for (const auto& p : plots) {
    width = std::max(width, p.width);
    height += p.height;
  }
  std::ostringstream os;
  os << "<?xml version='1.0' encoding='UTF-8'?>\n<!-- " << ToolVersion() << ": "
     << Escape(CommandLine()) << " -->\n";
  os << "<svg xmlns='http://www.w3.org/2000/svg' width='" << width
     << "' height='" << height << "' font-family='sans-serif'>\n"
     << "<rect width='100%' height='100%' fill='white'/>\n";
  int y0 = 0;
  for (const auto& p : plots) {
    Draw(p, y0, os);
    y0 += p.height;
  }
  os << "</svg>\n";
  return os.str();
}

std::string FormatSvgPlot(const Plot& plot) { return FormatSvgPlots({plot}); }

}  // namespace kincal
