#include "data/observations.h"

#include <cmath>
#include <map>
#include <set>
#include <sstream>

#include "data/atomic_file.h"
#include "data/csv.h"
#include "data/error.h"
#include "data/provenance.h"
#include "data/yaml_util.h"

namespace kincal {

int Observations::CountWithPoints() const {
  int n = 0;
  for (const auto& r : rows) n += r.has_point ? 1 : 0;
  return n;
}

int Observations::CountWithFixedPoint() const {
  int n = 0;
  for (const auto& r : rows) n += r.fixed_point.empty() ? 0 : 1;
  return n;
}

bool Observations::AnyTime() const {
  for (const auto& r : rows) {
    if (r.HasTime()) return true;
  }
  return false;
}

bool Observations::AnyTemp() const {
  for (const auto& r : rows) {
    if (r.HasTemp()) return true;
  }
  return false;
}

bool Observations::AnySeriesLabel() const {
  for (const auto& r : rows) {
    if (!r.series.empty()) return true;
  }
  return false;
}

std::vector<std::string> Observations::SeriesNames() const {
  std::vector<std::string> names;
  std::set<std::string> seen;
  for (const auto& r : rows) {
    if (seen.insert(r.series).second) names.push_back(r.series);
  }
  return names;
}

std::vector<int> Observations::SeriesRows(const std::string& name) const {
  std::vector<int> out;
  for (size_t i = 0; i < rows.size(); ++i) {
    if (rows[i].series == name) out.push_back(static_cast<int>(i));
  }
  return out;
}

void RequireOneSeries(const Observations& obs, const std::string& command) {
  const std::vector<std::string> names = obs.SeriesNames();
  if (names.size() < 2) return;
  std::string list;
  for (const auto& n : names) {
    list += (list.empty() ? "'" : ", '") + n + "' (" +
            std::to_string(obs.SeriesRows(n).size()) + " rows)";
  }
  const Observation& first_other = obs.rows.at(obs.SeriesRows(names[1]).at(0));
  throw InputError(
      obs.source, first_other.line, 0,
      "the rows belong to " + std::to_string(names.size()) +
          " series (column 'series': " + list + "), each with its own " +
          "measuring frame; `kincal " + command +
          "` fits one frame and needs the rows of one series per run (e.g. "
          "keep one series' rows), while `kincal evaluate` registers one "
          "frame per series and `kincal calibrate` and `kincal diagnose "
          "model` fit one frame per series with the robot shared");
}

namespace {
std::string JoinNames(const std::vector<std::string>& names) {
  std::string s;
  for (const auto& n : names) s += (s.empty() ? "" : ", ") + n;
  return s;
}

// What a column of observations.csv holds.
enum Role { kPose, kJoint, kX, kY, kZ, kFixed, kTime, kTemp, kSeries };
struct Column {
  Role role;
  int joint = -1;
  std::string name;
};

// The role of one header cell; InputError for an unknown column.
Column HeaderColumn(const CsvField& f, const CsvLine& header,
                    const std::string& file,
                    const std::vector<std::string>& joint_names) {
  const std::string& name = f.text;
  Column c;
  c.name = name;
  if (name == "pose") {
    c.role = kPose;
  } else if (name == "x") {
    c.role = kX;
  } else if (name == "y") {
    c.role = kY;
  } else if (name == "z") {
    c.role = kZ;
  } else if (name == "fixed_point") {
    c.role = kFixed;
  } else if (name == "t") {
    c.role = kTime;
  } else if (name == "temp_c") {
    c.role = kTemp;
  } else if (name == "series") {
    c.role = kSeries;
  } else {
    c.role = kJoint;
    for (size_t j = 0; j < joint_names.size(); ++j) {
      if (joint_names[j] == name) c.joint = static_cast<int>(j);
    }
    if (c.joint < 0) {
      throw InputError(file, header.line, f.column,
                       "unknown column '" + name +
                           "': expected pose, the robot's joints (" +
                           JoinNames(joint_names) +
                           "), x, y, z, fixed_point, t, temp_c or series");
    }
  }
  return c;
}

// The header: each column's role, checked for a pose column, every joint,
// and all or none of x, y, z.
std::vector<Column> ParseHeader(const CsvLine& header, const std::string& file,
                                const std::vector<std::string>& joint_names) {
  std::vector<Column> columns;
  std::set<std::string> seen;
  for (const CsvField& f : header.fields) {
    const std::string& name = f.text;
    if (name.empty()) {
      throw InputError(file, header.line, f.column,
                       "empty column name in header");
    }
    if (!seen.insert(name).second) {
      throw InputError(file, header.line, f.column,
                       "duplicate column '" + name + "'");
    }
    columns.push_back(HeaderColumn(f, header, file, joint_names));
  }
  if (!seen.count("pose")) {
    throw InputError(file, header.line, 1, "header has no 'pose' column");
  }
  for (const auto& j : joint_names) {
    if (!seen.count(j)) {
      throw InputError(file, header.line, header.end_column,
                       "header has no column for joint '" + j + "'");
    }
  }
  const int xyz_count =
      static_cast<int>(seen.count("x") + seen.count("y") + seen.count("z"));
  if (xyz_count != 0 && xyz_count != 3) {
    throw InputError(file, header.line, header.end_column,
                     "header has only some of x, y, z: give all three or none");
  }
  return columns;
}

// The rows of observations.csv, one at a time (pose ids unique across them).
class RowParser {
 public:
  RowParser(const std::string& file, const std::vector<Column>& columns,
            size_t joints)
      : file_(file), columns_(columns), joints_(joints) {}

