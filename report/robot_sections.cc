#include "report/robot_sections.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "calib/chain.h"
#include "report/verdict.h"

namespace kincal {
namespace {

// Indices 0..n-1 thinned evenly to at most `max`.
std::vector<int> Thin(size_t n, int max) {
  std::vector<int> idx;
  const double step = n > static_cast<size_t>(max) ? double(n) / max : 1.0;
  for (double k = 0; k < n; k += step) idx.push_back(static_cast<int>(k));
  return idx;
}

std::string ThinNote(size_t n, int max) {
  return n > static_cast<size_t>(max)
             ? " Markers: every " + Fmt(double(n) / max, 2) + "-th of " +
                   std::to_string(n) + " rows (statistics use all)."
             : "";
}

std::string JointUnit(const Robot& r, int j) {
  return r.joints[j].type == JointType::kPrismatic ? "mm" : "deg";
}

// Parameter unit shown in tables.

// Equal-count bins of the trend lines: 12, fewer so that each holds 8 poses
// or more, none (0) below 3 bins: a mean of one or two poses is no trend.
int TrendBins(size_t poses) {
  const int bins = std::min<int>(12, static_cast<int>(poses / 8));
  return bins >= 3 ? bins : 0;
}

std::string TrendWords(size_t poses) {
  const int bins = TrendBins(poses);
  return bins > 0
             ? "; lines: means of " + std::to_string(bins) + " equal-count bins"
             : "; no trend lines: too few poses (" + std::to_string(poses) +
                   ") for means of 8 or more";
}

// The enlargement of the workspace arrows: 0.12 x the workspace over the
// longest error, rounded down to 1, 2 or 5 x 10^k so the legend reads it.
double RoundScale(double scale) {
  if (!(scale > 0) || !std::isfinite(scale)) return 1.0;
  const double decade = std::pow(10.0, std::floor(std::log10(scale)));
  return scale >= 5 * decade   ? 5 * decade
         : scale >= 2 * decade ? 2 * decade
                               : decade;
}

std::vector<const ResidualSet*> Sets(const ReportAnalysis& an) {
  std::vector<const ResidualSet*> sets = {&an.res_geo};
  if (an.has_ext) sets.push_back(&an.res_ext);
  return sets;
}

// |error| against one reading of every pose, geometric (and extended)
// model, with binned means as trend lines.
template <typename XOf>
Plot Scatter(const ReportAnalysis& an, const ReportOptions& opt,
             const std::string& title, const std::string& x_label, XOf x_of) {
  Plot p;
  p.title = title;
  p.x_label = x_label;
  p.y_label = "|error| (mm)";
  p.width = kSmallPlotWidth;
  p.height = 320;
  const std::vector<const ResidualSet*> sets = Sets(an);
  for (const ResidualSet* s : sets) {
    PlotSeries pts;
    pts.label = s->label;
    pts.points = true;
    std::vector<double> xs;
    for (int row : s->rows) xs.push_back(x_of(row));
    for (int i : Thin(xs.size(), opt.max_points / 2)) {
      pts.x.push_back(xs[i]);
      pts.y.push_back(s->norm_mm[i]);
    }
    p.series.push_back(pts);
  }
  const int bins = TrendBins(an.res_geo.rows.size());
  for (size_t k = 0; k < sets.size() && bins > 0; ++k) {
    PlotSeries trend;
    trend.color_index = static_cast<int>(k);
    std::vector<double> xs;
    for (int row : sets[k]->rows) xs.push_back(x_of(row));
    BinnedMeans(xs, sets[k]->norm_mm, bins, &trend.x, &trend.y);
    p.series.push_back(trend);
  }
  return p;
}

}  // namespace

void AddDiagnosisSection(const ReportInputs& in, const ReportOptions& opt,
                         HtmlReport* page) {
  if (!in.has_diag) return;
  const nlohmann::json& findings = in.diag["findings"];
  page->Section("diagnosis",
                findings.empty() ? "Diagnosis" : "Diagnosis: causes found");
  if (findings.empty()) {
    page->Paragraph(
        "No significant effect: no cause diagnose model tested lowered the "
        "error on poses held out of the fit (" +
        opt.diagnosis + ", kincal diagnose model --json).");
    return;
  }
  std::vector<std::vector<std::string>> rows;
  for (const auto& f : findings) {
    auto s = [&](const char* k) {
      if (!f.contains(k) || f[k].is_null()) return std::string("-");
      if (f[k].is_number()) return Fmt(f[k].get<double>(), 4);
      if (f[k].is_string()) return f[k].get<std::string>();
      return f[k].dump();
    };
    std::string ci = "-";
    if (f.contains("ci95") && f["ci95"].size() == 2 &&
        f["ci95"][0].is_number()) {
      ci = "[" + Fmt(f["ci95"][0].get<double>(), 4) + ", " +
           Fmt(f["ci95"][1].get<double>(), 4) + "]";
    }
    rows.push_back({s("cause"), s("joint"), s("magnitude"), s("unit"), ci,
                    s("heldout_rms_before_mm"), s("heldout_rms_after_mm")});
  }
  page->Table({"cause", "joint", "magnitude", "unit", "95 % interval",
               "held-out before (mm)", "held-out after (mm)"},
              rows);
  page->Paragraph("From " + opt.diagnosis +
                  " (kincal diagnose model --json): causes tested jointly "
                  "with the geometry, kept when they lower the error on "
                  "poses held out of the fit.");
}

void AddResidualsSection(const ReportInputs& in, const ReportAnalysis& an,
                         const ReportOptions& opt, HtmlReport* page) {
  if (!an.has_geo) return;
  page->Section("residuals", "What the model gets wrong: residuals");
  const Robot& jr = in.JointRobot();
  std::vector<Plot> plots;
  for (int j = 0; j < in.JointCount(); ++j) {
    plots.push_back(Scatter(an, opt, jr.joints[j].name,
                            jr.joints[j].name + " (" + JointUnit(jr, j) + ")",
                            [&, j](int row) { return in.obs.rows[row].q[j]; }));
  }
  page->FigureRow(
      plots,
      "|error| of each pose against each joint reading: the geometric "
      "model (blue)" +
          std::string(an.has_ext ? ", with the extensions (red)" : "") +
          TrendWords(an.res_geo.rows.size()) +
          ". A trend means the geometric model misses something that "
          "depends on that joint." +
          ThinNote(an.res_geo.rows.size(), opt.max_points / 2));
  std::vector<Plot> tplots;
  if (in.obs.AnyTime()) {
    tplots.push_back(Scatter(an, opt, "against time", "t (s)", [&](int row) {
      return in.obs.rows[row].HasTime() ? in.obs.rows[row].t_s : NAN;
    }));
  }
  bool has_temp = false;
  for (const Observation& r : in.obs.rows) has_temp |= r.HasTemp();
  if (has_temp) {
    tplots.push_back(
        Scatter(an, opt, "against temperature", "temp_c (deg C)", [&](int row) {
          return in.obs.rows[row].HasTemp() ? in.obs.rows[row].temp_c : NAN;
        }));
  }
  if (!tplots.empty()) {
    page->FigureRow(tplots,
                    "|error| against time and temperature (drift, thermal "
                    "growth show as trends).");
  } else {
    page->Paragraph(
        "The observations have no t or temp_c column: no plot "
        "against time or temperature.");
  }
}

void AddStructureSection(const ReportInputs& in, const ReportAnalysis& an,
                         const ReportOptions& opt, HtmlReport* page) {
  const int pa = an.structure.a, pb = an.structure.b;
  if (!an.has_geo || pa < 0) return;
  const Robot& jr = in.JointRobot();
  page->Section("structure", "Residual structure over " + jr.joints[pa].name +
                                 " x " + jr.joints[pb].name);
  std::vector<Plot> maps;
  double cell_hi = 1.0;
  int grid_bins = 12;
  for (const ResidualSet* s : Sets(an)) {
    Plot p;
    p.title = s->label + ": |mean error vector| per cell";
    p.x_label = jr.joints[pa].name + " (" + JointUnit(jr, pa) + ")";
    p.y_label = jr.joints[pb].name + " (" + JointUnit(jr, pb) + ")";
    p.width = kSmallPlotWidth;
    p.height = 420;
    PlotSeries cells;
    cells.points = true;
    cells.color_label = "|mean error| (mm)";
    std::vector<double> xa, xb;
    for (int row : s->rows) {
      xa.push_back(in.obs.rows[row].q[pa]);
      xb.push_back(in.obs.rows[row].q[pb]);
    }
    // About 6 poses per cell on average, 4 to 12 cells a side.
    const int bins =
        std::clamp(static_cast<int>(std::sqrt(xa.size() / 6.0)), 4, 12);
    MeanVectorGrid(xa, xb, s->e_in_base, bins, 3, &cells.x, &cells.y,
                   &cells.color, &cells.cell_w, &cells.cell_h);
    if (maps.empty()) {
      cell_hi = cells.color.empty()
                    ? 1.0
                    : *std::max_element(cells.color.begin(), cells.color.end());
      grid_bins = bins;
    }
    cells.color_lo = 0.0;  // one colour scale for both maps
    cells.color_hi = cell_hi;
    p.series.push_back(cells);
    PlotSeries poses;
    poses.points = true;
    poses.color_index = 7;
    for (int i : Thin(xa.size(), opt.max_points / 2)) {
      poses.x.push_back(xa[i]);
      poses.y.push_back(xb[i]);
    }
    p.series.push_back(poses);
    maps.push_back(p);
  }
  page->FigureRow(
      maps, StructureSentence(in, an) +
                " Colour: length of the mean error vector of the poses in "
                "each cell of a " +
                std::to_string(grid_bins) + " x " + std::to_string(grid_bins) +
                " grid (finer than the 5 x 5 grid of the shares above, which "
                "keeps their chance level low; cells with 3 or more poses; "
                "blue small, red large; one scale from 0 for both maps): the "
                "systematic part the model misses. Grey dots: the poses." +
                ThinNote(an.res_geo.rows.size(), opt.max_points / 2));
}

void AddWorkspaceSection(const ReportAnalysis& an, const ReportOptions& opt,
                         HtmlReport* page) {
  if (!an.has_geo) return;
  const ResidualSet& g = an.res_geo;
  page->Section("workspace", "Residual vectors in the workspace");
  double extent = 0, emax = 0;
  for (size_t i = 0; i < g.rows.size(); ++i) {
    extent = std::max(extent, g.tip_in_base[i].cwiseAbs().maxCoeff());
    emax = std::max(emax, g.norm_mm[i]);
  }
  const double scale = RoundScale(emax > 0 ? 0.12 * extent / emax : 1.0);
  const int max_markers = std::min(opt.max_points, 800);
  std::vector<Plot> views;
  for (int view = 0; view < 2; ++view) {
    Plot p;
    const int a = 0, b = view == 0 ? 1 : 2;
    p.title =
        g.label + (view == 0 ? ": top view (x, y)" : ": side view (x, z)");
    p.x_label = "x in base (mm)";
    p.y_label = std::string(view == 0 ? "y" : "z") + " in base (mm)";
    p.width = kSmallPlotWidth;
    p.height = 460;
    p.equal_axes = true;
    PlotSeries arrows;
    arrows.label = "error x " + Fmt(scale, 6);
    arrows.points = true;
    arrows.color_label = "|error| (mm)";
    for (int i : Thin(g.rows.size(), max_markers)) {
      arrows.x.push_back(g.tip_in_base[i][a]);
      arrows.y.push_back(g.tip_in_base[i][b]);
      arrows.dx.push_back(scale * g.e_in_base[i][a]);
      arrows.dy.push_back(scale * g.e_in_base[i][b]);
      arrows.color.push_back(g.norm_mm[i]);
    }
    p.series.push_back(arrows);
    views.push_back(p);
  }
  page->FigureRow(views,
                  "Model tip positions in the robot base frame with the error "
                  "vector (model - measured) drawn " +
                      Fmt(scale, 6) +
                      " times enlarged. Regions of long, aligned arrows are "
                      "where the geometric model fails." +
                      ThinNote(g.rows.size(), max_markers));
}

void AddSensitivitySection(const ReportAnalysis& an, HtmlReport* page) {
  if (!an.has_geo) return;
  std::vector<Plot> plots;
  std::string caption;
  for (const char* unit : {"mm", "deg"}) {
    const bool lengths = unit[0] == 'm';
    Plot p;
    p.width = kSmallPlotWidth;
    p.height = 340;
    if (an.has_fixed_sensitivity) {
      p.title = std::string("eps vs ") + (lengths ? "lengths" : "angles");
      p.x_label =
          std::string("offset from the calibrated value (") + unit + ")";
      p.y_label = "eps (mm)";
      p.lines.push_back({SensitivityOptions().eta_mm, "eta = 1 mm"});
      for (const auto& c : an.sensitivity.curves) {
        if (c.unit != unit || c.flat) continue;
        p.series.push_back({c.param.name, c.offsets, c.eps_mm});
      }
    } else {
      p.title = std::string("RMS error vs ") + (lengths ? "lengths" : "angles");
      p.x_label = std::string("offset from the model's value (") + unit + ")";
      p.y_label = "RMS |error| (mm)";
      for (const auto& c : an.measured_sensitivity) {
        if (c.unit == unit) p.series.push_back({c.name, c.offsets, c.rms_mm});
      }
    }
    if (!p.series.empty()) plots.push_back(p);
  }
  if (plots.empty()) return;
  if (an.has_fixed_sensitivity) {
    caption =
        "The seed's Fig. 2/3: eps (mean distance of the model tips to their "
        "fixed point) as each parameter alone moves. Verdict: " +
        an.sensitivity.verdict + ".";
    for (const auto& n : an.sensitivity.notes) caption += " " + n;
  } else {
    caption =
        "The seed's Fig. 2/3 for measured points: the RMS tip error as each "
        "identifiable geometry parameter alone moves +-5 mm or deg from the "
        "geometric model (measuring frame held). Equal valleys at offset 0 "
        "mean no single parameter change improves the fit; a valley away "
        "from 0 names a parameter error.";
  }
  page->Section("sensitivity", "Sensitivity curves (seed Section 3)");
  page->FigureRow(plots, caption);
}

void AddClearanceSection(const ReportAnalysis& an, HtmlReport* page) {
  if (!an.has_clear) return;
  const ClearanceResult& clear = an.clear;
  page->Section("clearance", "Joint motion error test (seed Section 4)");
  Plot dev = DeviationPlot(clear);
  dev.title = "Deviation per pose, geometric model (Fig. 4)";
  dev.width = an.has_ext ? kSmallPlotWidth : kWidePlotWidth;
  dev.height = 320;
  std::vector<Plot> devs = {dev};
  if (an.has_ext) {
    Plot after = dev;
    after.title = "Deviation per pose with the extensions (Fig. 6)";
    after.series[0].x.clear();
    after.series[0].y.clear();
    for (size_t i = 0; i < an.res_ext.rows.size(); ++i) {
      after.series[0].x.push_back(static_cast<double>(i + 1));
      after.series[0].y.push_back(an.res_ext.norm_mm[i]);
    }
    after.lines = {{an.res_ext.stats.rms_mm, "RMS"}};
    after.y_min = 0;
    after.y_max =
        *std::max_element(clear.errors_mm.begin(), clear.errors_mm.end()) *
        1.05;
    devs.push_back(after);
  }
  page->FigureRow(devs,
                  "The error of every pose after registering the measuring "
                  "frame, in visit order" +
                      std::string(an.has_ext ? "; right: the same with the "
                                               "extensions, same scale"
                                             : "") +
                      ".");
  std::vector<Plot> sweeps;
  for (size_t k = 0; k < clear.sweeps.size(); ++k) {
    const PoseSweep& ps = clear.sweeps[k];
    Plot p = SweepPlot(clear, k);
    p.title = (k == 0 ? "Worst pose " : "Pose ") + ps.pose +
              (k == 0 ? " (Fig. 5)" : "");
    p.width = k == 0 ? kWidePlotWidth : kSmallPlotWidth;
    p.height = k == 0 ? 420 : 300;
    if (k == 0) {
      page->Figure(p, "Each joint's reading swept +-" + Fmt(clear.gamma, 3) +
                          " with the others fixed at the worst pose; y axis 0 "
                          "to 3x the pose's error (curves leaving the frame "
                          "are clipped) so the minimum near zero stays "
                          "visible.");
    } else {
      sweeps.push_back(p);
    }
  }
  if (!sweeps.empty()) {
    page->FigureRow(sweeps, "The next-worst poses (the seed's step 3).");
  }
  std::vector<std::vector<std::string>> rows;
  for (size_t j = 0; j < clear.joint_names.size(); ++j) {
    rows.push_back({clear.joint_names[j], std::to_string(clear.wins[j]),
                    Fmt(clear.median_ratio[j], 3)});
  }
  page->Table({"joint", "best at poses", "median error_min / error_before"},
              rows);
  page->Paragraph(
      clear.suspect >= 0
          ? "Suspect: " + clear.joint_names[clear.suspect] +
                ". Caution (docs/DIAGNOSE.md): a sweep moves the tip along "
                "one Jacobian column, so almost any joint lowers one pose's "
                "error; the diagnosis tests a clearance model on all poses "
                "instead."
          : "No suspect joint: no joint removes the worst poses' error.");
}

namespace {

std::string NameList(const nlohmann::json& names) {
  std::string out;
  if (!names.is_array()) return out;
  for (const auto& n : names) {
    if (n.is_string()) out += (out.empty() ? "" : ", ") + n.get<std::string>();
  }
  return out;
}

}  // namespace

void AddIdentifiabilitySection(const ReportInputs& in, const ReportAnalysis& an,
                               HtmlReport* page) {
  if (in.has_bundle) {
    page->Section("identifiability", "Identifiability");
    page->Paragraph(
        "Estimated by kincal bundle: " +
        NameList(in.bundle.value("identifiable", nlohmann::json())) + ".");
    page->Paragraph(
        "Held at nominal (redundant with the others or the frames): " +
        NameList(in.bundle.value("unidentifiable", nlohmann::json())) + ".");
    return;
  }
  if (!an.has_calres) return;
  const Identifiability& id = an.calres.identifiability;
  page->Section("identifiability", "Identifiability");
  std::ostringstream s;
  s << id.identifiable.size() << " parameters determined by the data ("
    << id.RobotParameterCount() << " of the robot, the rest the measuring "
    << "frame or fixed points), " << id.unidentifiable.size()
    << " held at nominal; condition number of the column-scaled Jacobian "
    << Fmt(id.condition, 3) << ".";
  page->Paragraph(s.str());
  std::vector<std::vector<std::string>> rows;
  for (size_t i = 0; i < id.unidentifiable.size(); ++i) {
    rows.push_back({id.unidentifiable[i].name,
                    i < id.relations.size() ? id.relations[i] : ""});
  }
  if (!rows.empty()) {
    page->Table(
        {"held at nominal", "why: the combination it is redundant with"}, rows);
  }
  if (!id.weak.empty()) {
    std::string w;
    for (const auto& x : id.weak) w += (w.empty() ? "" : ", ") + x;
    page->Paragraph("Weakly determined (estimated, large sigma): " + w + ".");
  }
}

namespace {

void AddBundleParameters(const ReportInputs& in, const ReportOptions& opt,
                         HtmlReport* page) {
  std::vector<std::vector<std::string>> rows;
  for (const char* key : {"params", "extensions"}) {
    if (!in.bundle.contains(key) || !in.bundle[key].is_array()) continue;
    for (const auto& p : in.bundle[key]) {
      auto num = [&](const char* k) {
        return p.contains(k) && p[k].is_number() ? Fmt(p[k].get<double>(), 6)
                                                 : std::string("-");
      };
      rows.push_back({p.value("name", "?"), num("value"), num("sigma")});
    }
  }
  page->Table({"parameter", "value (mm | deg)", "sigma"}, rows);
  page->Paragraph("From " + opt.bundle +
                  " (kincal bundle --json): the bundle adjustment's own "
                  "values and 1-sigma, not re-fitted here.");
}

}  // namespace

void AddParametersSection(const ReportInputs& in, const ReportAnalysis& an,
                          const ReportOptions& opt, HtmlReport* page) {
  if (in.has_bundle) {
    page->Section("parameters", "Parameters: the bundle adjustment's");
    AddBundleParameters(in, opt, page);
    return;
  }
  if (!an.has_calres) return;
  const CalibrateResult& c = an.calres;
  page->Section("parameters", "Parameters: nominal -> calibrated");
  ModelState nom;
  nom.chain = Chain::FromRobot(an.nominal);
  ModelState file_state;
  if (in.has_cal) file_state.chain = Chain::FromRobot(in.cal);
  std::vector<std::vector<std::string>> rows;
  for (size_t i = 0; i < c.fit.params.size(); ++i) {
    const ParamInfo& p = c.fit.params[i];
    if (p.kind != ParamKind::kRow && p.kind != ParamKind::kFrame) continue;
    const bool row = p.kind == ParamKind::kRow;
    const double n0 = row ? p.ToInterface(ParamValue(nom, p)) : NAN;
    const double v = c.fit.values[i];
    std::vector<std::string> r = {
        p.name,    p.InterfaceUnit(),       Fmt(n0, 6),
        Fmt(v, 6), Fmt(c.fit.sigmas[i], 2), row ? Fmt(v - n0, 3) : "-"};
    if (in.has_cal) {
      r.push_back(row && in.has_robot
                      ? Fmt(p.ToInterface(ParamValue(file_state, p)), 6)
                      : "-");
    }
    rows.push_back(r);
  }
  std::vector<std::string> head = {"parameter",  "unit",  "nominal",
                                   "calibrated", "sigma", "change"};
  if (in.has_cal) head.push_back("in " + opt.calibrated);
  page->Table(head, rows);
  page->Paragraph(
      "Calibrated here with the calib library (the defaults of kincal "
      "calibrate: 20 % of the poses held out, seed " +
      std::to_string(opt.seed) +
      "); sigma is 1-sigma from the fit's covariance scaled by the residual "
      "noise.");
}

}  // namespace kincal
