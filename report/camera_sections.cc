#include "report/camera_sections.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

#include "data/atomic_file.h"
#include "data/csv.h"
#include "data/error.h"
#include "data/svg_plot.h"

namespace kincal {
namespace {

// An empty plot over one camera's imager: pixel axes, rows downwards,
// equal scales (the heat maps below).
Plot ImagePlot(const std::string& title) {
  Plot p;
  p.title = title;
  p.x_label = "image column (px)";
  p.y_label = "image row (px, downwards)";
  p.width = 500;
  p.height = 420;
  p.y_down = true;
  p.equal_axes = true;
  return p;
}

// Per camera of camcal's JSON with an image_grid: RMS per cell as coloured
// cells and the mean residual vector as an arrow from the cell centre,
// enlarged by *arrow_gain (one gain for all cameras: the 90th-percentile
// arrow spans half a cell, so one outlier cell does not shrink the rest); image
// rows grow downwards as in the image. Empty when no camera has a grid.
std::vector<Plot> ImageGridPlots(const nlohmann::json& cameras,
                                 double* arrow_gain) {
  std::vector<Plot> plots;
  double hi = 0.0, cell = INFINITY;
  std::vector<double> lengths;
  for (const auto& c : cameras) {
    if (!c.contains("image_grid") || !c["image_grid"].is_object()) continue;
    const nlohmann::json& g = c["image_grid"];
    const int cols = g.value("cols", 0), rows = g.value("rows", 0);
    const double cw = g.value("cell_w_px", 0.0), ch = g.value("cell_h_px", 0.0);
    auto at = [&](const char* key, size_t k) {
      return g.contains(key) && g[key].is_array() && k < g[key].size() &&
                     g[key][k].is_number()
                 ? g[key][k].get<double>()
                 : std::numeric_limits<double>::quiet_NaN();
    };
    if (cols <= 0 || rows <= 0 || !(cw > 0) || !(ch > 0)) continue;
    Plot p = ImagePlot(c.value("name", "?") + ": residual over the image");
    PlotSeries cells;
    cells.points = true;
    cells.color_label = "RMS (px)";
    cells.cell_w = cw;
    cells.cell_h = ch;
    PlotSeries arrows;
    arrows.points = true;
    arrows.color_index = 7;
    for (int j = 0; j < rows; ++j) {
      for (int i = 0; i < cols; ++i) {
        const size_t k = static_cast<size_t>(j) * cols + i;
        const double rms = at("rms_px", k);
        if (!std::isfinite(rms)) continue;
        const double x = (i + 0.5) * cw, y = (j + 0.5) * ch;
        cells.x.push_back(x);
        cells.y.push_back(y);
        cells.color.push_back(rms);
        hi = std::max(hi, rms);
        const double dx = at("mean_dx_px", k), dy = at("mean_dy_px", k);
        if (std::isfinite(dx) && std::isfinite(dy)) {
          arrows.x.push_back(x);
          arrows.y.push_back(y);
          arrows.dx.push_back(dx);
          arrows.dy.push_back(dy);
          lengths.push_back(std::hypot(dx, dy));
        }
      }
    }
    if (cells.x.empty()) continue;
    cell = std::min(cell, std::min(cw, ch));
    // The frame shows the whole imager, also cells no corner reached.
    p.x_min = 0.0;
    p.x_max = cols * cw;
    p.y_min = 0.0;
    p.y_max = rows * ch;
    p.series = {cells, arrows};
    plots.push_back(p);
  }
  // A round gain (1, 2, 5 x 10^k) so the caption can name it.
  double gain = 1.0;
  double p90 = 0.0;
  if (!lengths.empty()) {
    const size_t k = lengths.size() * 9 / 10;
    std::nth_element(lengths.begin(), lengths.begin() + k, lengths.end());
    p90 = lengths[k];
  }
  if (p90 > 0 && std::isfinite(cell)) {
    const double want = 0.5 * cell / p90;
    const double decade = std::pow(10.0, std::floor(std::log10(want)));
    gain = want >= 5 * decade   ? 5 * decade
           : want >= 2 * decade ? 2 * decade
                                : decade;
  }
  for (Plot& p : plots) {
    p.series[0].color_lo = 0.0;
    p.series[0].color_hi = hi > 0 ? hi : 1.0;
    for (double& d : p.series[1].dx) d *= gain;
    for (double& d : p.series[1].dy) d *= gain;
  }
  *arrow_gain = gain;
  return plots;
}

// Per camera of camcal's JSON with a projection_uncertainty grid: the
// worst-direction 1-sigma of projecting a point (camcal's distance) as a
// heat map over the imager (cols x rows cells, sigma at each centre), one
// colour scale from 0 for all cameras, capped at *cap_px (4x the largest
// centre sigma, at least the valid-region threshold) so the extrapolated
// corners do not wash out the rest; sigma above the cap shows at the cap.
std::vector<Plot> UncertaintyPlots(const nlohmann::json& cameras,
                                   double* cap_px) {
  std::vector<Plot> plots;
  double centre_max = 0.0, threshold = 0.0;
  for (const auto& c : cameras) {
    if (!c.contains("projection_uncertainty") ||
        !c["projection_uncertainty"].is_object()) {
      continue;
    }
    const nlohmann::json& u = c["projection_uncertainty"];
    if (!u.contains("grid") || !u["grid"].is_object()) continue;
    const nlohmann::json& g = u["grid"];
    const int cols = g.value("cols", 0), rows = g.value("rows", 0);
    const int width = c.value("width", 0), height = c.value("height", 0);
    if (cols <= 0 || rows <= 0 || width <= 0 || height <= 0 ||
        !g.contains("sigma_px") || !g["sigma_px"].is_array() ||
        g["sigma_px"].size() != static_cast<size_t>(cols) * rows) {
      continue;
    }
    if (u.contains("centre") && u["centre"].is_object()) {
      centre_max = std::max(centre_max, u["centre"].value("sigma_px", 0.0));
    }
    threshold = std::max(threshold, u.value("valid_threshold_px", 0.0));
    Plot p = ImagePlot(c.value("name", "?") + ": projection uncertainty");
    PlotSeries cells;
    cells.points = true;
    cells.color_label = "sigma (px)";
    cells.cell_w = static_cast<double>(width) / cols;
    cells.cell_h = static_cast<double>(height) / rows;
    for (int j = 0; j < rows; ++j) {
      for (int i = 0; i < cols; ++i) {
        const nlohmann::json& v =
            g["sigma_px"][static_cast<size_t>(j) * cols + i];
        if (!v.is_number()) continue;
        cells.x.push_back((i + 0.5) * cells.cell_w);
        cells.y.push_back((j + 0.5) * cells.cell_h);
        cells.color.push_back(v.get<double>());
      }
    }
    if (cells.x.empty()) continue;
    p.x_min = 0.0;
    p.x_max = width;
    p.y_min = 0.0;
    p.y_max = height;
    p.series = {cells};
    plots.push_back(p);
  }
  const double cap = std::max(4.0 * centre_max, threshold);
  *cap_px = cap > 0 ? cap : 1.0;
  for (Plot& p : plots) {
    for (double& v : p.series[0].color) v = std::min(v, *cap_px);
    p.series[0].color_lo = 0.0;
    p.series[0].color_hi = *cap_px;
  }
  return plots;
}

// The uncertainty maps with their caption (nothing without a grid).
void AddUncertaintyFigure(const nlohmann::json& cameras, HtmlReport* page) {
  double cap_px = 1.0;
  const std::vector<Plot> plots = UncertaintyPlots(cameras, &cap_px);
  if (plots.empty()) return;
  std::string distance = "infinity";
  for (const auto& c : cameras) {
    if (c.contains("projection_uncertainty") &&
        c["projection_uncertainty"].contains("distance") &&
        c["projection_uncertainty"]["distance"].is_number()) {
      distance = Fmt(c["projection_uncertainty"]["distance"].get<double>(), 4) +
                 " target units";
    }
  }
  page->FigureRow(
      plots,
      "Projection uncertainty over the image (mrcal's definition): the "
      "worst-direction 1-sigma of projecting a point at " +
          distance +
          " through the calibrated camera, propagated from the covariance of "
          "the intrinsics, the extrinsics and every board pose. One scale "
          "from 0 for all cameras, capped at " +
          Fmt(cap_px, 3) +
          " px (cells above show the cap). Low where the boards were; high "
          "where the model is extrapolated: use the image there with care.");
}

}  // namespace

void AddCameraSection(const Rig& rig, const nlohmann::json& camcal,
                      const std::string& camcal_path, HtmlReport* page) {
  page->Section("camera", "Camera calibration");
  std::vector<std::vector<std::string>> rows;
  for (const Camera& c : rig.cameras) {
    const CameraIntrinsics& k = c.intrinsics;
    std::string dist;
    for (double d : k.distortion)
      dist += (dist.empty() ? "" : ", ") + Fmt(d, 4);
    rows.push_back(
        {k.name, std::to_string(k.width) + " x " + std::to_string(k.height),
         Fmt(k.fx, 7), Fmt(k.fy, 7), Fmt(k.cx, 6), Fmt(k.cy, 6), dist});
  }
  page->Table({"camera", "size (px)", "fx", "fy", "cx", "cy", "distortion"},
              rows);
  if (rig.cameras.size() > 1) {
    page->Paragraph("Baseline " + Fmt(rig.BaselineMm(), 6) + " mm.");
  }
  if (camcal.is_object() && camcal.contains("cameras")) {
    std::vector<std::vector<std::string>> srows;
    Plot views;
    views.title = "Reprojection error per view";
    views.x_label = "view";
    views.y_label = "RMS (px)";
    views.width = 1000;
    views.height = 340;
    for (const auto& c : camcal["cameras"]) {
      auto g = [&](const nlohmann::json& o, const char* k) {
        return o.contains(k) && o[k].is_number() ? Fmt(o[k].get<double>(), 3)
                                                 : std::string("-");
      };
      const nlohmann::json sg =
          c.contains("sigma") ? c["sigma"] : nlohmann::json::object();
      srows.push_back({c.value("name", "?"), g(c, "rms_px"), g(c, "max_px"),
                       g(c, "holdout_rms_px"), g(sg, "fx"), g(sg, "fy"),
                       g(sg, "cx"), g(sg, "cy")});
      if (c.contains("view_rms_px")) {
        PlotSeries s;
        s.label = c.value("name", "?");
        s.points = true;
        int v = 0;
        for (const auto& x : c["view_rms_px"]) {
          ++v;
          if (!x.is_number()) continue;
          s.x.push_back(v);
          s.y.push_back(x.get<double>());
        }
        views.series.push_back(s);
      }
    }
    page->Table({"camera", "RMS (px)", "max (px)", "held-out RMS (px)",
                 "sigma fx", "sigma fy", "sigma cx", "sigma cy"},
                srows);
    if (!views.series.empty()) {
      page->Figure(views, "From " + camcal_path +
                              " (kincal camcal --json): RMS reprojection "
                              "error of every view, per camera.");
    }
    double arrow_gain = 1.0;
    std::vector<Plot> over_image =
        ImageGridPlots(camcal["cameras"], &arrow_gain);
    if (!over_image.empty()) {
      page->FigureRow(
          over_image,
          "Reprojection error over the image: each cell of the imager "
          "coloured by the RMS residual of the corners detected in it (one "
          "scale from 0 for all cameras; white: no corner ever there, so "
          "the model is extrapolated), the arrow is the mean residual "
          "vector (projected - detected), drawn " +
              Fmt(arrow_gain, 3) +
              " x enlarged. Arrows that turn with the position (outwards or "
              "inwards at the edges) mean the distortion model is too weak; "
              "random arrows mean noise.");
    }
    AddUncertaintyFigure(camcal["cameras"], page);
  } else {
    page->Paragraph(
        "Per-view reprojection errors and the sigma of the intrinsics are "
        "in the JSON that kincal camcal --json prints: save it beside the "
        "rig file (same name, .json) or pass --camcal.");
  }
}

void AddTrackingSection(const std::string& points_path, bool exists,
                        HtmlReport* page) {
  page->Section("tracking", "Tracking quality per frame");
  if (exists) {
    const std::vector<CsvLine> lines =
        TokenizeCsv(ReadFile(points_path), points_path);
    Require(!lines.empty(), points_path + ": empty");
    std::map<std::string, int> col;
    for (size_t c = 0; c < lines[0].fields.size(); ++c) {
      col[lines[0].fields[c].text] = static_cast<int>(c);
    }
    for (const char* need : {"frame", "x", "reproj_px", "tags"}) {
      if (!col.count(need)) {
        throw InputError(points_path, lines[0].line, 1,
                         std::string("expected the header of kincal track's "
                                     "points.csv (missing '") +
                             need + "')");
      }
    }
    PlotSeries reproj{"found", {}, {}, true}, lost{"not found", {}, {}, true};
    PlotSeries tags{"tags used", {}, {}, false, true};
    int found = 0, total = 0;
    for (size_t i = 1; i < lines.size(); ++i) {
      const auto& f = lines[i].fields;
      auto cell = [&](const char* k) {
        const int c = col[k];
        double v = NAN;
        if (c < static_cast<int>(f.size())) ParseFiniteDouble(f[c].text, &v);
        return v;
      };
      const double frame = cell("frame");
      ++total;
      if (std::isfinite(cell("x"))) {
        ++found;
        reproj.x.push_back(frame);
        reproj.y.push_back(cell("reproj_px"));
      } else {
        lost.x.push_back(frame);
        lost.y.push_back(0.0);
      }
      tags.x.push_back(frame);
      tags.y.push_back(cell("tags"));
    }
    Plot p;
    p.title = "Tool-pose fit per frame";
    p.x_label = "frame";
    p.y_label = "reprojection RMS (px)";
    p.series = {reproj, lost};
    p.width = 500;
    p.height = 320;
    Plot t;
    t.title = "Tag observations used per frame";
    t.x_label = "frame";
    t.y_label = "tags";
    t.series = {tags};
    t.width = 500;
    t.height = 320;
    page->FigureRow({p, t}, "From " + points_path + ": tip found in " +
                                std::to_string(found) + " of " +
                                std::to_string(total) +
                                " frames; frames without a tip at 0 (red).");
  } else {
    page->Paragraph(points_path +
                    " not found: run kincal track on the session to see the "
                    "tracking quality here.");
  }
}

}  // namespace kincal