  Observation Parse(const CsvLine& line) {
    if (line.fields.size() != columns_.size()) {
      throw InputError(file_, line.line,
                       line.fields.size() > columns_.size()
                           ? line.fields[columns_.size()].column
                           : line.end_column,
                       "expected " + std::to_string(columns_.size()) +
                           " columns as in the header, got " +
                           std::to_string(line.fields.size()));
    }
    Observation o;
    o.line = line.line;
    o.q.assign(joints_, 0.0);
    xyz_given_ = 0;
    first_xyz_column_ = 0;
    for (size_t c = 0; c < columns_.size(); ++c) {
      Cell(line, line.fields[c], columns_[c], &o);
    }
    if (xyz_given_ != 0 && xyz_given_ != 3) {
      throw InputError(file_, line.line, first_xyz_column_,
                       "x, y, z: give all three or leave all three empty");
    }
    o.has_point = xyz_given_ == 3;
    return o;
  }

 private:
  void Cell(const CsvLine& line, const CsvField& f, const Column& col,
            Observation* o) {
    double v = 0.0;
    switch (col.role) {
      case kPose:
        if (f.text.empty()) {
          throw InputError(file_, line.line, f.column, "empty pose id");
        }
        if (!pose_ids_.insert(f.text).second) {
          throw InputError(file_, line.line, f.column,
                           "duplicate pose id '" + f.text + "'");
        }
        o->pose = f.text;
        break;
      case kJoint:
        if (!ParseFiniteDouble(f.text, &v)) {
          throw InputError(file_, line.line, f.column,
                           "column '" + col.name +
                               "': expected a finite number (joint reading), "
                               "got '" +
                               f.text + "'");
        }
        // Physical range: deg (revolute, a few turns) or mm (prismatic).
        if (!(std::abs(v) <= 1e5)) {
          throw InputError(file_, line.line, f.column,
                           "column '" + col.name +
                               "': joint reading out of range (|q| <= "
                               "1e5 deg or mm), got '" +
                               f.text + "'");
        }
        o->q[col.joint] = v;
        break;
      case kX:
      case kY:
      case kZ:
        PointCell(line, f, col, o);
        break;
      case kFixed:
        o->fixed_point = f.text;
        break;
      case kTime:
        if (f.text.empty()) break;
        if (!ParseFiniteDouble(f.text, &v)) {
          throw InputError(file_, line.line, f.column,
                           "column 't': expected a finite number (s) or "
                           "empty, got '" +
                               f.text + "'");
        }
        o->t_s = v;
        break;
      case kTemp:
        if (f.text.empty()) break;
        if (!ParseFiniteDouble(f.text, &v) || v < -273.15 || v > 1000.0) {
          throw InputError(file_, line.line, f.column,
                           "column 'temp_c': expected a temperature in deg "
                           "C (-273.15..1000) or empty, got '" +
                               f.text + "'");
        }
        o->temp_c = v;
        break;
      case kSeries:
        o->series = f.text;
        break;
    }
  }

