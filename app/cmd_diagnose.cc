// kincal diagnose: why the robot model is wrong.
//   diagnose model      model-discrepancy analysis (catalogue of causes)
//   diagnose clearance  the seed's Section 4 joint motion error test
//   diagnose compare    per-joint clearance before / after maintenance

#include <cmath>
#include <cstdio>
#include <memory>
#include <sstream>

#include "app/app_util.h"
#include "app/command.h"
#include "calib/evaluate.h"
#include "data/atomic_file.h"
#include "data/error.h"
#include "data/progress.h"
#include "data/urdf.h"
#include "diagnose/clearance.h"
#include "diagnose/compare.h"
#include "diagnose/model_diagnosis.h"

namespace kincal::app {
namespace {

struct ModelArgs {
  std::string robot, obs, out, residuals, root, tip;
  std::vector<std::string> validate;
  bool json = false;
  DiagnoseOptions options;
};

std::string FormatJoint(const std::string& joint) {
  return joint.empty() ? "-" : joint;
}

nlohmann::json Number(double v) {
  return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json();
}

// diagnose/series_checks.h as JSON: per series, then the scale test.
nlohmann::json SeriesJson(const SeriesChecks& c) {
  nlohmann::json per = nlohmann::json::array();
  for (const SeriesCheck& s : c.series) {
    per.push_back({{"name", s.name},
                   {"train_poses", s.train_poses},
                   {"heldout_poses", s.heldout_poses},
                   {"train_rms_mm", Number(s.train_rms_mm)},
                   {"heldout_rms_mm", Number(s.heldout_rms_mm)},
                   {"joints_cv_explained", Number(s.joints_cv_explained)},
                   {"point_cv_explained", Number(s.point_cv_explained)},
                   {"follows", s.follows},
                   {"scale_ppm", Number(s.scale_ppm)},
                   {"scale_sigma_ppm", Number(s.scale_sigma_ppm)}});
  }
  return {{"per_series", per},
          {"scale_f", Number(c.scale_f)},
          {"scale_p_value", Number(c.scale_p_value)},
          {"scale_significant", c.scale_significant},
          {"shared_scale_sine", Number(c.shared_scale_sine)}};
}

// The per-series lines of the text output (several series only).
void PrintSeries(const SeriesChecks& c) {
  if (c.series.empty()) return;
  std::printf(
      "  per series (own measuring frame): %-10s %6s %6s %10s %10s %7s %7s "
      "%-10s %s\n",
      "series", "train", "held", "train_mm", "held_mm", "joints", "point",
      "follows", "scale ppm vs first");
  for (const SeriesCheck& s : c.series) {
    std::printf("  %35s %-10s %6d %6d %10.4f %10.4f %7.2f %7.2f %-10s", "",
                s.name.empty() ? "-" : s.name.c_str(), s.train_poses,
                s.heldout_poses, s.train_rms_mm, s.heldout_rms_mm,
                s.joints_cv_explained, s.point_cv_explained, s.follows.c_str());
    if (std::isfinite(s.scale_sigma_ppm)) {
      std::printf(" %.1f +- %.1f\n", s.scale_ppm, s.scale_sigma_ppm);
    } else {
      std::printf(" (reference)\n");
    }
  }
  std::printf(
      "  instrument scale per series: F %.3g, p %.3g (%s); one scale shared "
      "by all series: %s (sine %.2g)\n",
      c.scale_f, c.scale_p_value,
      c.scale_significant ? "significant" : "not significant",
      c.shared_scale_sine < 1e-3 ? "not identifiable with the robot's lengths"
                                 : "identifiable",
      c.shared_scale_sine);
}

int RunModel(const ModelArgs& args) {
  const Robot robot = ReadRobot(args.robot, args.root, args.tip);
  Warnings warnings = CommandWarnings();
  const Observations obs =
      ReadCheckedObservations(args.obs, robot, args.robot, &warnings);
  // Several series: one measuring frame each, the robot shared.
  RequireNoFrameJump(robot, obs, "diagnose model");
  DiagnoseOptions options = args.options;
  for (const std::string& v : args.validate) {
    options.validation.push_back(
        ReadCheckedObservations(v, robot, args.robot, &warnings));
    RequireNoFrameJump(robot, options.validation.back(),
                       "diagnose model --validate");
  }
  Progress progress("kincal diagnose model", args.json);
  progress.Stage("fitting candidate extensions with the geometry, " +
                 std::to_string(obs.rows.size()) + " poses");
  const DiagnosisResult r = DiagnoseModel(robot, obs, options);
  progress.Done();
  for (const Warning& w : r.warnings) warnings.Add(w.code, w.message);
  if (!args.out.empty()) {
    std::ostringstream note;
    note << "diagnose model from " << args.obs << ": verdict " << r.verdict
         << ", held-out RMS " << r.nominal_heldout_rms_mm << " -> "
         << r.final_heldout_rms_mm << " mm";
    std::vector<std::string> comment = {note.str()};
    for (const Finding& f : r.findings) {
      std::ostringstream line;
      line << "finding: " << f.cause << " " << FormatJoint(f.joint) << " "
           << f.magnitude << " " << f.unit << " (95 % CI " << f.ci_low << " .. "
           << f.ci_high << ")";
      comment.push_back(line.str());
    }
    WriteFileAtomic(args.out, FormatRobotYaml(r.extended, comment));
  }
  if (!args.residuals.empty()) {
    WriteFileAtomic(args.residuals, ResidualsCsv(r, obs));
  }
  if (args.json) {
    nlohmann::json j = DiagnosisJson(r, options);
    if (!r.series.series.empty()) j["series"] = SeriesJson(r.series);
    if (!args.out.empty()) j["out"] = args.out;
    AddWarnings(warnings, &j);
    PrintJson(j);
    return 0;
  }
  std::printf(
      "kincal diagnose model: %d training + %d held-out poses, seed %llu\n",
      r.train_poses, r.heldout_poses,
      static_cast<unsigned long long>(args.options.seed));
  std::printf("  geometric model: train RMS %.4f mm, held-out RMS %.4f mm\n",
              r.nominal_train_rms_mm, r.nominal_heldout_rms_mm);
  if (r.folds >= 2) {
    std::printf(
        "  %d-fold cross-validated RMS (training poses): %.4f -> %.4f mm\n",
        r.folds, r.nominal_cv_rms_mm, r.final_cv_rms_mm);
  }
  std::printf("  noise %.4f mm per axis (%s), residual %.4f mm per axis\n",
              r.noise_mm, r.noise_source.c_str(), r.residual_sigma_mm);
  std::printf("  verdict: %s\n", r.verdict.c_str());
  if (!r.findings.empty()) {
    std::printf("  %-12s %-6s %12s %-5s %-25s %s\n", "cause", "joint",
                "magnitude", "unit", "95% interval",
                "held-out RMS before -> after");
  }
  for (const Finding& f : r.findings) {
    char ci[64];
    std::snprintf(ci, sizeof(ci), "[%.5g, %.5g]", f.ci_low, f.ci_high);
    std::printf("  %-12s %-6s %12.5g %-5s %-25s %.4f -> %.4f mm\n",
                f.cause.c_str(), FormatJoint(f.joint).c_str(), f.magnitude,
                f.unit.c_str(), ci, f.heldout_rms_before_mm,
                f.heldout_rms_after_mm);
    if (r.folds >= 2 && f.cause != "unexplained") {
      std::printf("    %d-fold cross-validated RMS %.4f -> %.4f mm\n", r.folds,
                  f.cv_rms_before_mm, f.cv_rms_after_mm);
    }
    if (f.periodic) {
      std::string arcs;
      for (const auto& a : f.extrapolated) {
        char buf[64];
        std::snprintf(buf, sizeof buf, "%s%.1f..%.1f", arcs.empty() ? "" : ", ",
                      a[0], a[1]);
        arcs += buf;
      }
      std::printf(
          "    periodic over the revolution: amplitude %.4f deg, supported by "
          "the travel [%.1f, %.1f] deg; extrapolated at %s deg (largest "
          "value there %.4f deg)\n",
          f.amplitude, f.travel_lo, f.travel_hi,
          arcs.empty() ? "no angle" : arcs.c_str(), f.extrapolated_peak);
    }
    for (const Equivalent& e : f.equivalent) {
      std::printf("    equivalent on this data: %s %s %.5g %s\n",
                  e.cause.c_str(), FormatJoint(e.joint).c_str(), e.magnitude,
                  e.unit.c_str());
    }
    if (f.cause == "unexplained") {
      std::string deps;
      for (const std::string& d : f.depends_on)
        deps += (deps.empty() ? "" : ", ") + d;
      std::printf(
          "    depends on: %s (smooth correction, k = %d: %.0f %% of the "
          "residual power in cross-validation; held-out %.4f -> %.4f mm)\n",
          deps.empty() ? "nothing smooth" : deps.c_str(), f.smooth_k,
          100.0 * f.cv_explained, f.heldout_rms_before_mm,
          f.heldout_rms_after_mm);
    }
  }
  std::printf("  final held-out RMS %.4f mm (%.3f s)\n", r.final_heldout_rms_mm,
              r.seconds);
  if (!options.validation.empty()) {
    std::printf("  validation series (frame only): %.4f -> %.4f mm\n",
                r.nominal_validation_rms_mm, r.final_validation_rms_mm);
  }
  PrintSeries(r.series);
  if (!args.out.empty()) std::printf("  wrote %s\n", args.out.c_str());
  return 0;
}

struct ClearanceArgs {
  std::string robot, obs, plot, csv, root, tip;
  bool json = false;
  ClearanceOptions options;
};

int RunClearance(const ClearanceArgs& args) {
  const Robot robot = ReadRobot(args.robot, args.root, args.tip);
  Warnings warnings = CommandWarnings();
  const Observations obs =
      ReadCheckedObservations(args.obs, robot, args.robot, &warnings);
  RequireOneSeries(obs, "diagnose clearance");
  const ClearanceResult r = DiagnoseClearance(robot, obs, args.options);
  if (!args.csv.empty()) WriteFileAtomic(args.csv, ClearanceCsv(r));
  if (!args.plot.empty()) WriteFileAtomic(args.plot, ClearanceSvg(r));
  if (args.json) {
    nlohmann::json j = ClearanceJson(r);
    AddWarnings(warnings, &j);
    PrintJson(j);
    return 0;
  }
  std::printf("kincal diagnose clearance: %d poses, RMS %.4f mm, gamma %g\n",
              r.stats.n, r.stats.rms_mm, r.gamma);
  if (!r.sweeps.empty()) {
    const PoseSweep& w = r.sweeps[0];
    std::printf("  worst pose %s: eps %.4f mm\n", w.pose.c_str(), w.error_mm);
    std::printf("  %-6s %12s %12s %10s %5s %8s\n", "joint", "before_mm",
                "min_mm", "at_offset", "wins", "median");
    for (const SweepCurve& c : w.joints) {
      std::printf("  %-6s %12.4f %12.4f %10.3f %5d %8.3f\n",
                  r.joint_names[c.joint].c_str(), c.error_before_mm,
                  c.error_min_mm, c.at_offset, r.wins[c.joint],
                  r.median_ratio[c.joint]);
    }
  }
  std::printf(
      "  suspect: %s (best joint at a majority of the %zu worst poses, "
      "median error ratio <= %.2f)\n",
      r.suspect >= 0 ? r.joint_names[r.suspect].c_str() : "none",
      r.sweeps.size(), args.options.reduction_threshold);
  return 0;
}

struct CompareArgs {
  std::string robot, before, after, root, tip;
  bool json = false;
};

int RunCompare(const CompareArgs& args) {
  const Robot robot = ReadRobot(args.robot, args.root, args.tip);
  Warnings warnings = CommandWarnings();
  const Observations before =
      ReadCheckedObservations(args.before, robot, args.robot, &warnings);
  const Observations after =
      ReadCheckedObservations(args.after, robot, args.robot, &warnings);
  RequireOneSeries(before, "diagnose compare");
  RequireOneSeries(after, "diagnose compare");
  const CompareResult r = CompareClearance(robot, before, after);
  if (args.json) {
    nlohmann::json j = CompareJson(r);
    AddWarnings(warnings, &j);
    PrintJson(j);
    return 0;
  }
  std::printf(
      "kincal diagnose compare: clearance per joint, 95 %% intervals\n");
  std::printf("  %-6s %-4s %24s %24s %8s %s\n", "joint", "unit", "before",
              "after", "z", "changed");
  for (const JointClearanceChange& c : r.joints) {
    char b[64], a[64];
    std::snprintf(b, sizeof(b), "%.4f [%.4f, %.4f]", c.before.value,
                  c.before.ci_low, c.before.ci_high);
    std::snprintf(a, sizeof(a), "%.4f [%.4f, %.4f]", c.after.value,
                  c.after.ci_low, c.after.ci_high);
    std::printf("  %-6s %-4s %24s %24s %8.2f %s\n", c.joint.c_str(),
                c.unit.c_str(), b, a, c.z, c.changed ? "yes" : "no");
  }
  if (r.verdict == "not_determined") {
    std::printf(
        "  verdict: not_determined (no joint's clearance can be determined "
        "in both sessions)\n");
  } else {
    std::printf("  verdict: %s (|z| > %.2f)\n", r.verdict.c_str(),
                r.z_critical);
  }
  std::printf("%s", CompareIso9283Text(r).c_str());
  return 0;
}

}  // namespace

void AddDiagnoseCommand(CLI::App& app, Runner* run) {
  CLI::App* diag = app.add_subcommand(
      "diagnose",
      "Find why the robot model is wrong: model, clearance, compare");
  diag->require_subcommand(1);

  auto margs = std::make_shared<ModelArgs>();
  CLI::App* model = diag->add_subcommand(
      "model",
      "Fit geometry, test the catalogue of causes (backlash, compliance, "
      "cyclic, gain, axis_tilt, drift, elastostatic, thermal, "
      "mount_compliance, transmission, gravity) against held-out poses, report "
      "findings");
  AddRobotOptions(model, &margs->robot, &margs->root, &margs->tip,
                  "robot.yaml or .urdf")
      ->required();
  model->add_option("--obs", margs->obs, "observations.csv")->required();
  model->add_option(
      "--out", margs->out,
      "write the extended model (extensions:) to this robot.yaml");
  model->add_option("--residuals", margs->residuals,
                    "write the final per-pose residual vectors to this CSV");
  model->add_option("--noise", margs->options.noise_mm,
                    "measurement noise per axis, mm (default: estimate)");
  model->add_option("--seed", margs->options.seed, "seed of the held-out split")
      ->capture_default_str();
  model
      ->add_option("--holdout", margs->options.holdout_fraction,
                   "fraction of poses held out")
      ->capture_default_str();
  model
      ->add_option("--false-alarm", margs->options.false_alarm,
                   "family-wise false-alarm probability per selection step")
      ->capture_default_str();
  model
      ->add_option("--max-findings", margs->options.max_findings,
                   "stop after this many findings")
      ->capture_default_str();
  model->add_option("--causes", margs->options.causes,
                    "restrict the catalogue (e.g. --causes backlash gain)");
  model->add_option("--threads", margs->options.num_threads, "threads")
      ->capture_default_str();
  model
      ->add_option("--folds", margs->options.folds,
                   "k-fold cross-validation of the selection on the training "
                   "poses: a candidate must lower the cross-validated RMS, "
                   "the lowest wins (0 or 1 = the single held-out split; "
                   "default: fewer folds when poses are few)")
      ->capture_default_str();
  model->add_option("--validate", margs->validate,
                    "other series of the same robot for cross-series "
                    "validation (observations.csv; repeatable)");
  model->add_flag("--json", margs->json, "print one JSON object");
  model->footer(HelpFooter(
      "Example (the demo session):\n  kincal diagnose model --robot "
      "data/sessions/bh7_demo/robot.yaml --obs "
      "data/sessions/bh7_demo/observations.csv --out extended.yaml --json > "
      "diag.json\n  kincal report --robot data/sessions/bh7_demo/robot.yaml "
      "--obs data/sessions/bh7_demo/observations.csv --calibrated "
      "extended.yaml --diagnosis diag.json --out report.html"));
  model->callback([run, margs, model] {
    margs->options.folds_given = model->get_option("--folds")->count() > 0;
    *run = [margs] { return RunModel(*margs); };
  });

  auto cargs = std::make_shared<ClearanceArgs>();
  CLI::App* clear = diag->add_subcommand(
      "clearance",
      "The seed's Section 4 joint motion error test: sweep each joint at the "
      "worst poses");
  AddRobotOptions(clear, &cargs->robot, &cargs->root, &cargs->tip,
                  "robot.yaml (calibrated) or .urdf")
      ->required();
  clear->add_option("--obs", cargs->obs, "observations.csv")->required();
  clear
      ->add_option("--gamma", cargs->options.gamma,
                   "sweep half-range, deg (revolute) or mm (prismatic)")
      ->capture_default_str();
  clear
      ->add_option("--worst", cargs->options.worst_poses,
                   "worst poses examined (step 3)")
      ->capture_default_str();
  clear->add_flag("--calibrate,!--no-calibrate",
                  cargs->options.calibrate_geometry,
                  "calibrate the geometry on the same data first (default; "
                  "the paper runs the test on its calibrated robot); "
                  "--no-calibrate uses the robot as given");
  clear->add_option("--plot", cargs->plot, "write an SVG of Fig. 4 and Fig. 5");
  clear->add_option("--csv", cargs->csv, "write deviations and curves as CSV");
  clear->add_flag("--json", cargs->json, "print one JSON object");
  clear->footer(
      HelpFooter("Example (seed Section 4, sweep +-3 deg | mm):\n  kincal "
                 "diagnose clearance --robot cal.yaml --obs "
                 "data/sessions/bh7_demo/observations.csv --gamma 3 --plot "
                 "clearance.svg --csv clearance.csv"));
  clear->callback(
      [run, cargs] { *run = [cargs] { return RunClearance(*cargs); }; });

  auto pargs = std::make_shared<CompareArgs>();
  CLI::App* cmp = diag->add_subcommand(
      "compare",
      "Per-joint clearance of two sessions (before / after maintenance)");
  cmp->add_option("before", pargs->before, "observations.csv before")
      ->required();
  cmp->add_option("after", pargs->after, "observations.csv after")->required();
  AddRobotOptions(cmp, &pargs->robot, &pargs->root, &pargs->tip,
                  "robot.yaml or .urdf")
      ->required();
  cmp->add_flag("--json", pargs->json, "print one JSON object");
  cmp->footer(HelpFooter(
      "Example: errors before and after a repair, same poses:\n  kincal "
      "diagnose compare before.csv after.csv --robot cal.yaml --json"));
  cmp->callback(
      [run, pargs] { *run = [pargs] { return RunCompare(*pargs); }; });
}

}  // namespace kincal::app
