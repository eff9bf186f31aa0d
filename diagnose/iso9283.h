#ifndef KINCAL_DIAGNOSE_ISO9283_H_
#define KINCAL_DIAGNOSE_ISO9283_H_

// ISO 9283 pose accuracy and pose repeatability (positions only), from
// observations in visit order whose `fixed_point` is the label of the
// commanded pose (P1..P5) and whose x,y,z is the attained position measured
// in the instrument's frame (docs/ISO9283.md).
//
// For pose j with n cycles, in the robot base frame:
//   commanded   c = the robot model's tip at the row's joint readings (the
//                   mean over its rows when the readings differ)
//   barycentre  x̄ = (1/n) sum_i x_i   (same for y, z)
//   AP_x = x̄ - x_c, AP_y = ȳ - y_c, AP_z = z̄ - z_c
//   AP_P = sqrt(AP_x^2 + AP_y^2 + AP_z^2)
//   l_i  = sqrt((x_i - x̄)^2 + (y_i - ȳ)^2 + (z_i - z̄)^2)
//   l̄    = (1/n) sum_i l_i
//   S_l  = sqrt(sum_i (l_i - l̄)^2 / (n - 1))
//   RP_l = l̄ + 3 S_l
// Orientation accuracy and repeatability (AP_a, RP_a, ...) need measured
// orientations, which observations.csv does not carry: not computed.
//
// The measured points are in the instrument's frame. meas_from_base is the
// rigid (Umeyama, no scale) least-squares fit of the model's tips to the
// measured points of the labelled rows (calib/fit.h
// InitializeFrameAndPoints), unless given (Iso9283Options::meas_from_base,
// e.g. registered on other data by RegisterMeasuringFrame). Registered on
// the same poses, the fit takes up the part of the AP vectors that a rigid
// motion of the five commanded positions explains (6 of their 15
// coordinates): AP is then a lower bound of the AP against an independent
// frame. RP does not depend on the frame (distances within one pose).

#include <Eigen/Core>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "data/observations.h"
#include "data/rigid3.h"
#include "data/robot.h"

namespace kincal {

struct Iso9283Options {
  // When set, the measuring frame to use as is (the AP is then not reduced
  // by a registration on the tested poses). Default: registered on the
  // labelled rows themselves.
  std::optional<Rigid3> meas_from_base;
  // Residual RMS of that frame's registration (mm) and the rows it was
  // registered on, reported as given (RegisterMeasuringFrame fills them).
  double given_frame_rms_mm = 0.0;
  int given_frame_rows = 0;
  // > 0: pass/fail per pose, AP_P <= ap_tolerance_mm and RP_l <=
  // rp_tolerance_mm (a bound that is 0 is not checked).
  double ap_tolerance_mm = 0.0;
  double rp_tolerance_mm = 0.0;
};

// The characteristics of one commanded pose.
struct Iso9283Pose {
  std::string label;
  int n = 0;                     // cycles (labelled rows)
  std::vector<int> rows;         // their indices in the observations
  Eigen::Vector3d commanded_mm;  // base frame
  // Largest distance of one row's model tip from `commanded_mm` (0 when
  // every cycle has the same joint readings).
  double commanded_spread_mm = 0.0;
  Eigen::Vector3d barycentre_mm;  // base frame
  Eigen::Vector3d ap_xyz_mm;      // AP_x, AP_y, AP_z
  double ap_mm = 0.0;             // AP_P
  double l_mean_mm = 0.0;         // l̄
  double s_l_mm = 0.0;            // S_l
  double rp_mm = 0.0;             // RP_l
  bool pass = true;               // against the tolerances (true when none)
};

// AP and RP of one pose from its commanded position and attained positions,
// both in the same frame (n >= 2; n == 1 gives S_l = 0). Label, rows and
// the commanded spread are left to the caller.
Iso9283Pose PoseCharacteristics(const Eigen::Vector3d& commanded_mm,
                                const std::vector<Eigen::Vector3d>& attained);

struct Iso9283Result {
  std::vector<Iso9283Pose> poses;  // in order of first visit
  double ap_max_mm = 0.0, rp_max_mm = 0.0;
  Rigid3 meas_from_base;
  // True when the frame was registered on the tested rows (AP reduced by
  // the fit), false when given.
  bool frame_registered_on_poses = true;
  // RMS over the registration rows of |meas_from_base * tip - measured|, mm,
  // and how many rows it was registered on.
  double registration_rms_mm = 0.0;
  int registration_rows = 0;
  int unlabelled_rows = 0;  // rows without a label (approach moves only)
  bool tolerance_given = false;
  bool pass = true;  // every pose passes (true when no tolerance)
};

// Throws InputError (file:line) when no row has a fixed_point label, when a
// labelled row has no x,y,z, when a label has fewer than 2 rows, or when the
// frame cannot be registered (fewer than 3 poses, or all on one line).
Iso9283Result ComputeIso9283(const Robot& robot, const Observations& obs,
                             const Iso9283Options& options = {});

// The measuring frame registered on other observations of the same
// instrument set-up (frame and fixed points only, robot held fixed; the
// fit of kincal evaluate): for --frame-from. Its residual RMS and rows are
// put into the options' given_frame_* fields.
Iso9283Options RegisterMeasuringFrame(const Robot& robot,
                                      const Observations& obs,
                                      Iso9283Options options = {});

// The result as JSON (docs/ISO9283.md, formats.md "Commands added in
// version 3"): `poses` (per label: pose, n, ap_mm, rp_mm, ap_x_mm, ap_y_mm,
// ap_z_mm, barycentre_mm, commanded_mm, commanded_spread_mm, l_mean_mm,
// s_l_mm, and pass with a tolerance), ap_max_mm, rp_max_mm, frame,
// registration_rms_mm, registration_rows, unlabelled_rows, orientation, and
// pass with a tolerance.
nlohmann::json Iso9283Json(const Iso9283Result& result);

// The per-pose table in words (one header line, one line per pose, the
// maxima), each line starting with `indent`.
std::string Iso9283Text(const Iso9283Result& result,
                        const std::string& indent = "  ");

// True when any row has a fixed_point label and x,y,z (data an ISO 9283
// evaluation can read).
bool HasIso9283Rows(const Observations& obs);

}  // namespace kincal

#endif  // KINCAL_DIAGNOSE_ISO9283_H_
