#ifndef KINCAL_DATA_ROBOT_H_
#define KINCAL_DATA_ROBOT_H_

#include <Eigen/Core>
#include <array>
#include <limits>
#include <map>
#include <string>
#include <utility>
#include <vector>

namespace kincal {

enum class JointType { kRevolute, kPrismatic, kFixed };
enum class Convention { kDh, kMdh, kUrdf };

const char* ToString(JointType type);
const char* ToString(Convention convention);

// One row of the kinematic chain, in interface units (mm, deg). Which fields
// are used depends on Robot::convention (see docs/CONVENTIONS.md):
//   dh:   Rz(theta + q) Tz(d + q) Tx(a) Rx(alpha) Ry(beta)
//   mdh:  Rx(alpha) Ry(beta) Tx(a) Rz(theta + q) Tz(d + q)
//   urdf: T(xyz) Rz(yaw) Ry(pitch) Rx(roll) * joint motion about/along `axis`
struct RobotRow {
  std::string name;  // joint name, or "tool" for the fixed last row
  JointType type = JointType::kRevolute;
  double theta_deg = 0.0;
  double d_mm = 0.0;
  double a_mm = 0.0;
  double alpha_deg = 0.0;
  double beta_deg = 0.0;  // Hayati twist; 0 unless identified (axis_tilt)
  Eigen::Vector3d xyz_mm = Eigen::Vector3d::Zero();
  Eigen::Vector3d rpy_deg = Eigen::Vector3d::Zero();
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();
  // Joint limits in reading units (mm or deg); NaN when the file has none.
  double lower = std::numeric_limits<double>::quiet_NaN();
  double upper = std::numeric_limits<double>::quiet_NaN();
  bool HasLimits() const { return lower == lower && upper == upper; }
  // Inertial data of the link this row's joint moves (the link whose frame
  // the row ends in), for gravity models: robot.yaml `mass` (kg) and `com`
  // (mm, in the frame after this row), or a URDF link's <inertial>.
  // mass_kg is NaN when the file gives none.
  double mass_kg = std::numeric_limits<double>::quiet_NaN();
  Eigen::Vector3d com_mm = Eigen::Vector3d::Zero();
  bool HasMass() const { return mass_kg == mass_kg; }
};

// A model extension identified by the diagnosis (`extensions:` in robot.yaml).
// `values` holds the cause's fields in interface units, e.g.
//   backlash: {width}            deg or mm (full clearance width)
//   compliance: {per_torque}     deg per (mm x unit mass) of gravity torque
//   cyclic: {cos, sin}           deg, first harmonic of the read joint angle,
//           optional {cos2, sin2, cos3, sin3} for the 2nd and 3rd harmonics
//   gain: {g}                    dimensionless, q = (1 + g) q_read
//   drift: {vx, vy, vz}          mm per hour, tip drift in the base frame
//   elastostatic: {per_knm}      deg (mm) per kN m (kN) of the gravity torque
//                                of the link masses about the joint
//   thermal: {rate}              relative growth of the row's lengths per K
//                                of temp_c - 20 (data with temp_c) or per h
//   mount_compliance: {iso}      deg per kN m: base tilt under the arm's
//           optional {aniso_cos, aniso_sin}  gravity moment (no joint)
// axis_tilt is not an extension entry: it is the row's `beta`.
struct Extension {
  std::string cause;
  std::string joint;  // empty for drift
  std::map<std::string, double> values;
};

// What a calibrated model was fitted on and how well it knows its values
// (robot.yaml `fitted_on:` and `covariance:`, written by calibrate, diagnose
// and bundle): compensate flags targets outside the data's travel and
// temperature and predicts each target's error from it.
// Fourier terms of a periodic transmission in a robot file (a1..a32,
// b1..b32).
constexpr int kFourierTerms = 64;

struct FitRecord {
  int poses = 0;  // 0 = no record
  // Per joint (robot order), the readings' range [lo, hi] in the data (reading
  // units); empty = unknown.
  std::vector<std::array<double, 2>> joint_range;
  // Per joint, the widest gap (from, to) between readings inside the travel
  // when it is wide (over 10 % of the travel and 5 deg | mm; NaN = none):
  // a function fitted along the travel is not held there. Empty = unknown.
  std::vector<std::array<double, 2>> joint_gap;
  // temp_c range of the data (NaN = no temperature column).
  double temp_lo_c = std::numeric_limits<double>::quiet_NaN();
  double temp_hi_c = std::numeric_limits<double>::quiet_NaN();
  // Input of the thermal extension: "temp_c" (per K of temp_c - 20) or
  // "hours" (per hour since the first timed row); "" = no thermal term.
  std::string thermal_input;
  // The measuring frame the model was registered in (meas_from_base:
  // rotation vector in deg, translation in mm); has_frame false = unknown.
  bool has_frame = false;
  std::array<double, 6> frame{};
  // With several series (spec v3 column `series`), every series' measuring
  // frame (label, frame as above) in first-seen order; `frame` is the first.
  // Empty for one series.
  std::vector<std::pair<std::string, std::array<double, 6>>> series_frames;
  // Held-out tip RMS of the model (3D, mm) and the part of its residual above
  // the measurement noise (3D RMS, mm; 0 when none is detected); NaN = unknown.
  double heldout_rms_mm = std::numeric_limits<double>::quiet_NaN();
  double systematic_rms_mm = std::numeric_limits<double>::quiet_NaN();
  // Covariance of the fitted robot parameters (names as in
  // docs/CONVENTIONS.md "Parameter names", interface units: mm, deg, the
  // families' units; frame.* is the measuring frame, fixed points are left
  // out). Empty = unknown.
  std::vector<std::string> covariance_params;
  Eigen::MatrixXd covariance;
  // A periodic transmission's coefficients in the covariance are those of the
  // functions the diagnosis fitted (<joint>.transmission1..m, deg): per such
  // joint, the basis B (kFourierTerms rows in the order cos q, sin q,
  // cos 2q, ..., sin 32q; m columns) with the row's Fourier coefficients
  // [a1, b1, a2, ...] = B c. Empty = none.
  std::vector<std::pair<std::string, Eigen::MatrixXd>> periodic_bases;

