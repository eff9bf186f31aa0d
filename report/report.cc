#include "report/report.h"

#include <sys/stat.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "calib/calibrate.h"
#include "calib/chain.h"
#include "calib/sensitivity.h"
#include "camcal/rig.h"
#include "data/atomic_file.h"
#include "data/error.h"
#include "data/provenance.h"
#include "data/urdf.h"
#include "diagnose/clearance.h"
#include "report/camera_sections.h"
#include "report/html.h"
#include "report/residuals.h"

namespace kincal {
namespace {

bool Exists(const std::string& path) {
  struct stat st;
  return !path.empty() && ::stat(path.c_str(), &st) == 0;
}

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

// "# ..." provenance lines of a text file (first 6 comment lines) or the
// "command" of a JSON object.
std::vector<std::string> Provenance(const std::string& path) {
  std::vector<std::string> out;
  std::ifstream in(path);
  std::string line;
  int comments = 0;
  bool first = true;
  while (std::getline(in, line) && comments < 6) {
    if (first && !line.empty() && line[0] == '{') {
      try {
        const auto j = nlohmann::json::parse(ReadFile(path));
        if (j.contains("command"))
          out.push_back(j["command"].get<std::string>());
        if (j.contains("kincal_version")) {
          out.push_back(j["kincal_version"].get<std::string>());
        }
      } catch (const std::exception&) {
      }
      return out;
    }
    first = false;
    size_t at = line.find_first_not_of(" \t");
    if (at == std::string::npos) continue;
    if (line.compare(at, 4, "<!--") == 0 || line[at] == '#') {
      out.push_back(line.substr(at));
      ++comments;
    } else if (line[at] != '<') {
      break;
    }
  }
  return out;
}

Robot WithoutExtensions(Robot r) {
  r.extensions.clear();
  return r;
}

std::string JointUnit(const Robot& r, int j) {
  return r.joints[j].type == JointType::kPrismatic ? "mm" : "deg";
}

struct Inputs {
  bool has_robot = false, has_cal = false, has_obs = false;
  Robot robot, cal;
  Observations obs;
  nlohmann::json diag;
  bool has_diag = false;
};

// Parameter unit shown in tables.
std::string Unit(const ParamInfo& p) { return p.angle ? "deg" : "mm"; }

}  // namespace

ReportResult BuildReport(
    const ReportOptions& opt,
    const std::function<void(const std::string&)>& progress_fn) {
  auto progress = [&](const std::string& what) {
    if (progress_fn) progress_fn(what);
  };
  ReportResult result;
  Inputs in;
  // --- read every input first: bad input fails before any computation.
  if (!opt.robot.empty()) {
    in.robot = ReadRobot(opt.robot, opt.root, opt.tip);
    in.has_robot = true;
  }
  if (!opt.calibrated.empty()) {
    in.cal = ReadRobot(opt.calibrated, opt.root, opt.tip);
    in.has_cal = true;
  }
  if (!opt.obs.empty()) {
    Require(in.has_robot || in.has_cal,
            "--obs needs --robot or --calibrated (the joint names)");
    const Robot& r = in.has_robot ? in.robot : in.cal;
    in.obs = ReadObservationsCsv(opt.obs, r.JointNames());
    in.has_obs = true;
  }
  if (in.has_robot && in.has_cal) {
    Require(in.robot.JointNames() == in.cal.JointNames(),
            opt.calibrated + ": joints differ from " + opt.robot);
  }
  if (!opt.diagnosis.empty()) {
    const std::string text = ReadFile(opt.diagnosis);
    try {
      in.diag = nlohmann::json::parse(text);
    } catch (const nlohmann::json::parse_error& e) {
      throw InputError(opt.diagnosis, 0, 0,
                       std::string("expected the JSON printed by `kincal "
                                   "diagnose model --json`: ") +
                           e.what());
    }
    if (!in.diag.is_object() || !in.diag.contains("verdict") ||
        !in.diag.contains("findings") || !in.diag["findings"].is_array()) {
      throw InputError(opt.diagnosis, 1, 1,
                       "expected an object with 'verdict' and 'findings' "
                       "(the output of `kincal diagnose model --json`)");
    }
    in.has_diag = true;
  }
  Rig rig;
  bool has_rig = false;
  if (!opt.rig.empty()) {
    rig = ReadRigYaml(opt.rig);
    has_rig = true;
  }
  nlohmann::json camcal;
  std::string camcal_path = opt.camcal_json;
  if (camcal_path.empty() && has_rig) {  // camcal --json saved beside?
    const size_t dot = opt.rig.rfind('.');
    const std::string guess =
        (dot == std::string::npos ? opt.rig : opt.rig.substr(0, dot)) + ".json";
    if (Exists(guess)) camcal_path = guess;
  }
  if (!camcal_path.empty()) {
    try {
      camcal = nlohmann::json::parse(ReadFile(camcal_path));
    } catch (const nlohmann::json::parse_error& e) {
      throw InputError(camcal_path, 0, 0,
                       std::string("expected camcal's JSON: ") + e.what());
    }
  }
  std::string points_path;
  if (!opt.session.empty()) {
    Require(Exists(opt.session), opt.session + ": no such session folder");
    points_path = opt.session + "/points.csv";
    if (opt.session.size() > 4 &&
        opt.session.compare(opt.session.size() - 4, 4, ".csv") == 0) {
      points_path = opt.session;
    }
  }

  const std::string name = in.has_robot ? in.robot.name
                           : in.has_cal ? in.cal.name
                                        : std::string("kincal");
  HtmlReport page("kincal report: " + name);
  std::vector<std::string> verdict;

  // --- computations ------------------------------------------------------
  const bool can_fit = in.has_obs && (in.has_robot || in.has_cal);
  const Robot nominal =
      in.has_robot ? in.robot : WithoutExtensions(in.cal);  // start values
  bool has_calres = false;
  CalibrateResult calres;
  ResidualSet res_nominal, res_geo, res_ext;
  bool has_nominal = false, has_geo = false, has_ext = false;
  Robot geometric;
  if (can_fit) {
    progress("calibrating the geometry (held-out poses, identifiability)");
    try {
      CalibrateOptions co;
      co.seed = opt.seed;
      calres = Calibrate(nominal, in.obs, co);
      has_calres = true;
    } catch (const InputError& e) {
      result.notes.push_back(std::string("calibration skipped: ") + e.what());
    }
    geometric = in.has_cal   ? WithoutExtensions(in.cal)
                : has_calres ? calres.calibrated
                             : nominal;
    progress("residuals of the nominal, geometric and extended models");
    if (in.has_robot) {
      res_nominal = ComputeResiduals(in.robot, in.obs, "nominal");
      has_nominal = true;
    }
    res_geo = ComputeResiduals(geometric, in.obs, "geometric model");
    has_geo = true;
    if (in.has_cal && !in.cal.extensions.empty()) {
      res_ext = ComputeResiduals(in.cal, in.obs, "with extensions");
      has_ext = true;
    }
  }

  // --- verdict ---------------------------------------------------------------
  std::ostringstream struct_words;
  int pair_a = -1, pair_b = -1;
  double pair_share = 0, share_a = 0, share_b = 0, pair_share_ext = -1;
  const Robot& jr = in.has_robot ? in.robot : in.cal;
  const int nj = (in.has_robot || in.has_cal) ? (int)jr.joints.size() : 0;
  std::vector<std::vector<double>> qcol(nj);
  if (has_geo) {
    for (int j = 0; j < nj; ++j) {
      for (int row : res_geo.rows) qcol[j].push_back(in.obs.rows[row].q[j]);
    }
    for (int a = 0; a < nj; ++a) {
      for (int b = a + 1; b < nj; ++b) {
        const double s =
            VectorExplainedByGrid(qcol[a], qcol[b], res_geo.e_in_base, 5);
        if (s > pair_share) pair_share = s, pair_a = a, pair_b = b;
      }
    }
    if (pair_a >= 0) {
      std::vector<double> zero(qcol[pair_a].size(), 0.0);
      share_a = VectorExplainedByGrid(qcol[pair_a], zero, res_geo.e_in_base, 5);
      share_b = VectorExplainedByGrid(qcol[pair_b], zero, res_geo.e_in_base, 5);
      if (has_ext && res_ext.rows == res_geo.rows) {
        pair_share_ext = VectorExplainedByGrid(qcol[pair_a], qcol[pair_b],
                                               res_ext.e_in_base, 5);
      }
      struct_words << "What the geometric model still gets wrong (RMS "
                   << Fmt(res_geo.stats.rms_mm, 3) << " mm on "
                   << res_geo.stats.n << " poses) depends most on "
                   << jr.joints[pair_a].name << " x " << jr.joints[pair_b].name
                   << ": their 5 x 5 grid explains " << Fmt(100 * pair_share, 2)
                   << " % of the variance of the 3D error vectors ("
                   << jr.joints[pair_a].name << " alone "
                   << Fmt(100 * share_a, 2) << " %, " << jr.joints[pair_b].name
                   << " alone " << Fmt(100 * share_b, 2) << " %; by chance ~"
                   << Fmt(100 * 24.0 / std::max(1, res_geo.stats.n), 2)
                   << " %).";
      if (pair_share_ext >= 0) {
        struct_words << " With the extensions: " << Fmt(100 * pair_share_ext, 2)
                     << " %.";
      }
    }
  }
  if (in.has_diag) {
    const auto& d = in.diag;
    const std::string v = d.value("verdict", "");
    std::vector<std::string> parts;
    for (const auto& f : d["findings"]) {
      const std::string cause = f.value("cause", "?");
      const std::string joint = f.contains("joint") && f["joint"].is_string()
                                    ? f["joint"].get<std::string>()
                                    : "";
      std::ostringstream s;
      auto num = [](const nlohmann::json& x) {
        return x.is_number() ? x.get<double>() : NAN;
      };
      if (cause == "unexplained") {
        s << "unexplained systematic error, RMS "
          << Fmt(num(f.value("magnitude", nlohmann::json())), 3) << " mm";
        if (f.contains("depends_on") && f["depends_on"].is_array()) {
          std::string dep;
          for (const auto& x : f["depends_on"]) {
            dep += (dep.empty() ? "" : ", ") + x.get<std::string>();
          }
          if (!dep.empty()) s << " depending on " << dep;
        }
      } else {
        s << cause << (joint.empty() ? "" : " in " + joint) << ", "
          << Fmt(num(f.value("magnitude", nlohmann::json())), 3) << " "
          << f.value("unit", "");
        if (f.contains("ci95") && f["ci95"].size() == 2) {
          s << " [" << Fmt(num(f["ci95"][0]), 3) << ", "
            << Fmt(num(f["ci95"][1]), 3) << "]";
        }
        s << "; held-out error "
          << Fmt(num(f.value("heldout_rms_before_mm", nlohmann::json())), 3)
          << " -> "
          << Fmt(num(f.value("heldout_rms_after_mm", nlohmann::json())), 3)
          << " mm";
      }
      parts.push_back(s.str());
    }
    std::ostringstream head;
    head << (v == "effect_found" ? "Diagnosis: effect found. "
                                 : "Diagnosis: no significant effect. ");
    if (d.contains("nominal") && d.contains("final")) {
      head << "Held-out error "
           << Fmt(d["nominal"].value("heldout_rms_mm", NAN), 3) << " mm with "
           << "the calibrated geometry -> "
           << Fmt(d["final"].value("heldout_rms_mm", NAN), 3)
           << " mm with the model extensions.";
    }
    verdict.push_back(head.str());
    for (const auto& p : parts) verdict.push_back(p);
  }
  if (has_calres) {
    std::ostringstream s;
    s << "Geometric calibration (run here, seed " << opt.seed
      << "): held-out RMS " << Fmt(calres.heldout.rms_mm, 3) << " mm on "
      << calres.heldout.n << " poses (training " << Fmt(calres.train.rms_mm, 3)
      << " mm)";
    if (has_nominal) {
      s << "; the nominal robot, frame registered only: "
        << Fmt(res_nominal.stats.rms_mm, 3) << " mm";
    }
    s << ". " << calres.identifiability.RobotParameterCount()
      << " robot parameters identifiable; "
      << calres.identifiability.unidentifiable.size()
      << " others are redundant with them or the frame and stay at nominal "
         "(see Identifiability).";
    verdict.push_back(s.str());
    if (!calres.outliers.empty()) {
      // Gross errors (calib/outliers.h): named in words, the poses first.
      std::ostringstream g;
      g << calres.outliers.size() << " row(s) are more than "
        << Fmt(kDefaultOutlierSigmas, 2) << " robust sigmas ("
        << Fmt(calres.outlier_axis_sigma_mm, 3)
        << " mm per axis) off the calibrated model";
      g << (calres.outliers_too_many
                ? " (too many to leave them all out: the model may be wrong "
                  "rather than the rows)"
                : " and were left out of the fit");
      g << ":";
      for (size_t i = 0; i < calres.outliers.size() && i < 10; ++i) {
        const RowOutlier& o = calres.outliers[i];
        g << (i ? ";" : "") << " pose " << o.pose << ": " << Fmt(o.error_mm, 3)
          << " mm" << (o.heldout ? ", held out" : "")
          << (o.excluded ? "" : ", kept");
        if (!o.near_point.empty()) {
          g << " (" << Fmt(o.near_point_mm, 3) << " mm from " << o.near_point
            << ": saved under the wrong label?)";
        }
      }
      if (calres.outliers.size() > 10) g << "; ...";
      g << ". Check these rows of the data.";
      verdict.push_back(g.str());
    }
  }
  if (has_ext) {
    verdict.push_back("The extended model (" + opt.calibrated + ", " +
                      std::to_string(in.cal.extensions.size()) +
                      " extensions) on all poses: RMS " +
                      Fmt(res_ext.stats.rms_mm, 3) + " mm (geometry alone " +
                      Fmt(res_geo.stats.rms_mm, 3) + " mm).");
  }
  if (!struct_words.str().empty()) verdict.push_back(struct_words.str());

  // Clearance (needed for the verdict line, drawn later).
  bool has_clear = false;
  ClearanceResult clear;
  if (has_geo && in.obs.CountWithPoints() >= 3) {
    progress("the seed's Section 4 clearance sweeps");
    try {
      ClearanceOptions co;
      co.gamma = opt.gamma;
      // As `kincal diagnose clearance` does by default: calibrate the
      // nominal geometry on the same data first (without a nominal robot,
      // the geometric model as given).
      co.calibrate_geometry = in.has_robot;
      clear =
          DiagnoseClearance(in.has_robot ? in.robot : geometric, in.obs, co);
      has_clear = true;
      verdict.push_back(
          "Section 4 test (sweep +-" + Fmt(opt.gamma, 3) +
          " of each joint at the " + std::to_string(clear.sweeps.size()) +
          " worst poses): " +
          (clear.suspect >= 0
               ? "suspect joint " + clear.joint_names[clear.suspect] + "."
               : "no joint removes the error of the worst poses."));
    } catch (const InputError& e) {
      result.notes.push_back(std::string("clearance skipped: ") + e.what());
    }
  }
  if (verdict.empty()) {
    verdict.push_back(
        "No robot data given: the sections below show what the inputs hold.");
  }
  page.Section("verdict", "Verdict");
  std::string vhtml = "<div class='verdict'>";
  for (const auto& v : verdict) vhtml += "<p>" + XmlEscape(v) + "</p>";
  page.Raw(vhtml + "</div>");

  // --- diagnosis table ----------------------------------------------------
  if (in.has_diag) {
    page.Section("diagnosis", "Diagnosis: causes found");
    std::vector<std::vector<std::string>> rows;
    for (const auto& f : in.diag["findings"]) {
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
    page.Table({"cause", "joint", "magnitude", "unit", "95 % interval",
                "held-out before (mm)", "held-out after (mm)"},
               rows);
    page.Paragraph("From " + opt.diagnosis +
                   " (kincal diagnose model --json): causes tested jointly "
                   "with the geometry, kept when they lower the error on "
                   "poses held out of the fit.");
  }

  // --- residuals against joints, time, temperature -------------------------
  if (has_geo) {
    progress("drawing residual plots");
    page.Section("residuals", "What the model gets wrong: residuals");
    std::vector<const ResidualSet*> sets = {&res_geo};
    if (has_ext) sets.push_back(&res_ext);
    auto scatter = [&](const std::string& title, const std::string& xl,
                       auto xof) {
      Plot p;
      p.title = title;
      p.x_label = xl;
      p.y_label = "|error| (mm)";
      p.width = 420;
      p.height = 300;
      for (const ResidualSet* s : sets) {
        PlotSeries pts;
        pts.label = s->label;
        pts.points = true;
        std::vector<double> xs;
        for (size_t i = 0; i < s->rows.size(); ++i)
          xs.push_back(xof(s->rows[i]));
        for (int i : Thin(xs.size(), opt.max_points / 2)) {
          pts.x.push_back(xs[i]);
          pts.y.push_back(s->norm_mm[i]);
        }
        p.series.push_back(pts);
      }
      for (size_t k = 0; k < sets.size(); ++k) {
        const ResidualSet* s = sets[k];
        PlotSeries trend;
        trend.label = "";
        trend.color_index = static_cast<int>(k);
        std::vector<double> xs;
        for (int row : s->rows) xs.push_back(xof(row));
        BinnedMeans(xs, s->norm_mm, 12, &trend.x, &trend.y);
        p.series.push_back(trend);
      }
      return p;
    };
    std::vector<Plot> plots;
    for (int j = 0; j < nj; ++j) {
      plots.push_back(scatter(
          jr.joints[j].name, jr.joints[j].name + " (" + JointUnit(jr, j) + ")",
          [&, j](int row) { return in.obs.rows[row].q[j]; }));
    }
    page.FigureRow(
        plots,
        "|error| of each pose against each joint reading: the geometric "
        "model (blue)" +
            std::string(has_ext ? ", with the extensions (red)" : "") +
            "; lines: means of 12 equal-count bins. A trend means the "
            "geometric model misses something that depends on that joint." +
            ThinNote(res_geo.rows.size(), opt.max_points / 2));
    std::vector<Plot> tplots;
    if (in.obs.AnyTime()) {
      tplots.push_back(scatter("against time", "t (s)", [&](int row) {
        return in.obs.rows[row].HasTime() ? in.obs.rows[row].t_s : NAN;
      }));
    }
    bool has_temp = false;
    for (const Observation& r : in.obs.rows) has_temp |= r.HasTemp();
    if (has_temp) {
      tplots.push_back(
          scatter("against temperature", "temp_c (deg C)", [&](int row) {
            return in.obs.rows[row].HasTemp() ? in.obs.rows[row].temp_c : NAN;
          }));
    }
    if (!tplots.empty()) {
      page.FigureRow(tplots,
                     "|error| against time and temperature (drift, thermal "
                     "growth show as trends).");
    } else {
      page.Paragraph(
          "The observations have no t or temp_c column: no plot "
          "against time or temperature.");
    }

    // Structure over the two joints the error depends on most.
    if (pair_a >= 0) {
      page.Section("structure", "Residual structure over " +
                                    jr.joints[pair_a].name + " x " +
                                    jr.joints[pair_b].name);
      std::vector<Plot> maps;
      double cell_hi = 1.0;
      int grid_bins = 12;
      for (const ResidualSet* s : sets) {
        Plot p;
        p.title = s->label + ": |mean error vector| per cell (mm)";
        p.x_label = jr.joints[pair_a].name + " (" + JointUnit(jr, pair_a) + ")";
        p.y_label = jr.joints[pair_b].name + " (" + JointUnit(jr, pair_b) + ")";
        p.width = 520;
        p.height = 420;
        PlotSeries cells;
        cells.points = true;
        cells.color_label = "|mean error| (mm)";
        std::vector<double> xa, xb;
        for (int row : s->rows) {
          xa.push_back(in.obs.rows[row].q[pair_a]);
          xb.push_back(in.obs.rows[row].q[pair_b]);
        }
        // About 6 poses per cell on average, 4 to 12 cells a side.
        const int bins =
            std::clamp(static_cast<int>(std::sqrt(xa.size() / 6.0)), 4, 12);
        MeanVectorGrid(xa, xb, s->e_in_base, bins, 3, &cells.x, &cells.y,
                       &cells.color, &cells.cell_w, &cells.cell_h);
        if (maps.empty()) {
          cell_hi = cells.color.empty() ? 1.0
                                        : *std::max_element(cells.color.begin(),
                                                            cells.color.end());
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
      page.FigureRow(maps,
                     struct_words.str() +
                         " Colour: length of the mean error vector of the "
                         "poses in each cell of a " +
                         std::to_string(grid_bins) + " x " +
                         std::to_string(grid_bins) +
                         " grid (finer than the 5 x 5 grid of the shares "
                         "above, which keeps their chance level low; cells "
                         "with 3 or more poses; blue small, red "
                         "large; one scale from 0 for both maps): the "
                         "systematic part the model misses. Grey dots: the "
                         "poses." +
                         ThinNote(res_geo.rows.size(), opt.max_points / 2));
    }

    // 3D vectors in the workspace.
    page.Section("workspace", "Residual vectors in the workspace");
    std::vector<Plot> views;
    double extent = 0, emax = 0;
    for (size_t i = 0; i < res_geo.rows.size(); ++i) {
      extent = std::max(extent, res_geo.tip_in_base[i].cwiseAbs().maxCoeff());
      emax = std::max(emax, res_geo.norm_mm[i]);
    }
    const double scale = emax > 0 ? 0.12 * extent / emax : 1.0;
    for (int view = 0; view < 2; ++view) {
      Plot p;
      const int a = 0, b = view == 0 ? 1 : 2;
      p.title = res_geo.label +
                (view == 0 ? ": top view (x, y)" : ": side view (x, z)");
      p.x_label = "x in base (mm)";
      p.y_label = std::string(view == 0 ? "y" : "z") + " in base (mm)";
      p.width = 520;
      p.height = 460;
      p.equal_axes = true;
      PlotSeries arrows;
      arrows.label = "error x " + Fmt(scale, 3);
      arrows.points = true;
      arrows.color_label = "|error| (mm)";
      for (int i : Thin(res_geo.rows.size(), std::min(opt.max_points, 800))) {
        arrows.x.push_back(res_geo.tip_in_base[i][a]);
        arrows.y.push_back(res_geo.tip_in_base[i][b]);
        arrows.dx.push_back(scale * res_geo.e_in_base[i][a]);
        arrows.dy.push_back(scale * res_geo.e_in_base[i][b]);
        arrows.color.push_back(res_geo.norm_mm[i]);
      }
      p.series.push_back(arrows);
      views.push_back(p);
    }
    page.FigureRow(
        views,
        "Model tip positions in the robot base frame with the error "
        "vector (model - measured) drawn " +
            Fmt(scale, 3) +
            " times enlarged. Regions of long, aligned arrows are "
            "where the geometric model fails." +
            ThinNote(res_geo.rows.size(), std::min(opt.max_points, 800)));
  }

  // --- the seed's Section 3: sensitivity curves -----------------------------
  if (has_geo) {
    progress("the seed's Section 3 sensitivity curves");
    std::vector<Plot> plots;
    std::string caption;
    if (in.obs.CountWithFixedPoint() >= 2) {
      try {
        SensitivityOptions so;
        const SensitivityResult sr = AnalyzeSensitivity(geometric, in.obs, so);
        for (const char* unit : {"mm", "deg"}) {
          Plot p;
          p.title =
              std::string("eps vs ") + (unit[0] == 'm' ? "lengths" : "angles");
          p.x_label =
              std::string("offset from the calibrated value (") + unit + ")";
          p.y_label = "eps (mm)";
          p.lines.push_back({so.eta_mm, "eta = 1 mm"});
          for (const auto& c : sr.curves) {
            if (c.unit != unit || c.flat) continue;
            p.series.push_back({c.param.name, c.offsets, c.eps_mm});
          }
          if (!p.series.empty()) plots.push_back(p);
        }
        caption =
            "The seed's Fig. 2/3: eps (mean distance of the model tips "
            "to their fixed point) as each parameter alone moves. "
            "Verdict: " +
            sr.verdict + ".";
        for (const auto& n : sr.notes) caption += " " + n;
      } catch (const InputError& e) {
        result.notes.push_back(std::string("sensitivity skipped: ") + e.what());
      }
    } else {
      // Measured points: the same curves with the RMS tip error, frame held.
      std::vector<std::string> skip;
      if (has_calres) skip = calres.identifiability.UnidentifiableNames();
      const std::vector<MeasuredCurve> curves =
          MeasuredSensitivity(geometric, in.obs, 5.0, 41, skip);
      for (const char* unit : {"mm", "deg"}) {
        Plot p;
        p.title = std::string("RMS error vs ") +
                  (unit[0] == 'm' ? "lengths" : "angles");
        p.x_label = std::string("offset from the model's value (") + unit + ")";
        p.y_label = "RMS |error| (mm)";
        for (const auto& c : curves) {
          if (c.unit == unit) p.series.push_back({c.name, c.offsets, c.rms_mm});
        }
        if (!p.series.empty()) plots.push_back(p);
      }
      caption =
          "The seed's Fig. 2/3 for measured points: the RMS tip error as each "
          "identifiable geometry parameter alone moves +-5 mm or deg from the "
          "geometric model (measuring frame held). Equal valleys at offset 0 "
          "mean no single parameter change improves the fit; a valley away "
          "from 0 names a parameter error.";
    }
    if (!plots.empty()) {
      page.Section("sensitivity", "Sensitivity curves (seed Section 3)");
      page.FigureRow(plots, caption);
    }
  }

  // --- the seed's Section 4: clearance sweeps -------------------------------
  if (has_clear) {
    page.Section("clearance", "Joint motion error test (seed Section 4)");
    Plot dev = DeviationPlot(clear);
    dev.title = "Deviation per pose, geometric model (Fig. 4)";
    dev.height = 300;
    std::vector<Plot> devs = {dev};
    if (has_ext) {
      Plot after = dev;
      after.title = "Deviation per pose with the extensions (Fig. 6)";
      after.series[0].x.clear();
      after.series[0].y.clear();
      for (size_t i = 0; i < res_ext.rows.size(); ++i) {
        after.series[0].x.push_back(static_cast<double>(i + 1));
        after.series[0].y.push_back(res_ext.norm_mm[i]);
      }
      after.lines = {{res_ext.stats.rms_mm, "RMS"}};
      after.y_min = 0;
      after.y_max =
          *std::max_element(clear.errors_mm.begin(), clear.errors_mm.end()) *
          1.05;
      devs.push_back(after);
    }
    page.FigureRow(devs,
                   "The error of every pose after registering the "
                   "measuring frame, in visit order" +
                       std::string(has_ext ? "; right: the same with "
                                             "the extensions, same scale"
                                           : "") +
                       ".");
    std::vector<Plot> sweeps;
    for (size_t k = 0; k < clear.sweeps.size(); ++k) {
      const PoseSweep& ps = clear.sweeps[k];
      Plot p = SweepPlot(clear, k);
      p.title = (k == 0 ? "Worst pose " : "Pose ") + ps.pose +
                (k == 0 ? " (Fig. 5)" : "");
      p.width = k == 0 ? 800 : 420;
      p.height = k == 0 ? 420 : 280;
      if (k == 0) {
        page.Figure(p, "Each joint's reading swept +-" + Fmt(clear.gamma, 3) +
                           " with the others fixed at the worst pose; y "
                           "axis 0 to 3x the pose's error (curves leaving "
                           "the frame are clipped) so the minimum near zero "
                           "stays visible.");
      } else {
        sweeps.push_back(p);
      }
    }
    if (!sweeps.empty()) {
      page.FigureRow(sweeps, "The next-worst poses (the seed's step 3).");
    }
    std::vector<std::vector<std::string>> rows;
    for (size_t j = 0; j < clear.joint_names.size(); ++j) {
      rows.push_back({clear.joint_names[j], std::to_string(clear.wins[j]),
                      Fmt(clear.median_ratio[j], 3)});
    }
    page.Table({"joint", "best at poses", "median error_min / error_before"},
               rows);
    page.Paragraph(
        clear.suspect >= 0
            ? "Suspect: " + clear.joint_names[clear.suspect] +
                  ". Caution (docs/DIAGNOSE.md): a sweep moves the tip along "
                  "one Jacobian column, so almost any joint lowers one "
                  "pose's error; the diagnosis tests a clearance model on "
                  "all poses instead."
            : "No suspect joint: no joint removes the worst poses' error.");
  }

  // --- identifiability and parameters --------------------------------------
  if (has_calres) {
    const Identifiability& id = calres.identifiability;
    page.Section("identifiability", "Identifiability");
    std::ostringstream s;
    s << id.identifiable.size() << " parameters determined by the data ("
      << id.RobotParameterCount() << " of the robot, the rest the measuring "
      << "frame or fixed points), " << id.unidentifiable.size()
      << " held at nominal; condition number of the column-scaled Jacobian "
      << Fmt(id.condition, 3) << ".";
    page.Paragraph(s.str());
    std::vector<std::vector<std::string>> rows;
    for (size_t i = 0; i < id.unidentifiable.size(); ++i) {
      rows.push_back({id.unidentifiable[i].name,
                      i < id.relations.size() ? id.relations[i] : ""});
    }
    if (!rows.empty()) {
      page.Table(
          {"held at nominal", "why: the combination it is redundant with"},
          rows);
    }
    if (!id.weak.empty()) {
      std::string w;
      for (const auto& x : id.weak) w += (w.empty() ? "" : ", ") + x;
      page.Paragraph("Weakly determined (estimated, large sigma): " + w + ".");
    }
    page.Section("parameters", "Parameters: nominal -> calibrated");
    ModelState nom;
    nom.chain = Chain::FromRobot(nominal);
    ModelState file_state;
    if (in.has_cal) file_state.chain = Chain::FromRobot(in.cal);
    std::vector<std::vector<std::string>> prow;
    for (size_t i = 0; i < calres.fit.params.size(); ++i) {
      const ParamInfo& p = calres.fit.params[i];
      if (p.kind != ParamKind::kRow && p.kind != ParamKind::kFrame) continue;
      const bool row = p.kind == ParamKind::kRow;
      const double n0 = row ? p.ToInterface(ParamValue(nom, p)) : NAN;
      const double v = calres.fit.values[i];
      std::vector<std::string> r = {p.name,
                                    Unit(p),
                                    Fmt(n0, 6),
                                    Fmt(v, 6),
                                    Fmt(calres.fit.sigmas[i], 2),
                                    row ? Fmt(v - n0, 3) : "-"};
      if (in.has_cal) {
        r.push_back(row && in.has_robot
                        ? Fmt(p.ToInterface(ParamValue(file_state, p)), 6)
                        : "-");
      }
      prow.push_back(r);
    }
    std::vector<std::string> head = {"parameter",  "unit",  "nominal",
                                     "calibrated", "sigma", "change"};
    if (in.has_cal) head.push_back("in " + opt.calibrated);
    page.Table(head, prow);
    page.Paragraph(
        "Calibrated here with the calib library (the defaults of "
        "kincal calibrate: 20 % of the poses held out, seed " +
        std::to_string(opt.seed) +
        "); sigma is 1-sigma from the fit's covariance scaled by "
        "the residual noise.");
  }

  // --- camera calibration and tracking (report/camera_sections.h) ---------
  if (has_rig) AddCameraSection(rig, camcal, camcal_path, &page);
  if (!points_path.empty()) {
    AddTrackingSection(points_path, Exists(points_path), &page);
  }

  // --- provenance -----------------------------------------------------------
  page.Section("provenance", "Inputs and the commands that made them");
  std::vector<std::vector<std::string>> prov;
  auto add = [&](const std::string& what, const std::string& path) {
    if (path.empty() || !Exists(path)) return;
    std::string cmd;
    for (const auto& l : Provenance(path))
      cmd += (cmd.empty() ? "" : " | ") + l;
    prov.push_back(
        {what, path, cmd.empty() ? "(no provenance recorded)" : cmd});
  };
  add("robot", opt.robot);
  add("observations", opt.obs);
  add("calibrated robot", opt.calibrated);
  add("diagnosis", opt.diagnosis);
  add("rig", opt.rig);
  add("camcal JSON", camcal_path);
  if (!opt.session.empty()) {
    add("session", opt.session + "/session.yaml");
    add("session frames", opt.session + "/frames.csv");
    add("tracked points", points_path);
  }
  page.Table({"input", "file", "made by"}, prov);
  page.Raw("<p>This report: <code>" + XmlEscape(CommandLine()) + "</code> (" +
           XmlEscape(ToolVersion()) + ").</p>");
  for (const auto& n : result.notes) {
    page.Raw("<p class='note'>" + XmlEscape(n) + "</p>");
  }
  result.html = page.Page("Written by " + ToolVersion() +
                          ". One self-contained file: no network needed; "
                          "figures are vector graphics (zoom, print).");
  result.sections = page.sections();
  result.figures = page.figures();
  return result;
}

}  // namespace kincal
