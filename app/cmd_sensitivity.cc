// kincal sensitivity: the seed paper's optimality criterion (Section 3,
// Fig. 2/3): eps of each parameter over +-range units around the calibrated
// value, valley values and locations, the verdict, and its blind spots.

#include <cstdio>
#include <memory>
#include <sstream>

#include "app/app_util.h"
#include "app/command.h"
#include "calib/sensitivity.h"
#include "data/atomic_file.h"
#include "data/csv.h"
#include "data/provenance.h"
#include "data/svg_plot.h"
#include "data/urdf.h"
#include "data/yaml_util.h"

namespace kincal::app {
namespace {

struct SensitivityArgs {
  std::string robot, obs, out_csv, plot, root, tip;
  SensitivityOptions options;
  bool json = false;
};

std::string CurvesCsv(const SensitivityResult& r) {
  std::ostringstream os;
  os << "# written by " << ToolVersion() << ": " << CommandLine() << "\n";
  os << "# eps at the given parameters " << FormatDouble(r.eps_mm)
     << " mm; verdict " << r.verdict << "\n";
  os << "param,unit,value,offset,eps_mm\n";
  for (const SensitivityCurve& c : r.curves) {
    for (size_t k = 0; k < c.offsets.size(); ++k) {
      os << c.param.name << "," << c.unit << "," << FormatDouble(c.value) << ","
         << FormatDouble(c.offsets[k]) << "," << FormatDouble(c.eps_mm[k])
         << "\n";
    }
  }
  return os.str();
}

std::string CurvesSvg(const SensitivityResult& r, double eta) {
  std::vector<Plot> plots;
  for (const char* unit : {"mm", "deg"}) {
    Plot p;
    p.title = std::string("eps vs. each ") +
              (std::string(unit) == "mm" ? "length" : "angle") +
              " parameter around the calibrated value (seed Fig. 3)";
    p.x_label = std::string("offset (") + unit + ")";
    p.y_label = "eps (mm)";
    for (const SensitivityCurve& c : r.curves) {
      if (c.unit != unit || c.flat) continue;
      p.series.push_back({c.param.name, c.offsets, c.eps_mm, false, false});
    }
    p.lines.push_back({eta, "eta"});
    p.lines.push_back({r.eps_mm, "eps at optimum"});
    if (!p.series.empty()) plots.push_back(p);
  }
  return FormatSvgPlots(plots);
}

int RunSensitivity(const SensitivityArgs& args) {
  const Robot robot = ReadRobot(args.robot, args.root, args.tip);
  Warnings warnings = CommandWarnings();
  const Observations obs =
      ReadCheckedObservations(args.obs, robot, args.robot, &warnings);
  RequireOneSeries(obs, "sensitivity");
  const SensitivityResult r = AnalyzeSensitivity(robot, obs, args.options);
  if (!args.out_csv.empty()) WriteFileAtomic(args.out_csv, CurvesCsv(r));
  if (!args.plot.empty()) {
    WriteFileAtomic(args.plot, CurvesSvg(r, args.options.eta_mm));
  }
  if (args.json) {
    nlohmann::json curves = nlohmann::json::array();
    for (const SensitivityCurve& c : r.curves) {
      curves.push_back({{"name", c.param.name},
                        {"unit", c.unit},
                        {"value", Number(c.value)},
                        {"valley_mm", Number(c.valley_mm)},
                        {"valley_offset", Number(c.valley_offset)},
                        {"flat", c.flat},
                        {"identifiable", c.identifiable},
                        {"improves", c.improves},
                        {"offsets", c.offsets},
                        {"eps_mm", c.eps_mm}});
    }
    nlohmann::json j = {{"verdict", r.verdict},
                        {"eps_mm", Number(r.eps_mm)},
                        {"epsilon", StatsJson(r.epsilon)},
                        {"eta_mm", args.options.eta_mm},
                        {"range", args.options.range},
                        {"steps", args.options.steps},
                        {"valleys_equal", r.valleys_equal},
                        {"below_eta", r.below_eta},
                        {"valley_min_mm", Number(r.valley_min_mm)},
                        {"valley_max_mm", Number(r.valley_max_mm)},
                        {"valley_tolerance_mm", Number(r.valley_tolerance_mm)},
                        {"reasons", r.reasons},
                        {"flat", r.flat},
                        {"unidentifiable", r.unidentifiable},
                        {"notes", r.notes},
                        {"curves", curves}};
    AddWarnings(warnings, &j);
    PrintJson(j);
    return 0;
  }
  std::printf(
      "kincal sensitivity: %d fixed-point poses, eps %.4f mm (max %.4f, std "
      "%.4f)\n",
      r.epsilon.n, r.eps_mm, r.epsilon.max_mm, r.epsilon.std_mm);
  std::printf("  %-16s %6s %12s %12s %12s  %s\n", "parameter", "unit", "value",
              "valley mm", "at offset", "");
  for (const SensitivityCurve& c : r.curves) {
    std::printf("  %-16s %6s %12.4f %12.6f %12.4f  %s%s%s\n",
                c.param.name.c_str(), c.unit.c_str(), c.value, c.valley_mm,
                c.valley_offset, c.flat ? "flat " : "",
                c.identifiable ? "" : "unidentifiable ",
                c.improves ? "IMPROVES" : "");
  }
  std::printf("  valleys %.6f .. %.6f mm (tolerance %.6f), eta %.3f mm\n",
              r.valley_min_mm, r.valley_max_mm, r.valley_tolerance_mm,
              args.options.eta_mm);
  std::printf("  verdict: %s\n", r.verdict.c_str());
  for (const auto& s : r.reasons) std::printf("    %s\n", s.c_str());
  std::printf("  what the criterion cannot see:\n");
  for (const auto& s : r.notes) std::printf("    %s\n", s.c_str());
  return 0;
}

}  // namespace

void AddSensitivityCommand(CLI::App& app, Runner* run) {
  auto args = std::make_shared<SensitivityArgs>();
  CLI::App* sub = app.add_subcommand(
      "sensitivity",
      "The seed's optimality criterion (Section 3): eps of each parameter "
      "over +-range around the calibrated value, valleys and verdict");
  AddRobotOptions(sub, &args->robot, &args->root, &args->tip,
                  "calibrated robot.yaml or .urdf")
      ->required();
  sub->add_option("--obs", args->obs, "observations.csv with fixed_point rows")
      ->required();
  sub->add_option("--range", args->options.range, "+- units (mm or deg)")
      ->capture_default_str();
  sub->add_option("--steps", args->options.steps, "grid points per curve (odd)")
      ->capture_default_str();
  sub->add_option("--eta", args->options.eta_mm, "accuracy index eta, mm")
      ->capture_default_str();
  sub->add_option("--param", args->options.params,
                  "parameter to vary (repeatable; default all geometry)");
  sub->add_option("--out-csv", args->out_csv, "curves as CSV");
  sub->add_option("--plot", args->plot, "curves as an SVG image");
  sub->add_flag("--json", args->json, "print one JSON object");
  sub->footer(HelpFooter(
      "Example (seed Section 3 on fixed-point data):\n  kincal simulate "
      "--robot data/robots/bh7.yaml --out fp --mode fixed-point\n  kincal "
      "calibrate --robot data/robots/bh7.yaml --obs fp/observations.csv "
      "--method paper --out cal.yaml\n  kincal sensitivity --robot cal.yaml "
      "--obs fp/observations.csv --plot curves.svg"));
  sub->callback(
      [run, args] { *run = [args] { return RunSensitivity(*args); }; });
}

}  // namespace kincal::app
