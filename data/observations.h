#ifndef KINCAL_DATA_OBSERVATIONS_H_
#define KINCAL_DATA_OBSERVATIONS_H_

#include <Eigen/Core>
#include <limits>
#include <string>
#include <vector>

namespace kincal {

// One row of observations.csv: a robot pose, in the order the robot visited
// them. Joint readings are in reading units (mm for prismatic, deg for
// revolute), in the robot's joint order (not the file's column order).
struct Observation {
  std::string pose;
  std::vector<double> q;
  bool has_point = false;
  Eigen::Vector3d p_in_meas = Eigen::Vector3d::Zero();    // mm
  std::string fixed_point;                                // "" = none
  double t_s = std::numeric_limits<double>::quiet_NaN();  // NaN = unknown
  // Temperature at the measurement (spec v2 column temp_c), deg C; NaN =
  // unknown.
  double temp_c = std::numeric_limits<double>::quiet_NaN();
  int line = 0;  // line in the source file (1-based), for messages

  bool HasTime() const { return t_s == t_s; }
  bool HasTemp() const { return temp_c == temp_c; }
};

struct Observations {
  std::string source;                    // file the rows came from
  std::vector<std::string> joint_names;  // robot joint order
  std::vector<Observation> rows;         // visit order

  int CountWithPoints() const;
  int CountWithFixedPoint() const;
  bool AnyTime() const;
  bool AnyTemp() const;
};

// Reads observations.csv (../shared/spec/formats.md) for a robot with the
// given joint names. Strict: any invalid cell, column or row throws
// InputError with file:line:column. Accepts a UTF-8 BOM and CRLF line ends.
Observations ReadObservationsCsv(const std::string& path,
                                 const std::vector<std::string>& joint_names);
Observations ParseObservationsCsv(const std::string& text,
                                  const std::string& file_label,
                                  const std::vector<std::string>& joint_names);

// Writes the rows as observations.csv; `comment` lines become "# ..." lines
// after the provenance line. Columns x,y,z / fixed_point / t / temp_c appear
// when any row has them.
std::string FormatObservationsCsv(const Observations& obs,
                                  const std::vector<std::string>& comment = {});

// The subset of rows at the given indices (order kept).
Observations Subset(const Observations& obs, const std::vector<int>& indices);

}  // namespace kincal

#endif  // KINCAL_DATA_OBSERVATIONS_H_
