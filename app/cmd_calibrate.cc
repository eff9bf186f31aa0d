// kincal calibrate: geometry + base-to-measuring-frame transform from
// measured points (or the seed's single-point objective with --method paper).

#include <cstdio>
#include <iostream>
#include <memory>
#include <sstream>

#include "app/app_util.h"
#include "app/command.h"
#include "calib/calibrate.h"
#include "calib/evaluate.h"
#include "data/atomic_file.h"
#include "data/csv.h"
#include "data/error.h"
#include "data/progress.h"
#include "data/urdf.h"

namespace kincal::app {
namespace {

struct CalibrateArgs {
  std::string robot, obs, out, method = "lsq", root, tip;
  double bound_length_mm = 0, bound_angle_deg = 0;  // 0: the robot file's
  std::vector<std::string> distances, free;
  CalibrateOptions options;
  bool json = false;
};

FixedDistance ParseDistance(const std::string& text) {
  std::vector<std::string> parts;
  std::stringstream ss(text);
  for (std::string p; std::getline(ss, p, ',');) parts.push_back(p);
  FixedDistance d;
  if (parts.size() != 3 || parts[0].empty() || parts[1].empty() ||
      !ParseFiniteDouble(parts[2], &d.distance_mm) || d.distance_mm <= 0) {
    throw InputError("--fixed-distance '" + text +
                     "': expected LABEL_A,LABEL_B,DISTANCE_MM");
  }
  d.a = parts[0];
  d.b = parts[1];
  return d;
}

// The nominal robot, with --bound-length / --bound-angle applied.
Robot ReadNominal(const CalibrateArgs& args) {
  Robot nominal = ReadRobot(args.robot, args.root, args.tip);
  if (args.bound_length_mm > 0) nominal.bound_length_mm = args.bound_length_mm;
  if (args.bound_angle_deg > 0) nominal.bound_angle_deg = args.bound_angle_deg;
  if (args.bound_length_mm > 0 || args.bound_angle_deg > 0) {
    nominal.bounds_stated = true;
  }
  return nominal;
}

// The fit options: --method, --loss and --fixed-distance checked and added.
CalibrateOptions FitOptions(const CalibrateArgs& args) {
  CalibrateOptions options = args.options;
  if (args.method == "paper") {
    options.method = CalibrateOptions::kPaper;
  } else if (args.method == "lsq") {
    options.method = CalibrateOptions::kLeastSquares;
  } else {
    throw InputError("--method: expected 'lsq' or 'paper', got '" +
                     args.method + "'");
  }
  if (options.loss != "none" && options.loss != "huber" &&
      options.loss != "cauchy") {
    throw InputError("--loss: expected none, huber or cauchy");
  }
  for (const auto& d : args.distances) {
    options.distances.push_back(ParseDistance(d));
  }
  options.extra_params = args.free;
  return options;
}

// The calibrated robot.yaml, with the figures and the held parameters in
// its header comment.
void WriteCalibrated(const CalibrateArgs& args, const CalibrateResult& r) {
  std::ostringstream note;
  note << "calibrated by " << r.method << " from " << args.obs << ": train RMS "
       << r.train.rms_mm << " mm (" << r.train.n << " poses), held-out RMS "
       << r.heldout.rms_mm << " mm (" << r.heldout.n << " poses)";
  std::vector<std::string> comment = {note.str()};
  std::string held;
  for (const auto& name : r.identifiability.UnidentifiableNames()) {
    held += (held.empty() ? "" : ", ") + name;
  }
  if (!held.empty()) comment.push_back("held (not identifiable): " + held);
  WriteFileAtomic(args.out, FormatRobotYaml(r.calibrated, comment));
}

nlohmann::json CalibrateJson(const CalibrateArgs& args,
                             const CalibrateResult& r, const Robot& nominal) {
  const Identifiability& id = r.identifiability;
  nlohmann::json j;
  j["method"] = r.method;
  j["train_rms_mm"] = Number(r.train.rms_mm);
  j["heldout_rms_mm"] = r.heldout.n > 0 ? Number(r.heldout.rms_mm) : nullptr;
  j["train"] = StatsJson(r.train);
  j["heldout"] = StatsJson(r.heldout);
  j["identifiable"] = id.IdentifiableNames();
  j["unidentifiable"] = id.UnidentifiableNames();
  j["weakly_identifiable"] = id.weak;
  j["relations"] = id.relations;
  j["identifiability_passes"] = static_cast<int>(r.passes.size());
  j["freed"] = r.freed;
  j["held"] = r.held;
  nlohmann::json passes = nlohmann::json::array();
  for (const IdentifiabilityPass& p : r.passes) {
    passes.push_back({{"free", p.num_free},
                      {"freed", p.freed},
                      {"held", p.held},
                      {"train_rms_mm", Number(p.train_rms_mm)},
                      {"undone", p.undone}});
  }
  j["passes"] = passes;
  nlohmann::json widened = nlohmann::json::array();
  for (const WidenedBound& w : r.widened_bounds) {
    widened.push_back(
        {{"name", w.name}, {"from", Number(w.from)}, {"to", Number(w.to)}});
  }
  j["widened_bounds"] = widened;
  j["at_bound"] = r.at_bound;
  j["prior_weight"] = r.prior_weight;
  j["condition_number"] = Number(id.condition);
  j["parameters"] = ParametersJson(r.fit, [&] {
    ModelState s;
    s.chain = Chain::FromRobot(nominal);
    return s;
  }());
  j["sigma0_mm"] = Number(r.fit.sigma0_mm);
  j["termination"] = r.fit.termination;
  j["converged"] = r.fit.converged;
  j["iterations"] = r.fit.iterations;
  j["fit_seconds"] = r.fit.seconds;
  j["seconds"] = r.seconds;
  j["seed"] = args.options.seed;
  j["holdout_fraction"] = args.options.holdout_fraction;
  if (r.has_epsilon) {
    j["epsilon"] = {{"mean_mm", r.epsilon.mean_mm},
                    {"max_mm", r.epsilon.max_mm},
                    {"std_mm", r.epsilon.std_mm},
                    {"n", r.epsilon.n}};
  }
  if (!r.distance_errors_mm.empty())
    j["distance_errors_mm"] = r.distance_errors_mm;
  j["outlier_sigmas"] = args.options.outlier_sigmas;
  j["outlier_axis_sigma_mm"] = Number(r.outlier_axis_sigma_mm);
  j["outlier_rounds"] = r.outlier_rounds;
  j["outliers"] = OutliersJson(r.outliers);
  j["outliers_too_many"] = r.outliers_too_many;
  if (!args.out.empty()) j["out"] = args.out;
  return j;
}

void PrintCalibrate(const CalibrateArgs& args, const CalibrateResult& r,
                    const Robot& nominal, const nlohmann::json& j) {
  const Identifiability& id = r.identifiability;
  std::printf("kincal calibrate (%s): %d training poses, %d held out\n",
              r.method.c_str(), r.train.n, r.heldout.n);
  std::printf("  train RMS    %.4f mm   (mean %.4f, max %.4f)\n",
              r.train.rms_mm, r.train.mean_mm, r.train.max_mm);
  if (r.heldout.n > 0) {
    std::printf("  held-out RMS %.4f mm   (mean %.4f, max %.4f)\n",
                r.heldout.rms_mm, r.heldout.mean_mm, r.heldout.max_mm);
  }
  if (r.has_epsilon) {
    std::printf(
        "  epsilon (mean distance to the fixed point) %.4f mm, max %.4f, std "
        "%.4f\n",
        r.epsilon.mean_mm, r.epsilon.max_mm, r.epsilon.std_mm);
  }
  PrintOutliers(r.outliers, r.outlier_axis_sigma_mm,
                args.options.outlier_sigmas);
  if (r.outliers_too_many) {
    std::printf(
        "  warning: more rows are beyond the threshold than a fit can spare "
        "(a quarter, or a fixed point left with < 3): those listed as kept "
        "are in the figures; the model may be wrong rather than the rows\n");
  }
  std::printf("  %zu identifiable parameters, %zu held at nominal; %s\n",
              id.identifiable.size(), id.unidentifiable.size(),
              r.fit.termination.c_str());
  std::printf("  %zu identifiability pass(es)", r.passes.size());
  if (!r.freed.empty())
    std::printf(", freed at the solution: %zu", r.freed.size());
  if (!r.held.empty())
    std::printf(", held at the solution: %zu", r.held.size());
  std::printf("\n");
  for (const auto& rel : id.relations) std::printf("    %s\n", rel.c_str());
  for (const WidenedBound& w : r.widened_bounds) {
    std::printf(
        "  bound of %s widened %g -> %g (the data pressed it to its bound)\n",
        w.name.c_str(), w.from, w.to);
  }
  if (!r.at_bound.empty()) {
    std::string names;
    for (const auto& n : r.at_bound) names += (names.empty() ? "" : ", ") + n;
    if (nominal.bounds_stated ||
        args.options.method == CalibrateOptions::kPaper) {
      std::printf(
          "  warning: on their bound at the end: %s; the robot may "
          "deviate from its nominal model by more than the bounds allow\n",
          names.c_str());
    } else {
      std::printf(
          "  note: on their bound at the end: %s; a wider bound did not fit "
          "better by 1 %%: these data determine them weakly\n",
          names.c_str());
    }
  }

  std::printf("  %-14s %12s %12s %10s\n", "parameter", "nominal", "value",
              "sigma");
  for (const auto& p : j["parameters"]) {
    if (!p.contains("nominal")) continue;
    std::printf("  %-14s %12.4f %12.4f %10.4f %s\n",
                p["name"].get<std::string>().c_str(),
                p["nominal"].get<double>(), p["value"].get<double>(),
                p["sigma"].is_null() ? NAN : p["sigma"].get<double>(),
                p["unit"].get<std::string>().c_str());
  }
  if (!args.out.empty()) std::printf("  wrote %s\n", args.out.c_str());
  std::printf("  %.3f s\n", r.seconds);
}

int RunCalibrate(CalibrateArgs args) {
  const Robot nominal = ReadNominal(args);
  Warnings warnings = CommandWarnings();
  const Observations obs =
      ReadCheckedObservations(args.obs, nominal, args.robot, &warnings);
  // Several series: one measuring frame each, the robot shared.
  RequireNoFrameJump(nominal, obs, "calibrate");
  WarnPoseCoverage(nominal, obs, &warnings);
  args.options = FitOptions(args);
  Progress progress("kincal calibrate", args.json || obs.rows.size() < 500);
  progress.Stage("fitting " + std::to_string(obs.rows.size()) +
                 " poses (Ceres LM, identifiability, covariance)");
  const CalibrateResult r = Calibrate(nominal, obs, args.options);
  progress.Done();
  if (!args.out.empty()) WriteCalibrated(args, r);
  nlohmann::json j = CalibrateJson(args, r, nominal);
  AddWarnings(warnings, &j);
  if (args.json) {
    PrintJson(j);
    return 0;
  }
  PrintCalibrate(args, r, nominal, j);
  return 0;
}

}  // namespace

void AddCalibrateCommand(CLI::App& app, Runner* run) {
  auto args = std::make_shared<CalibrateArgs>();
  CLI::App* sub = app.add_subcommand(
      "calibrate",
      "Fit robot geometry and the base-to-measuring-frame transform to "
      "measured tip points (Ceres LM), or the seed's single-point objective");
  AddRobotOptions(sub, &args->robot, &args->root, &args->tip,
                  "nominal robot.yaml or .urdf")
      ->required();
  sub->add_option("--obs", args->obs, "observations.csv")->required();
  sub->add_option("--out", args->out, "calibrated robot.yaml to write");
  sub->add_option("--method", args->method,
                  "lsq (least squares, default) | paper (eq. 9, direct search)")
      ->capture_default_str();
  sub->add_option("--holdout", args->options.holdout_fraction,
                  "fraction of poses held out of the fit")
      ->capture_default_str();
  sub->add_option("--seed", args->options.seed, "seed of the held-out split")
      ->capture_default_str();
  sub->add_option("--loss", args->options.loss, "none | huber | cauchy")
      ->capture_default_str();
  sub->add_option("--loss-scale", args->options.loss_scale_mm,
                  "robust loss scale, mm")
      ->capture_default_str();
  sub->add_option("--rank-tol", args->options.identifiability.tolerance,
                  "identifiability threshold (sine of the angle to the span)")
      ->capture_default_str();
  sub->add_option("--bound-length", args->bound_length_mm,
                  "admissible deviation of lengths from nominal, mm, a hard "
                  "limit (default: the robot file's bounds; a URDF's 20 mm "
                  "are widened where the data press against them)")
      ->check(CLI::Range(1e-6, 1e4));
  sub->add_option("--bound-angle", args->bound_angle_deg,
                  "admissible deviation of angles from nominal, deg, a hard "
                  "limit (default: the robot file's bounds; a URDF's 10 deg "
                  "are widened where the data press against them)")
      ->check(CLI::Range(1e-6, 180.0));
  sub->add_option("--max-sigma-fraction",
                  args->options.identifiability.max_sigma_fraction,
                  "at the solution, hold a parameter whose predicted 1-sigma "
                  "exceeds this fraction of its bound")
      ->check(CLI::Range(1e-6, 1e6))
      ->capture_default_str();
  sub->add_option("--prior", args->options.prior_weight,
                  "ridge pull of the geometry towards nominal: residual "
                  "W * deviation / bound, mm-equivalent (0 = none; default "
                  "-1: 1 for single-point data, 0 with measured tip points)")
      ->check(CLI::Range(0.0, 1e6))
      ->capture_default_str();
  sub->add_option("--id-passes", args->options.max_identifiability_passes,
                  "most passes of fit -> identifiability at the solution -> "
                  "fit (1 = decide once, at the start values)")
      ->check(CLI::Range(1, 20))
      ->capture_default_str();
  sub->add_option("--outlier-sigma", args->options.outlier_sigmas,
                  "rows whose error exceeds this many robust sigmas (per "
                  "axis, from the median error) are gross errors: left out "
                  "of the fit and listed (0 = keep every row)")
      ->check(CLI::Range(0.0, 1e6))
      ->capture_default_str();
  sub->add_option("--fixed-distance", args->distances,
                  "known distance between fixed points: A,B,MM (repeatable)");
  sub->add_option("--distance-weight", args->options.distance_weight,
                  "weight of each --fixed-distance residual beside the tip "
                  "residuals (mm-equivalent per mm)")
      ->check(CLI::Range(1e-3, 1e6))
      ->capture_default_str();
  sub->add_option("--free", args->free,
                  "extra parameters to fit, e.g. j2.beta, or a joint-error "
                  "family for every joint, e.g. compliance (repeatable)");
  sub->add_flag("--json", args->json, "print one JSON object");
  sub->footer(HelpFooter(
      "Example (the demo session):\n  kincal calibrate --robot "
      "data/sessions/bh7_demo/robot.yaml --obs "
      "data/sessions/bh7_demo/observations.csv --out cal.yaml --json\n  "
      "Single-point data with a known 50 mm between two sockets:\n  kincal "
      "calibrate --robot panda.urdf --tip ball_link --obs panda.csv "
      "--fixed-distance hole_0,hole_1,50 --out cal.yaml"));
  sub->callback([run, args] { *run = [args] { return RunCalibrate(*args); }; });
}

}  // namespace kincal::app