  bool present() const { return poses > 0; }
};

struct Robot {
  std::string name;
  Convention convention = Convention::kDh;
  Eigen::Vector3d gravity = Eigen::Vector3d(0, 0, -1);  // unit, base frame
  std::vector<RobotRow> joints;                         // chain order
  RobotRow tool;  // fixed last row (type kFixed, name "tool")
  double bound_length_mm = 5.0;
  double bound_angle_deg = 5.0;
  // True when the bounds were stated (robot.yaml `bounds:`, or calibrate's
  // --bound-length / --bound-angle): a hard constraint, the seed's delta.
  // Otherwise they are defaults that calibrate may widen where the data
  // press a parameter against them (CalibrateResult::widened_bounds).
  bool bounds_stated = false;
  std::vector<Extension> extensions;
  // The nominal rows the calibration started from (robot.yaml `nominal:`):
  // the kinematics the controller uses, for `compensate` of joint programs.
  // Empty = not recorded.
  std::vector<RobotRow> nominal_joints;
  RobotRow nominal_tool;
  FitRecord fitted_on;

  bool HasNominal() const { return !nominal_joints.empty(); }
  // This robot with its nominal rows (and no extensions, no record); throws
  // std::logic_error when HasNominal() is false.
  Robot Nominal() const;
  // Records `nominal`'s rows as this robot's nominal (same joints).
  void SetNominal(const Robot& nominal);
  int JointIndex(const std::string& name) const;  // -1 when absent
  std::vector<std::string> JointNames() const;
};

// Reads robot.yaml (format version 1, docs in ../shared/spec/formats.md).
// Throws InputError with file:line:column on any invalid content.
Robot ReadRobotYaml(const std::string& path);
Robot ParseRobotYaml(const std::string& text, const std::string& file_label);

// Serialises a robot as robot.yaml, with a "# <command>" provenance header and
// free `comment` lines (without '#').
std::string FormatRobotYaml(const Robot& robot,
                            const std::vector<std::string>& comment = {});

}  // namespace kincal

#endif  // KINCAL_DATA_ROBOT_H_
