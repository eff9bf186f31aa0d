#ifndef KINCAL_DATA_TARGETS_CSV_H_
#define KINCAL_DATA_TARGETS_CSV_H_

// Targets for `kincal compensate` (../shared/spec/formats.md, version 3):
// `target` and x,y,z [and rx,ry,rz, a rotation vector in deg] in the robot's
// base frame, optional seed joint columns named as in the robot file and an
// optional temp_c; or joint columns only: a program written for the nominal
// kinematics (a `pose` column stands for `target`, so plan's POSES.csv
// reads). Rows in the order the robot visits them.

#include <Eigen/Core>
#include <limits>
#include <string>
#include <vector>

namespace kincal {

struct TargetRow {
  std::string id;
  bool has_position = false;
  Eigen::Vector3d position_mm = Eigen::Vector3d::Zero();
  bool has_rotation = false;
  Eigen::Vector3d rotation_deg = Eigen::Vector3d::Zero();  // rotation vector
  std::vector<double> joints;  // robot order, reading units; empty = none
  double temp_c = std::numeric_limits<double>::quiet_NaN();
  int line = 0;
};

struct TargetsFile {
  std::string source;
  std::vector<TargetRow> rows;
  bool program = false;  // joint columns only
};

// Strict: unknown or duplicate columns, a partial x,y,z or rx,ry,rz set, a
// partial set of joint columns, empty or non-numeric cells and duplicate
// target ids throw InputError with file:line:column.
TargetsFile ParseTargetsCsv(const std::string& text, const std::string& file,
                            const std::vector<std::string>& joint_names);
TargetsFile ReadTargetsCsv(const std::string& path,
                           const std::vector<std::string>& joint_names);

}  // namespace kincal

#endif  // KINCAL_DATA_TARGETS_CSV_H_
