// kincal report: one self-contained HTML file from whatever the user has
// (report/report.h, docs/REPORT.md).

#include <chrono>
#include <cstdio>
#include <memory>
#include <nlohmann/json.hpp>

#include "app/app_util.h"
#include "app/command.h"
#include "data/atomic_file.h"
#include "data/error.h"
#include "data/progress.h"
#include "report/report.h"

namespace kincal::app {
namespace {

struct ReportArgs {
  ReportOptions options;
  std::string out;
  bool json = false;
};

int RunReport(const ReportArgs& args) {
  const auto start = std::chrono::steady_clock::now();
  const ReportOptions& o = args.options;
  Require(!o.robot.empty() || !o.calibrated.empty() || !o.diagnosis.empty() ||
              !o.session.empty() || !o.rig.empty() || !o.bundle.empty(),
          "kincal report: give at least one input (--robot, --calibrated, "
          "--diagnosis, --bundle, --session or --rig)");
  Progress progress("kincal report", args.json);
  const ReportResult r =
      BuildReport(o, [&](const std::string& what) { progress.Stage(what); });
  progress.Done();
  WriteFileAtomic(args.out, r.html);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
          .count();
  if (args.json) {
    nlohmann::json j = {{"out", args.out},        {"sections", r.sections},
                        {"figures", r.figures},   {"notes", r.notes},
                        {"bytes", r.html.size()}, {"seconds", seconds}};
    if (r.tolerance_given) {
      j["tolerance_mm"] = r.tolerance_mm;
      // null when not decided (no held-out figure, or too few poses).
      j["pass"] = r.tolerance_decided ? nlohmann::json(r.pass) : nullptr;
      j["decided"] = r.tolerance_decided;
      if (r.tolerance_available) {
        j["heldout_rms_mm"] = r.heldout_rms_mm;
        j["heldout_ci95_mm"] = {r.heldout_lo_mm, r.heldout_hi_mm};
        j["heldout_n"] = r.heldout_n;
      }
    }
    if (r.has_iso9283) {
      nlohmann::json iso = {{"ap_max_mm", r.iso9283_ap_max_mm},
                            {"rp_max_mm", r.iso9283_rp_max_mm}};
      if (r.tolerance_given) iso["pass"] = r.iso9283_pass;
      j["iso9283"] = iso;
    }
    PrintJson(j);
    return 0;
  }
  std::printf("kincal report: %zu sections, %d figures, %.1f s\n",
              r.sections.size(), r.figures, seconds);
  if (r.tolerance_given) {
    std::printf(
        "  %s: held-out RMS %.4g mm [%.4g, %.4g] (95 %%, %d poses), "
        "tolerance %.4g mm\n",
        !r.tolerance_decided ? "NOT DECIDED"
        : r.pass             ? "PASS"
                             : "FAIL",
        r.heldout_rms_mm, r.heldout_lo_mm, r.heldout_hi_mm, r.heldout_n,
        r.tolerance_mm);
  }
  if (r.has_iso9283) {
    std::printf("  ISO 9283: max AP %.4g mm, max RP %.4g mm%s\n",
                r.iso9283_ap_max_mm, r.iso9283_rp_max_mm,
                !r.tolerance_given ? ""
                : r.iso9283_pass   ? ": PASS"
                                   : ": FAIL");
  }
  for (const auto& n : r.notes) std::printf("  note: %s\n", n.c_str());
  std::printf("%s\n", args.out.c_str());
  return 0;
}

}  // namespace

void AddReportCommand(CLI::App& app, Runner* run) {
  auto args = std::make_shared<ReportArgs>();
  CLI::App* sub = app.add_subcommand(
      "report",
      "Write one self-contained HTML report (no network needed) from any of: "
      "robot, observations, calibrated robot, diagnosis JSON, session, rig. "
      "Sections appear when their inputs are there: verdict, residuals "
      "against joints / time / temperature and in the workspace (before and "
      "after the extensions), the seed's sensitivity and clearance figures, "
      "identifiability, parameters nominal -> calibrated +- sigma, camera "
      "calibration, tracking quality, provenance. Lengths mm, angles deg.");
  ReportOptions& o = args->options;
  sub->add_option("--out", args->out, "HTML file to write (atomically)")
      ->required();
  sub->add_option("--robot", o.robot, "nominal robot.yaml or .urdf");
  sub->add_option("--obs", o.obs,
                  "observations.csv (needs --robot or --calibrated)");
  sub->add_option("--calibrated", o.calibrated,
                  "calibrated robot.yaml, possibly with extensions (e.g. "
                  "diagnose model --out)");
  sub->add_option("--diagnosis", o.diagnosis,
                  "what `kincal diagnose model --json` printed");
  sub->add_option("--session", o.session,
                  "session folder (its points.csv from kincal track) or a "
                  "points.csv");
  sub->add_option("--rig", o.rig,
                  "rig.yaml from camcal (its camcal --json output is read "
                  "from RIG.json beside it when present)");
  sub->add_option("--camcal", o.camcal_json, "camcal --json output");
  sub->add_option("--bundle", o.bundle,
                  "what `kincal bundle --json` printed: the report shows the "
                  "bundle's own held-out tip error, reprojection RMS, sigma "
                  "and parameters instead of calibrating the points again");
  sub->add_option("--tolerance", o.tolerance_mm,
                  "mm: adds a pass/fail line, the final held-out RMS with its "
                  "95 % interval against this, and with --iso9283 every "
                  "pose's AP and RP against it (exit code stays 0)");
  sub->add_option("--iso9283", o.iso9283,
                  "observations.csv of ISO 9283 cycles (fixed_point = "
                  "commanded pose P1..P5, x,y,z attained): adds the ISO 9283 "
                  "section, AP and RP per pose (pass/fail with --tolerance)");
  sub->add_option("--root", o.root, "URDF root link");
  sub->add_option("--tip", o.tip, "URDF tip link");
  sub->add_option("--seed", o.seed,
                  "seed of the held-out split of the calibration run for the "
                  "report")
      ->capture_default_str();
  sub->add_option("--gamma", o.gamma,
                  "clearance sweep half-range, deg | mm (seed Section 4)")
      ->capture_default_str();
  sub->add_option("--max-points", o.max_points,
                  "markers per scatter series at most (thinned evenly)")
      ->capture_default_str();
  sub->add_flag("--json", args->json,
                "print one JSON object (out, sections, seconds)");
  sub->footer(HelpFooter(
      "Example (the demo's session):\n  kincal diagnose model --robot R.yaml "
      "--obs O.csv --out ext.yaml --json > diag.json\n  kincal report --robot "
      "R.yaml --obs O.csv --calibrated ext.yaml --diagnosis diag.json --out "
      "report.html"));
  sub->callback([run, args] { *run = [args] { return RunReport(*args); }; });
}

}  // namespace kincal::app
