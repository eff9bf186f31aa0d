// kincal iso9283: ISO 9283 pose accuracy (AP) and pose repeatability (RP)
// per commanded pose, from observations whose fixed_point labels the
// commanded pose of each measured cycle (diagnose/iso9283.h,
// docs/ISO9283.md).

#include <chrono>
#include <cstdio>
#include <memory>

#include "app/app_util.h"
#include "app/command.h"
#include "data/urdf.h"
#include "diagnose/iso9283.h"

namespace kincal::app {
namespace {

struct Iso9283Args {
  std::string robot, obs, frame_from, root, tip;
  double tolerance_mm = 0.0;
  double rp_tolerance_mm = 0.0;
  bool json = false;
};

// The standard's number of cycles per pose (ISO 9283 6.9).
constexpr int kStandardCycles = 30;

void WarnAboutCycles(const Iso9283Result& r, Warnings* warnings) {
  for (const Iso9283Pose& p : r.poses) {
    if (p.n < kStandardCycles) {
      warnings->Add("iso9283_few_cycles",
                    "pose '" + p.label + "' has " + std::to_string(p.n) +
                        " cycles; ISO 9283 asks for 30 (RP from fewer "
                        "cycles is less certain)");
    }
  }
  if (r.poses.size() != 5) {
    warnings->Add("iso9283_pose_count",
                  std::to_string(r.poses.size()) +
                      " commanded poses; ISO 9283 tests five (P1..P5 in "
                      "the test cube)");
  }
}

int RunIso9283(const Iso9283Args& args) {
  const auto start = std::chrono::steady_clock::now();
  const Robot robot = ReadRobot(args.robot, args.root, args.tip);
  Warnings warnings = CommandWarnings();
  const Observations obs =
      ReadCheckedObservations(args.obs, robot, args.robot, &warnings);
  RequireOneSeries(obs, "iso9283");
  Iso9283Options options;
  if (!args.frame_from.empty()) {
    const Observations frame_obs =
        ReadCheckedObservations(args.frame_from, robot, args.robot, &warnings);
    RequireOneSeries(frame_obs, "iso9283 --frame-from");
    options = RegisterMeasuringFrame(robot, frame_obs, options);
  }
  options.ap_tolerance_mm = args.tolerance_mm;
  options.rp_tolerance_mm =
      args.rp_tolerance_mm > 0 ? args.rp_tolerance_mm : args.tolerance_mm;
  const Iso9283Result r = ComputeIso9283(robot, obs, options);
  WarnAboutCycles(r, &warnings);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
          .count();
  if (args.json) {
    nlohmann::json j = Iso9283Json(r);
    if (r.tolerance_given) {
      j["tolerance_mm"] = Number(options.ap_tolerance_mm);
      j["rp_tolerance_mm"] = Number(options.rp_tolerance_mm);
    }
    if (!args.frame_from.empty()) j["frame_from"] = args.frame_from;
    j["seconds"] = seconds;
    AddWarnings(warnings, &j);
    PrintJson(j);
    return 0;
  }
  std::printf("kincal iso9283: %zu poses, positions only (no orientations)\n",
              r.poses.size());
  if (r.frame_registered_on_poses) {
    std::printf(
        "  measuring frame registered on the tested poses (%d rows, residual "
        "RMS %.4f mm): AP is reduced by the fit, see docs/ISO9283.md\n",
        r.registration_rows, r.registration_rms_mm);
  } else {
    std::printf("  measuring frame from %s (%d rows, residual RMS %.4f mm)\n",
                args.frame_from.c_str(), r.registration_rows,
                r.registration_rms_mm);
  }
  std::printf("%s", Iso9283Text(r).c_str());
  if (r.tolerance_given) {
    std::printf("  tolerance: AP <= %.4g mm, RP <= %.4g mm\n",
                options.ap_tolerance_mm, options.rp_tolerance_mm);
  }
  return 0;
}

}  // namespace

void AddIso9283Command(CLI::App& app, Runner* run) {
  auto args = std::make_shared<Iso9283Args>();
  CLI::App* sub = app.add_subcommand(
      "iso9283",
      "ISO 9283 pose accuracy AP and repeatability RP per commanded pose "
      "(fixed_point = P1..P5, rows in visit order, x,y,z = attained)");
  AddRobotOptions(sub, &args->robot, &args->root, &args->tip,
                  "robot.yaml or .urdf: the model whose tip at the commanded "
                  "joints is the commanded position")
      ->required();
  sub->add_option("--obs", args->obs,
                  "observations.csv: every cycle of every pose, labelled by "
                  "fixed_point, with its measured x,y,z")
      ->required();
  sub->add_option("--frame-from", args->frame_from,
                  "observations.csv of other poses measured in the same "
                  "set-up: register the measuring frame on them instead of "
                  "on the tested poses (AP then not reduced by the fit)");
  sub->add_option("--tolerance", args->tolerance_mm,
                  "mm: pass/fail per pose and overall, AP <= this and RP <= "
                  "this (or --rp-tolerance); exit code stays 0")
      ->check(CLI::Range(0.0, 1e6));
  sub->add_option("--rp-tolerance", args->rp_tolerance_mm,
                  "mm: the RP bound when it differs from --tolerance")
      ->check(CLI::Range(0.0, 1e6));
  sub->add_flag("--json", args->json, "print one JSON object");
  sub->footer(HelpFooter(
      "Example (5 poses x 30 cycles, frame registered on other poses):\n"
      "  kincal iso9283 --robot R.yaml --obs iso_cycles.csv --frame-from "
      "frame.csv --tolerance 0.5 --json"));
  sub->callback([run, args] { *run = [args] { return RunIso9283(*args); }; });
}

}  // namespace kincal::app
