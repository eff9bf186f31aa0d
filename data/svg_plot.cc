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

void Draw(const Plot& plot, int y0, const std::string& id,
          std::ostringstream& os) {
  const bool has_colorbar =
      std::any_of(plot.series.begin(), plot.series.end(),
                  [](const PlotSeries& s) { return !s.color.empty(); });
  const double left = 70, right = has_colorbar ? 90 : 20, top = 40, bottom = 50;
  double w = plot.width - left - right, h = plot.height - top - bottom;
  double xmin = INFINITY, xmax = -INFINITY, ymin = INFINITY, ymax = -INFINITY;
  double cmin = INFINITY, cmax = -INFINITY;
  for (const auto& s : plot.series) {
    const size_t n = std::min(s.x.size(), s.y.size());
    for (size_t i = 0; i < n; ++i) {
      if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) continue;
      xmin = std::min(xmin, s.x[i]);
      xmax = std::max(xmax, s.x[i]);
      ymin = std::min(ymin, s.y[i]);
      ymax = std::max(ymax, s.y[i]);
      if (s.cell_w > 0 && s.cell_h > 0) {
        xmin = std::min(xmin, s.x[i] - s.cell_w / 2);
        xmax = std::max(xmax, s.x[i] + s.cell_w / 2);
        ymin = std::min(ymin, s.y[i] - s.cell_h / 2);
        ymax = std::max(ymax, s.y[i] + s.cell_h / 2);
      }
      if (i < s.dx.size() && i < s.dy.size() && std::isfinite(s.dx[i]) &&
          std::isfinite(s.dy[i])) {
        xmin = std::min(xmin, s.x[i] + s.dx[i]);
        xmax = std::max(xmax, s.x[i] + s.dx[i]);
        ymin = std::min(ymin, s.y[i] + s.dy[i]);
        ymax = std::max(ymax, s.y[i] + s.dy[i]);
      }
      if (i < s.color.size() && std::isfinite(s.color[i])) {
        cmin = std::min(cmin, s.color[i]);
        cmax = std::max(cmax, s.color[i]);
      }
    }
    if (s.bars) ymin = std::min(ymin, 0.0);
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
  const double pad = 0.05 * (ymax - ymin);
  ymax += pad;
  if (ymin != 0.0) ymin -= pad;
  if (std::isfinite(plot.y_min)) ymin = plot.y_min;
  if (std::isfinite(plot.y_max)) ymax = plot.y_max;
  if (std::isfinite(plot.x_min)) xmin = plot.x_min;
  if (std::isfinite(plot.x_max)) xmax = plot.x_max;
  if (!(xmax > xmin)) xmax = xmin + 1.0;
  if (!(ymax > ymin)) ymax = ymin + 1.0;
  if (!(cmax >= cmin)) cmin = 0, cmax = 1;
  if (cmax - cmin < 1e-12) cmax = cmin + 1e-12;
  if (plot.equal_axes) {  // shrink one side so mm per pixel agree
    const double sx = (xmax - xmin) / w, sy = (ymax - ymin) / h;
    if (sx > sy) {
      h = (ymax - ymin) / sx;
    } else {
      w = (xmax - xmin) / sy;
    }
  }
  auto X = [&](double x) { return left + (x - xmin) / (xmax - xmin) * w; };
  auto Y = [&](double y) {
    return y0 + top + (plot.y_down ? y - ymin : ymax - y) / (ymax - ymin) * h;
  };
  const std::string clip = id + "clip" + std::to_string(y0);

  os << "<defs><clipPath id='" << clip << "'><rect x='" << Px(left) << "' y='"
     << Px(y0 + top) << "' width='" << Px(w) << "' height='" << Px(h)
     << "'/></clipPath></defs>\n";
  os << "<text x='" << plot.width / 2 << "' y='" << y0 + 22
     << "' text-anchor='middle' font-size='16'>" << XmlEscape(plot.title)
     << "</text>\n";
  os << "<rect x='" << Px(left) << "' y='" << Px(y0 + top) << "' width='"
     << Px(w) << "' height='" << Px(h) << "' fill='none' stroke='black'/>\n";
  const double xs = TickStep(xmax - xmin), ys = TickStep(ymax - ymin);
  for (double t = std::ceil(xmin / xs) * xs; t <= xmax + 1e-9 * xs; t += xs) {
    os << "<line x1='" << Px(X(t)) << "' y1='" << Px(y0 + top + h) << "' x2='"
       << Px(X(t)) << "' y2='" << Px(y0 + top + h + 5) << "' stroke='black'/>"
       << "<text x='" << Px(X(t)) << "' y='" << Px(y0 + top + h + 18)
       << "' text-anchor='middle' font-size='11'>" << Num(t) << "</text>\n";
  }
  for (double t = std::ceil(ymin / ys) * ys; t <= ymax + 1e-9 * ys; t += ys) {
    os << "<line x1='" << Px(left - 5) << "' y1='" << Px(Y(t)) << "' x2='"
       << Px(left + w) << "' y2='" << Px(Y(t)) << "' stroke='#ddd'/>"
       << "<text x='" << Px(left - 8) << "' y='" << Px(Y(t) + 4)
       << "' text-anchor='end' font-size='11'>" << Num(t) << "</text>\n";
  }
  os << "<text x='" << Px(left + w / 2) << "' y='" << Px(y0 + top + h + 40)
     << "' text-anchor='middle' font-size='13'>" << XmlEscape(plot.x_label)
     << "</text>\n";
  os << "<text transform='translate(16," << Px(y0 + top + h / 2)
     << ") rotate(-90)' text-anchor='middle' font-size='13'>"
     << XmlEscape(plot.y_label) << "</text>\n";
  os << "<g clip-path='url(#" << clip << ")'>\n";
  for (const auto& l : plot.lines) {
    os << "<line x1='" << Px(left) << "' y1='" << Px(Y(l.y)) << "' x2='"
       << Px(left + w) << "' y2='" << Px(Y(l.y))
       << "' stroke='black' stroke-dasharray='6,4'/><text x='"
       << Px(left + w - 4) << "' y='" << Px(Y(l.y) - 4)
       << "' text-anchor='end' font-size='11'>" << XmlEscape(l.label)
       << "</text>\n";
  }
  for (size_t k = 0; k < plot.series.size(); ++k) {
    const PlotSeries& s = plot.series[k];
    const std::string color =
        kColors[(s.color_index >= 0 ? s.color_index : k) % 10];
    const size_t n = std::min(s.x.size(), s.y.size());
    const bool arrows = !s.dx.empty() && !s.dy.empty();
    if (s.bars) {
      const double bw = std::max(1.0, 0.8 * w / std::max<size_t>(n, 1));
      for (size_t i = 0; i < n; ++i) {
        if (!std::isfinite(s.y[i])) continue;
        const double top_y = std::min(Y(s.y[i]), Y(0)),
                     bot = std::max(Y(s.y[i]), Y(0));
        os << "<rect x='" << Px(X(s.x[i]) - bw / 2) << "' y='" << Px(top_y)
           << "' width='" << Px(bw) << "' height='" << Px(bot - top_y)
           << "' fill='" << color << "'/>\n";
      }
    } else if (s.points || arrows) {
      for (size_t i = 0; i < n; ++i) {
        if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) continue;
        const std::string c =
            i < s.color.size() ? ColorScale((s.color[i] - cmin) / (cmax - cmin))
                               : color;
        if (s.cell_w > 0 && s.cell_h > 0) {
          const double x0 = X(s.x[i] - s.cell_w / 2),
                       x1 = X(s.x[i] + s.cell_w / 2);
          const double y1 = Y(s.y[i] - s.cell_h / 2),
                       y0c = Y(s.y[i] + s.cell_h / 2);
          os << "<rect x='" << Px(x0) << "' y='" << Px(std::min(y0c, y1))
             << "' width='" << Px(x1 - x0) << "' height='"
             << Px(std::abs(y1 - y0c)) << "' fill='" << c << "'/>\n";
          continue;
        }
        if (arrows && i < s.dx.size() && i < s.dy.size()) {
          os << "<line x1='" << Px(X(s.x[i])) << "' y1='" << Px(Y(s.y[i]))
             << "' x2='" << Px(X(s.x[i] + s.dx[i])) << "' y2='"
             << Px(Y(s.y[i] + s.dy[i])) << "' stroke='" << color
             << "' stroke-width='1.2'/>";
        }
        os << "<circle cx='" << Px(X(s.x[i])) << "' cy='" << Px(Y(s.y[i]))
           << "' r='" << (s.color.empty() ? "2.5" : "4") << "' fill='" << c
           << "'"
           << (s.color.empty() ? "" : " stroke='#555' stroke-width='0.3'")
           << "/>\n";
      }
    } else {
      os << "<polyline fill='none' stroke='" << color
         << "' stroke-width='1.5' points='";
      for (size_t i = 0; i < n; ++i) {
        if (std::isfinite(s.x[i]) && std::isfinite(s.y[i])) {
          os << Px(X(s.x[i])) << "," << Px(Y(s.y[i])) << " ";
        }
      }
      os << "'/>\n";
    }
  }
  os << "</g>\n";
  for (size_t k = 0; k < plot.series.size(); ++k) {
    const PlotSeries& s = plot.series[k];
    if (s.label.empty()) continue;
    os << "<rect x='" << Px(left + 10) << "' y='" << Px(y0 + top + 8 + 16 * k)
       << "' width='12' height='10' fill='" << kColors[k % 10] << "'/><text x='"
       << Px(left + 28) << "' y='" << Px(y0 + top + 17 + 16 * k)
       << "' font-size='11'>" << XmlEscape(s.label) << "</text>\n";
  }
  if (has_colorbar) {  // vertical colour bar right of the frame
    std::string label;
    for (const auto& s : plot.series) {
      if (!s.color.empty()) label = s.color_label;
    }
    const double bx = left + w + 20, by = y0 + top, bh = h, steps = 20;
    for (int i = 0; i < steps; ++i) {
      os << "<rect x='" << Px(bx) << "' y='" << Px(by + bh * i / steps)
         << "' width='14' height='" << Px(bh / steps + 0.5) << "' fill='"
         << ColorScale(1.0 - (i + 0.5) / steps) << "'/>";
    }
    os << "\n<text x='" << Px(bx + 18) << "' y='" << Px(by + 10)
       << "' font-size='11'>" << Num(cmax) << "</text><text x='" << Px(bx + 18)
       << "' y='" << Px(by + bh) << "' font-size='11'>" << Num(cmin)
       << "</text>\n<text transform='translate(" << Px(bx + 60) << ","
       << Px(by + bh / 2)
       << ") rotate(-90)' text-anchor='middle' font-size='12'>"
       << XmlEscape(label) << "</text>\n";
  }
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
    height += p.height;
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
    y0 += p.height;
  }
  os << "</svg>\n";
  return os.str();
}

std::string FormatSvgPlot(const Plot& plot) { return FormatSvgPlots({plot}); }

std::string FormatInlineSvg(const Plot& plot, const std::string& id) {
  std::ostringstream os;
  os << "<svg xmlns='http://www.w3.org/2000/svg' id='" << XmlEscape(id)
     << "' class='plot' viewBox='0 0 " << plot.width << " " << plot.height
     << "' font-family='sans-serif' role='img'><title>" << XmlEscape(plot.title)
     << "</title>\n";
  Draw(plot, 0, id, os);
  os << "</svg>\n";
  return os.str();
}

}  // namespace kincal
