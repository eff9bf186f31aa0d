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
//   measurement_rx/ry/rz      T-Mac orientation, deg (kept, not used)
//   measurement_std_x/y/z     tracker standard deviation, mm (B, C only)
//   measurement_temperature   environment temperature, deg C
//   Goal x/y/z                commanded T-Mac position in the robot base, m
//
// The measured point is the T-Mac (tracker target), which the data set's
// Trafo_TM_F_init.txt places 109 mm along the flange z axis: the tool row of
// data/robots/ur10.yaml.

#include <Eigen/Core>
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
  std::vector<Eigen::Vector3d> goal_mm;       // Goal x/y/z, converted to mm
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

// "2,02011E+13" / "0,365141" / "-1.5" -> double; false when not a finite
// number. A decimal comma is accepted; a single trailing '.' after a value
// that already has a decimal comma (the last line of Series_A ends with one)
// is ignored.
bool ParseDecimalComma(const std::string& text, double* value);

}  // namespace kincal

#endif  // KINCAL_DATA_IMPORT_IPA_H_
