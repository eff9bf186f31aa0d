#ifndef KINCAL_DATA_IMPORT_IPA_H_
#define KINCAL_DATA_IMPORT_IPA_H_

// Importer for the UR10 laser-tracker data set `ipa-robot-accuracy`
// (Landgraf et al., CASE 2021;
// github.com/christianlandgraf/ipa-robot-accuracy).
//
// Each series file (Series_A/measurements_grid.csv,
// Series_B/measurements_joint_configurations.csv,
// Series_C/measurements_random_poses.csv) is ';' separated with decimal
// commas and one header line. Columns used (found by header name, any order):
//   Timestamp                 YYYYMMDDhhmmss (series A); series B and C hold it
//                             truncated to 6 digits ("2,02011E+13"), useless
//   shoulder_pan_joint ... wrist_3_joint   joint angles, rad
//   measurement_x/y/z         Leica T-Mac position in the tracker frame, mm
//   measurement_rx/ry/rz      T-Mac orientation, deg (kept, not used by the
//                             point calibration): tracker_from_tmac =
//                             Rx(rx) Ry(ry) Rz(rz) (IpaRotation)
//   measurement_std_x/y/z     tracker standard deviation, mm (B, C only)
//   measurement_temperature   environment temperature, deg C -> temp_c of
//                             every observation row (spec v2 column)
//   Goal x/y/z                commanded TCP (109 mm out of the flange) in
//                             the ROS base frame, m
//
// The measured point is the origin of the T-Mac frame, 93.0 mm along the
// flange z axis (the tool row of data/robots/ur10.yaml). The data set's
// Trafo_TM_F_init.txt says 109 mm: that is the TCP the planner commanded
// (the Goal columns match the nominal chain with a 109 mm tool within
// 1 mm), not the measured point; the tracker's own orientations place the
// measured point 92.8 (series C) / 93.0 mm (series B) from the flange
// (calib/real_data_test.cc, docs/REAL_DATA.md).

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "data/observations.h"

namespace kincal {

// Joint names of the data set's columns, in UR10 chain order; also the joint
// names of data/robots/ur10.yaml.
std::vector<std::string> IpaUr10JointNames();

struct IpaSeries {
  // Joint readings in degrees (robot order), x,y,z in mm (tracker frame),
  // t_s in seconds since the first row when the file has full timestamps
  // (series A), NaN otherwise. Pose ids are the 0-based row numbers.
  Observations observations;
  // Side columns, one entry per row of `observations` (NaN where absent):
  std::vector<double> temperature_c;          // measurement_temperature
  std::vector<Eigen::Vector3d> std_mm;        // measurement_std_x/y/z
  std::vector<Eigen::Vector3d> rotation_deg;  // measurement_rx/ry/rz
  // Goal x/y/z, converted to mm: the commanded TCP, kept for the checks
  // that need it (calib/real_data_test.cc compares it with the nominal
  // chain's tip). `kincal import ipa-ur10` writes observations.csv, which
  // has no column for it; the ISO 9283 figures (diagnose/iso9283.h) take
  // the commanded position as the model's tip at the joint readings
  // instead. A repeated goal is no ISO 9283 cycle here: series A repeats
  // each grid goal (up to 23 times, consecutively) with other TCP
  // orientations, and the measured point (93 mm out of the flange) is not
  // the commanded TCP (109 mm), so its positions differ by millimetres.
  std::vector<Eigen::Vector3d> goal_mm;
  bool has_time = false;  // true when Timestamp had full resolution
};

// Reads one series file. `joint_names` are the robot's joint names that the
// six joint columns (in the data set's chain order) map to. Throws InputError
// with file:line:column on a missing column, a wrong field count or a cell
// that is not a number (decimal comma or point accepted).
IpaSeries ReadIpaSeries(
    const std::string& path,
    const std::vector<std::string>& joint_names = IpaUr10JointNames());
IpaSeries ParseIpaSeries(
    const std::string& text, const std::string& file_label,
    const std::vector<std::string>& joint_names = IpaUr10JointNames());

// The T-Mac orientation of one row (measurement_rx/ry/rz, deg) as
// tracker_from_tmac = Rx(rx) Ry(ry) Rz(rz) (intrinsic x-y-z). Checked on
// series C against the nominal chain: relative rotations between successive
// poses agree within 0.06 deg RMS; the extrinsic order Rz Ry Rx is off by
// 2.6 deg.
Eigen::Matrix3d IpaRotation(const Eigen::Vector3d& rx_ry_rz_deg);

// "2,02011E+13" / "0,365141" / "-1.5" -> double; false when not a finite
// number. A decimal comma is accepted; a single trailing '.' after a value
// that already has a decimal comma (the last line of Series_A ends with one)
// is ignored.
bool ParseDecimalComma(const std::string& text, double* value);

}  // namespace kincal

#endif  // KINCAL_DATA_IMPORT_IPA_H_
