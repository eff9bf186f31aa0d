#ifndef KINCAL_REPORT_ANALYSIS_H_
#define KINCAL_REPORT_ANALYSIS_H_

// The report's first two steps (report/report.h): read every input (bad
// input fails before any computation), then compute what the page shows
// (calibration, residuals, structure, clearance, sensitivity). The page is
// written from these two structs only (report/verdict.h, the *_sections.h).

#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "calib/calibrate.h"
#include "calib/sensitivity.h"
#include "camcal/rig.h"
#include "data/observations.h"
#include "data/robot.h"
#include "diagnose/clearance.h"
#include "diagnose/iso9283.h"
#include "report/report.h"
#include "report/residuals.h"

namespace kincal {

// What `kincal bundle` wrote into a calibrated robot's header
// ("# calibrated by kincal bundle ...", "# reprojection RMS ...").
struct BundleHeader {
  bool found = false;
  std::string reprojection;  // the header's reprojection line, or empty
};

struct ReportInputs {
  bool has_robot = false, has_cal = false, has_obs = false;
  bool has_diag = false, has_rig = false, has_bundle = false;
  Robot robot, cal;  // nominal; calibrated (possibly with extensions)
  Observations obs;
  bool has_iso9283 = false;
  Observations iso9283_obs;  // --iso9283
  nlohmann::json diag;       // diagnose model --json
  nlohmann::json bundle;     // bundle --json
  BundleHeader cal_header;
  Rig rig;
  nlohmann::json camcal;  // camcal --json (null when not given)
  std::string camcal_path, points_path;

  // The robot that names the joints (nominal, else the calibrated one).
  const Robot& JointRobot() const { return has_robot ? robot : cal; }
  int JointCount() const {
    return has_robot || has_cal ? static_cast<int>(JointRobot().joints.size())
                                : 0;
  }
};

// Reads every input of `options`. InputError (file:line:column) on bad ones.
ReportInputs ReadReportInputs(const ReportOptions& options);

// Reads a calibrated robot file's `kincal bundle` header lines.
BundleHeader ReadBundleHeader(const std::string& robot_path);

// The pair of joints whose 5 x 5 equal-count grid explains most of the
// variance of the geometric model's 3D error vectors (report/residuals.h).
struct StructureShare {
  int a = -1, b = -1;  // joint indices; -1 = not computed
  double pair = 0.0, a_alone = 0.0, b_alone = 0.0;
  double with_extensions = -1.0;  // the same pair, extended model (-1: none)
  int poses = 0;
};

// Chance level of a bins x bins grid's share for `poses` structure-free
// poses: (bins^2 - 1) / n.
double ChanceShare(int poses, int bins = 5);

struct ReportAnalysis {
  Robot nominal;    // start values of the calibration here
  Robot geometric;  // the geometric model the residuals are of
  bool has_calres = false;
  CalibrateResult calres;
  bool has_nominal = false, has_geo = false, has_ext = false;
  ResidualSet res_nominal, res_geo, res_ext;
  StructureShare structure;
  bool has_clear = false;
  ClearanceResult clear;
  // The seed's Section 3: fixed-point data (eps curves) or measured points.
  bool has_fixed_sensitivity = false;
  SensitivityResult sensitivity;
  std::vector<MeasuredCurve> measured_sensitivity;
  // ISO 9283 figures of --iso9283, and the robot file they used.
  bool has_iso9283 = false;
  Iso9283Result iso9283;
  std::string iso9283_robot;
  std::vector<std::string> notes;  // computations skipped and why
};

// Everything the page needs, computed before any section is written.
// `progress` (may be empty) is told what is being computed.
ReportAnalysis AnalyseReport(
    const ReportInputs& in, const ReportOptions& options,
    const std::function<void(const std::string&)>& progress = {});

}  // namespace kincal

#endif  // KINCAL_REPORT_ANALYSIS_H_
