#ifndef KINCAL_REPORT_REPORT_H_
#define KINCAL_REPORT_REPORT_H_

// `kincal report`: one self-contained HTML file from whatever the user has
// (../shared/spec/formats.md v2, docs/REPORT.md). Every section appears only
// when its inputs are there:
//
//   verdict          words first: the diagnosis' findings, held-out errors,
//                    the residual structure found here
//   diagnosis        the findings table (DIAG.json from diagnose model)
//   residuals        |residual| of the geometric model against each joint,
//                    time and temperature, before / after the extensions
//   structure        |residual| over the two joints it depends on most
//   workspace        residual vectors at the tip positions (top and side)
//   sensitivity      the seed's Section 3 curves (Fig. 2/3)
//   clearance        the seed's Section 4 sweeps (Fig. 4-6)
//   identifiability  identifiable / redundant parameters, relations, sigma
//   parameters       nominal -> calibrated +- sigma
//   iso9283          ISO 9283 AP and RP per commanded pose (--iso9283)
//   camera           rig intrinsics; per-view error and sigma (camcal JSON)
//   tracking         tip quality per frame (points.csv of a session)
//   provenance       the command and version that made every input
//
// Residuals and parameters are computed here through the calib library
// (Calibrate, Evaluate: the same defaults as `kincal calibrate`), unless a
// bundle result is given (its own parameters and held-out figures).
//
// The steps: read the inputs (report/analysis.h ReadReportInputs), compute
// (AnalyseReport), write the verdict (report/verdict.h), one function per
// section (report/robot_sections.h, report/camera_sections.h), provenance.

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace kincal {

struct ReportOptions {
  std::string robot, obs, calibrated, diagnosis, session, rig, camcal_json;
  std::string bundle;  // what `kincal bundle --json` printed (its own figures)
  std::string root, tip;  // URDF chain ends, when a robot is a .urdf
  uint64_t seed = 1;      // held-out split of the calibration run here
  double gamma = 3.0;     // clearance sweep half-range (deg | mm)
  // Markers per scatter series at most (evenly thinned above; said so).
  int max_points = 2000;
  // > 0: a pass/fail line, the final held-out RMS against this (mm); with
  // iso9283, also pass/fail of every pose's AP and RP against it.
  double tolerance_mm = 0.0;
  // Observations of ISO 9283 cycles (fixed_point = commanded pose label):
  // the ISO 9283 section. Needs --robot or --calibrated (the model whose tip
  // at the commanded joints is the commanded position; the nominal robot
  // when both are given).
  std::string iso9283;
};

struct ReportResult {
  std::string html;
  std::vector<std::string> sections;  // ids, in page order
  int figures = 0;
  std::vector<std::string> notes;  // sections skipped and why
  // --tolerance: whether given, whether a held-out figure was there, and
  // the check (report/verdict.h ToleranceCheck).
  bool tolerance_given = false, tolerance_available = false;
  bool tolerance_decided = false, pass = false;
  double tolerance_mm = 0.0, heldout_rms_mm = 0.0;
  double heldout_lo_mm = 0.0, heldout_hi_mm = 0.0;
  int heldout_n = 0;
  // --iso9283: the largest AP and RP (mm), and with --tolerance whether
  // every pose passed.
  bool has_iso9283 = false;
  double iso9283_ap_max_mm = 0.0, iso9283_rp_max_mm = 0.0;
  bool iso9283_pass = true;
};

// Reads the inputs (InputError with file:line:column on bad ones) and builds
// the page. `progress` (may be empty) is told what is being computed.
ReportResult BuildReport(
    const ReportOptions& options,
    const std::function<void(const std::string&)>& progress = {});

}  // namespace kincal

#endif  // KINCAL_REPORT_REPORT_H_
