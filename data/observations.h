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
  // Measurement campaign (spec v3 column series): rows of one series share a
  // measuring frame. "" = unlabelled (a file without the column is one
  // series; empty cells in the column form one more).
  std::string series;
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
  // Whether any row carries a non-empty series label.
  bool AnySeriesLabel() const;
  // The distinct series labels in first-seen order ("" included when some
  // row is unlabelled); one entry for a file without the column.
  std::vector<std::string> SeriesNames() const;
  // Indices of the rows of one series, in visit order.
  std::vector<int> SeriesRows(const std::string& name) const;
};

// Throws InputError unless every row belongs to one series: for commands
// that fit one measuring frame to all rows. `command` names the command in
// the message (e.g. "calibrate"); the message names the series and points
// to `kincal evaluate`, which registers one frame per series.
void RequireOneSeries(const Observations& obs, const std::string& command);

// Reads observations.csv (../shared/spec/formats.md) for a robot with the
// given joint names. Strict: any invalid cell, column or row throws
// InputError with file:line:column. Accepts a UTF-8 BOM and CRLF line ends.
Observations ReadObservationsCsv(const std::string& path,
                                 const std::vector<std::string>& joint_names);
Observations ParseObservationsCsv(const std::string& text,
                                  const std::string& file_label,
                                  const std::vector<std::string>& joint_names);

// Writes the rows as observations.csv; `comment` lines become "# ..." lines
// after the provenance line. Columns x,y,z / fixed_point / t / temp_c /
// series appear when any row has them.
std::string FormatObservationsCsv(const Observations& obs,
                                  const std::vector<std::string>& comment = {});

// The subset of rows at the given indices (order kept).
Observations Subset(const Observations& obs, const std::vector<int>& indices);

}  // namespace kincal

#endif  // KINCAL_DATA_OBSERVATIONS_H_
