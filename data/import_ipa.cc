#include "data/import_ipa.h"

#include <cmath>
#include <ctime>
#include <limits>
#include <map>

#include "data/atomic_file.h"
#include "data/csv.h"
#include "data/error.h"

namespace kincal {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// YYYYMMDDhhmmss -> seconds since the epoch (UTC); false unless 14 digits.
bool ParseTimestamp(const std::string& text, double* seconds) {
  if (text.size() != 14) return false;
  for (char c : text) {
    if (c < '0' || c > '9') return false;
  }
  auto num = [&](int pos, int len) { return std::stoi(text.substr(pos, len)); };
  std::tm tm{};
  tm.tm_year = num(0, 4) - 1900;
  tm.tm_mon = num(4, 2) - 1;
  tm.tm_mday = num(6, 2);
  tm.tm_hour = num(8, 2);
  tm.tm_min = num(10, 2);
  tm.tm_sec = num(12, 2);
  if (tm.tm_mon < 0 || tm.tm_mon > 11 || tm.tm_mday < 1 || tm.tm_mday > 31 ||
      tm.tm_hour > 23 || tm.tm_min > 59 || tm.tm_sec > 60) {
    return false;
  }
  *seconds = static_cast<double>(timegm(&tm));
  return true;
}

}  // namespace

std::vector<std::string> IpaUr10JointNames() {
  return {"shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint",
          "wrist_1_joint",      "wrist_2_joint",       "wrist_3_joint"};
}

Eigen::Matrix3d IpaRotation(const Eigen::Vector3d& rx_ry_rz_deg) {
  const Eigen::Vector3d r = rx_ry_rz_deg * M_PI / 180.0;
  return (Eigen::AngleAxisd(r.x(), Eigen::Vector3d::UnitX()) *
          Eigen::AngleAxisd(r.y(), Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(r.z(), Eigen::Vector3d::UnitZ()))
      .toRotationMatrix();
}

bool ParseDecimalComma(const std::string& text, double* value) {
  std::string s = text;
  const size_t comma = s.find(',');
  if (comma != std::string::npos) {
    if (s.find(',', comma + 1) != std::string::npos) return false;
    if (s.find('.') == s.size() - 1 && s.size() > comma + 2) s.pop_back();
    if (s.find('.') != std::string::npos) return false;
    s[comma] = '.';
  }
  return ParseFiniteDouble(s, value);
}

IpaSeries ParseIpaSeries(const std::string& text, const std::string& file,
                         const std::vector<std::string>& joint_names) {
  const std::vector<std::string> columns = IpaUr10JointNames();
  if (joint_names.size() != columns.size()) {
    throw InputError(file, 0, 0,
                     "the UR10 data set has 6 joint columns; the robot has " +
                         std::to_string(joint_names.size()) + " joints");
  }
  const std::vector<CsvLine> lines = TokenizeCsv(text, file, ';');
  if (lines.empty()) throw InputError(file, 1, 1, "expected a header line");
  const CsvLine& header = lines[0];
  std::map<std::string, int> index;
  for (size_t i = 0; i < header.fields.size(); ++i) {
    index[header.fields[i].text] = static_cast<int>(i);
  }
  auto require = [&](const std::string& name) {
    auto it = index.find(name);
    if (it == index.end()) {
      throw InputError(file, header.line, 1,
                       "expected a column '" + name +
                           "' (UR10 ipa-robot-accuracy series file)");
    }
    return it->second;
  };
  auto optional = [&](const std::string& name) {
    auto it = index.find(name);
    return it == index.end() ? -1 : it->second;
  };
  std::vector<int> joint_col;
  for (const std::string& c : columns) joint_col.push_back(require(c));
  const int xyz_col[3] = {require("measurement_x"), require("measurement_y"),
                          require("measurement_z")};
  const int std_col[3] = {optional("measurement_std_x"),
                          optional("measurement_std_y"),
                          optional("measurement_std_z")};
  const int rot_col[3] = {optional("measurement_rx"),
                          optional("measurement_ry"),
                          optional("measurement_rz")};
  const int goal_col[3] = {optional("Goal x"), optional("Goal y"),
                           optional("Goal z")};
  const int temp_col = optional("measurement_temperature");
  const int time_col = optional("Timestamp");

  IpaSeries out;
  out.observations.source = file;
  out.observations.joint_names = joint_names;
  std::vector<double> stamps;
  bool all_stamps = time_col >= 0;
  for (size_t li = 1; li < lines.size(); ++li) {
    const CsvLine& line = lines[li];
    if (line.fields.size() != header.fields.size()) {
      throw InputError(file, line.line, line.end_column,
                       "expected " + std::to_string(header.fields.size()) +
                           " ';'-separated fields, found " +
                           std::to_string(line.fields.size()));
    }
    auto number = [&](int col, const char* what) {
      const CsvField& f = line.fields[col];
      double v = 0.0;
      if (!ParseDecimalComma(f.text, &v)) {
        throw InputError(file, line.line, f.column,
                         std::string("expected a number (") + what +
                             "), found '" + f.text + "'");
      }
      return v;
    };
    auto side = [&](int col, const char* what, double scale) {
      return col < 0 ? kNaN : number(col, what) * scale;
    };
    Observation row;
    row.pose = std::to_string(li - 1);
    row.line = line.line;
    for (int j = 0; j < 6; ++j) {
      row.q.push_back(number(joint_col[j], "joint angle, rad") * 180.0 / M_PI);
    }
    row.has_point = true;
    for (int k = 0; k < 3; ++k) {
      row.p_in_meas[k] = number(xyz_col[k], "tracker position, mm");
    }
    if (all_stamps) {
      double s = 0.0;
      if (ParseTimestamp(line.fields[time_col].text, &s)) {
        stamps.push_back(s);
      } else {
        all_stamps = false;
      }
    }
    out.temperature_c.push_back(side(temp_col, "temperature", 1.0));
    row.temp_c = out.temperature_c.back();  // spec v2 column temp_c
    Eigen::Vector3d sd, rot, goal;
    for (int k = 0; k < 3; ++k) {
      sd[k] = side(std_col[k], "tracker std, mm", 1.0);
      rot[k] = side(rot_col[k], "tracker angle, deg", 1.0);
      goal[k] = side(goal_col[k], "goal position, m", 1000.0);
    }
    out.std_mm.push_back(sd);
    out.rotation_deg.push_back(rot);
    out.goal_mm.push_back(goal);
    out.observations.rows.push_back(row);
  }
  if (out.observations.rows.empty()) {
    throw InputError(file, header.line + 1, 1,
                     "expected at least one data row");
  }
  out.has_time = all_stamps;
  if (all_stamps) {
    for (size_t i = 0; i < stamps.size(); ++i) {
      out.observations.rows[i].t_s = stamps[i] - stamps[0];
    }
  }
  return out;
}

IpaSeries ReadIpaSeries(const std::string& path,
                        const std::vector<std::string>& joint_names) {
  return ParseIpaSeries(ReadFile(path), path, joint_names);
}

}  // namespace kincal