  void PointCell(const CsvLine& line, const CsvField& f, const Column& col,
                 Observation* o) {
    if (f.text.empty()) {
      if (first_xyz_column_ == 0) first_xyz_column_ = f.column;
      return;
    }
    double v = 0.0;
    if (!ParseFiniteDouble(f.text, &v)) {
      throw InputError(file_, line.line, f.column,
                       "column '" + col.name +
                           "': expected a finite number (mm) or empty, "
                           "got '" +
                           f.text + "'");
    }
    if (!(std::abs(v) <= 1e6)) {
      throw InputError(file_, line.line, f.column,
                       "column '" + col.name +
                           "': point out of range (|x| <= 1e6 mm, "
                           "1 km), got '" +
                           f.text + "'");
    }
    o->p_in_meas[col.role - kX] = v;
    ++xyz_given_;
    if (first_xyz_column_ == 0) first_xyz_column_ = f.column;
  }

  const std::string& file_;
  const std::vector<Column>& columns_;
  const size_t joints_;
  std::set<std::string> pose_ids_;
  int xyz_given_ = 0;
  int first_xyz_column_ = 0;
};

}  // namespace

Observations ParseObservationsCsv(const std::string& text,
                                  const std::string& file,
                                  const std::vector<std::string>& joint_names) {
  const std::vector<CsvLine> lines = TokenizeCsv(text, file);
  if (lines.empty()) {
    throw InputError(file, 0, 0,
                     "empty file: expected a header line 'pose," +
                         JoinNames(joint_names) + ",x,y,z' and rows");
  }
  const std::vector<Column> columns = ParseHeader(lines[0], file, joint_names);
  Observations obs;
  obs.source = file;
  obs.joint_names = joint_names;
  RowParser rows(file, columns, joint_names.size());
  for (size_t li = 1; li < lines.size(); ++li) {
    obs.rows.push_back(rows.Parse(lines[li]));
  }
  if (obs.rows.empty()) {
    throw InputError(file, lines[0].line, 0,
                     "no observation rows after the header");
  }
  return obs;
}

Observations ReadObservationsCsv(const std::string& path,
                                 const std::vector<std::string>& joint_names) {
  return ParseObservationsCsv(ReadFile(path), path, joint_names);
}

std::string FormatObservationsCsv(const Observations& obs,
                                  const std::vector<std::string>& comment) {
  bool points = false, fixed = false, time = false, temp = false;
  const bool series = obs.AnySeriesLabel();
  for (const auto& r : obs.rows) {
    points = points || r.has_point;
    fixed = fixed || !r.fixed_point.empty();
    time = time || r.HasTime();
    temp = temp || r.HasTemp();
  }
  std::ostringstream os;
  os << "# written by " << ToolVersion() << ": " << CommandLine() << "\n";
  for (const auto& c : comment) os << "# " << c << "\n";
  os << "pose";
  for (const auto& j : obs.joint_names) os << "," << j;
  if (points) os << ",x,y,z";
  if (fixed) os << ",fixed_point";
  if (time) os << ",t";
  if (temp) os << ",temp_c";
  if (series) os << ",series";
  os << "\n";
  for (const auto& r : obs.rows) {
    os << CsvQuote(r.pose);
    for (double q : r.q) os << "," << FormatDouble(q);
    if (points) {
      if (r.has_point) {
        for (int k = 0; k < 3; ++k) os << "," << FormatDouble(r.p_in_meas[k]);
      } else {
        os << ",,,";
      }
    }
    if (fixed) os << "," << CsvQuote(r.fixed_point);
    if (time) os << "," << (r.HasTime() ? FormatDouble(r.t_s) : "");
    if (temp) os << "," << (r.HasTemp() ? FormatDouble(r.temp_c) : "");
    if (series) os << "," << CsvQuote(r.series);
    os << "\n";
  }
  return os.str();
}

Observations Subset(const Observations& obs, const std::vector<int>& indices) {
  Observations out;
  out.source = obs.source;
  out.joint_names = obs.joint_names;
  for (int i : indices) out.rows.push_back(obs.rows.at(i));
  return out;
}

}  // namespace kincal
