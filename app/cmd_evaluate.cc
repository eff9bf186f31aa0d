// kincal evaluate: fit only the base-to-measuring-frame transform, then report
// the position error of a (calibrated) robot model on new data.

#include <cmath>
#include <algorithm>
#include <cstdio>
#include <memory>
#include <sstream>

#include "app/app_util.h"
#include "app/command.h"
#include "calib/evaluate.h"
#include "data/atomic_file.h"
#include "data/csv.h"
#include "data/provenance.h"
#include "data/urdf.h"
#include "data/yaml_util.h"

namespace kincal::app {
namespace {

struct EvaluateArgs {
  std::string robot, obs, residuals, root, tip;
  bool json = false;
  double outlier_sigmas = kDefaultOutlierSigmas;
};

// Single-point data: per fixed point, the scatter about its fitted
// position, and the distances between the fitted points (the model's
// prediction of a known distance, e.g. two sockets 50 mm apart). Rows
// flagged in `excluded` (may be empty) are left out of the scatter.
void AddPointsJson(const ModelState& st, const Observations& obs,
                   const std::vector<int>& rows,
                   const std::vector<double>& errors_mm,
                   const std::vector<char>& excluded, nlohmann::json* j) {
  if (st.point_labels.empty()) return;
  nlohmann::json points = nlohmann::json::object();
  for (size_t k = 0; k < st.point_labels.size(); ++k) {
    double sum = 0;
    int n = 0;
    for (size_t i = 0; i < rows.size(); ++i) {
      if (!excluded.empty() && excluded[i]) continue;
      if (obs.rows[rows[i]].fixed_point != st.point_labels[k]) continue;
      sum += errors_mm[i] * errors_mm[i];
      ++n;
    }
    const auto& p = st.points_in_base[k];
    points[st.point_labels[k]] = {
        {"n", n},
        {"rms_mm", Number(n > 0 ? std::sqrt(sum / n) : NAN)},
        {"in_base_mm", {p[0], p[1], p[2]}}};
  }
  (*j)["fixed_points"] = points;
  nlohmann::json dist = nlohmann::json::array();
  for (size_t a = 0; a < st.point_labels.size(); ++a) {
    for (size_t b = a + 1; b < st.point_labels.size(); ++b) {
      const auto& pa = st.points_in_base[a];
      const auto& pb = st.points_in_base[b];
      const double d = std::sqrt((pa[0] - pb[0]) * (pa[0] - pb[0]) +
                                 (pa[1] - pb[1]) * (pa[1] - pb[1]) +
                                 (pa[2] - pb[2]) * (pa[2] - pb[2]));
      dist.push_back({{"a", st.point_labels[a]},
                      {"b", st.point_labels[b]},
                      {"distance_mm", d}});
    }
  }
  (*j)["point_distances"] = dist;
}

// Per series (spec v3): its figures and its registered frame (rotation
// vector deg, translation mm).
nlohmann::json SeriesJson(const EvaluateResult& r) {
  nlohmann::json list = nlohmann::json::array();
  for (const SeriesEvaluation& s : r.series) {
    nlohmann::json j = {{"name", s.name}};
    j.update(StatsJson(s.stats));
    const auto& f = s.state.meas_from_base;
    j["frame"] = {{"rotation_deg",
                   {f[0] * 180 / M_PI, f[1] * 180 / M_PI, f[2] * 180 / M_PI}},
                  {"translation_mm", {f[3], f[4], f[5]}}};
    if (s.has_robust) j["without_outliers"] = StatsJson(s.robust_stats);
    list.push_back(j);
  }
  return list;
}

void WriteResiduals(const std::string& path, const Observations& obs,
                    const EvaluateResult& r) {
  const bool series = obs.AnySeriesLabel();
  std::ostringstream os;
  os << "# written by " << ToolVersion() << ": " << CommandLine() << "\n";
  os << "pose,error_mm" << (series ? ",series" : "") << "\n";
  for (size_t i = 0; i < r.rows.size(); ++i) {
    const Observation& o = obs.rows[r.rows[i]];
    os << CsvQuote(o.pose) << "," << FormatDouble(r.errors_mm[i]);
    if (series) os << "," << CsvQuote(o.series);
    os << "\n";
  }
  WriteFileAtomic(path, os.str());
}

void PrintSeries(const EvaluateResult& r) {
  for (const SeriesEvaluation& s : r.series) {
    std::printf(
        "  series '%s': %d poses, own frame: RMS %.4f mm, mean %.4f, max "
        "%.4f, std %.4f\n",
        s.name.c_str(), s.stats.n, s.stats.rms_mm, s.stats.mean_mm,
        s.stats.max_mm, s.stats.std_mm);
  }
}

// The thermal terms hold at the temperatures they were fitted on
// (calib/chain.h Chain::thermal_lo/hi): rows beyond are evaluated with the
// input clamped, and the warning says so.
void WarnTemperatureClamped(const Robot& robot, const Observations& obs,
                            Warnings* warnings) {
  const FitRecord& rec = robot.fitted_on;
  const bool thermal = std::any_of(
      robot.extensions.begin(), robot.extensions.end(),
      [](const Extension& e) { return e.cause == "thermal"; });
  if (!thermal || rec.thermal_input != "temp_c" ||
      !(rec.temp_lo_c == rec.temp_lo_c))
    return;
  int outside = 0;
  double lo = rec.temp_lo_c, hi = rec.temp_hi_c;
  for (const Observation& o : obs.rows) {
    if (!o.HasTemp() ||
        (o.temp_c >= rec.temp_lo_c && o.temp_c <= rec.temp_hi_c))
      continue;
    ++outside;
    lo = std::min(lo, o.temp_c);
    hi = std::max(hi, o.temp_c);
  }
  if (outside == 0) return;
  char msg[400];
  std::snprintf(msg, sizeof msg,
                "%d rows have temp_c outside the range the thermal terms were "
                "fitted on [%.2f, %.2f] C (these rows: %.2f .. %.2f C): the "
                "model holds the thermal input at the range's ends there "
                "instead of extrapolating the growth linearly",
                outside, rec.temp_lo_c, rec.temp_hi_c, lo, hi);
  warnings->Add("temperature_clamped", msg);
}

int RunEvaluate(const EvaluateArgs& args) {
  const Robot robot = ReadRobot(args.robot, args.root, args.tip);
  Warnings warnings = CommandWarnings();
  const Observations obs =
      ReadCheckedObservations(args.obs, robot, args.robot, &warnings);
  const EvaluateResult r = Evaluate(robot, obs, args.outlier_sigmas);
  WarnTemperatureClamped(robot, obs, &warnings);
  if (!args.residuals.empty()) WriteResiduals(args.residuals, obs, r);
  const bool labelled = obs.AnySeriesLabel();
  if (args.json) {
    nlohmann::json j = StatsJson(r.stats);
    j["extensions"] = robot.extensions.size();
    AddPointsJson(r.state, obs, r.rows, r.errors_mm, {}, &j);
    if (labelled) j["series"] = SeriesJson(r);
    j["outlier_sigmas"] = args.outlier_sigmas;
    j["outliers"] = OutliersJson(r.outliers);
    if (r.has_robust) {
      j["outlier_axis_sigma_mm"] = Number(r.outlier_axis_sigma_mm);
      nlohmann::json w = StatsJson(r.robust.stats);
      AddPointsJson(r.robust.state, obs, r.rows, r.robust.errors_mm, r.excluded,
                    &w);
      j["without_outliers"] = w;
    }
    AddWarnings(warnings, &j);
    PrintJson(j);
    return 0;
  }
  if (r.series.size() > 1) {
    std::printf(
        "kincal evaluate: %d poses in %zu series, one frame per series "
        "registered only\n",
        r.stats.n, r.series.size());
  } else {
    std::printf("kincal evaluate: %d poses, frame registered only\n",
                r.stats.n);
  }
  std::printf("  RMS %.4f mm, mean %.4f, max %.4f, std %.4f\n", r.stats.rms_mm,
              r.stats.mean_mm, r.stats.max_mm, r.stats.std_mm);
  if (labelled) PrintSeries(r);
  PrintOutliers(r.outliers, r.outlier_axis_sigma_mm, args.outlier_sigmas);
  if (r.has_robust) {
    const ErrorStats& w = r.robust.stats;
    std::printf(
        "  without them (frame registered on the other %d): RMS %.4f mm, "
        "mean %.4f, max %.4f, std %.4f\n",
        w.n, w.rms_mm, w.mean_mm, w.max_mm, w.std_mm);
  }
  return 0;
}

}  // namespace

void AddEvaluateCommand(CLI::App& app, Runner* run) {
  auto args = std::make_shared<EvaluateArgs>();
  CLI::App* sub = app.add_subcommand(
      "evaluate",
      "Register only the measuring frame (one per series) and report the tip "
      "position error of a robot model (with its extensions) on "
      "observations");
  AddRobotOptions(sub, &args->robot, &args->root, &args->tip,
                  "robot.yaml (calibrated) or .urdf")
      ->required();
  sub->add_option("--obs", args->obs, "observations.csv")->required();
  sub->add_option("--residuals", args->residuals,
                  "write per-pose errors to this CSV");
  sub->add_option("--outlier-sigma", args->outlier_sigmas,
                  "list rows whose error exceeds this many robust sigmas "
                  "(per axis, from the median error) and add the figures "
                  "without them (0 = none)")
      ->check(CLI::Range(0.0, 1e6))
      ->capture_default_str();
  sub->add_flag("--json", args->json, "print one JSON object");
  sub->footer(HelpFooter(
      "Example: the calibrated model on new poses:\n  kincal evaluate --robot "
      "cal.yaml --obs new_poses.csv --residuals errors.csv"));
  sub->callback([run, args] { *run = [args] { return RunEvaluate(*args); }; });
}

}  // namespace kincal::app
