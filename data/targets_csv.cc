#include "data/targets_csv.h"

#include <map>
#include <set>

#include "data/atomic_file.h"
#include "data/csv.h"
#include "data/error.h"

namespace kincal {
namespace {

// Column index of every header name; -1 when absent.
struct Columns {
  int target = -1, temp = -1;
  int xyz[3] = {-1, -1, -1};
  int rot[3] = {-1, -1, -1};
  std::vector<int> joints;
};

// The columns of a group (x,y,z / rx,ry,rz / joints): all present or none.
bool AllOrNone(const std::vector<int>& cols, const std::string& group,
               const std::string& file, const CsvLine& header) {
  int present = 0;
  for (int c : cols) present += c >= 0;
  if (present != 0 && present != static_cast<int>(cols.size())) {
    throw InputError(file, header.line, 1,
                     "header: expected all of " + group + " or none, got " +
                         std::to_string(present) + " of " +
                         std::to_string(cols.size()));
  }
  return present > 0;
}

Columns ReadHeader(const CsvLine& header, const std::string& file,
                   const std::vector<std::string>& joint_names) {
  std::map<std::string, int> index;
  for (size_t i = 0; i < header.fields.size(); ++i) {
    const CsvField& f = header.fields[i];
    if (!index.emplace(f.text, static_cast<int>(i)).second) {
      throw InputError(file, header.line, f.column,
                       "header: duplicate column '" + f.text + "'");
    }
  }
  auto take = [&](const std::string& name) {
    const auto it = index.find(name);
    if (it == index.end()) return -1;
    const int c = it->second;
    index.erase(it);
    return c;
  };
  Columns c;
  c.target = take("target");
  if (c.target < 0) c.target = take("pose");  // a POSES.csv of `plan`
  if (c.target < 0) {
    throw InputError(file, header.line, 1,
                     "header: expected a 'target' column (the target's id; "
                     "'pose' is read as well)");
  }
  const char* xyz[3] = {"x", "y", "z"};
  const char* rot[3] = {"rx", "ry", "rz"};
  for (int k = 0; k < 3; ++k) {
    c.xyz[k] = take(xyz[k]);
    c.rot[k] = take(rot[k]);
  }
  c.temp = take("temp_c");
  for (const std::string& j : joint_names) c.joints.push_back(take(j));
  if (!index.empty()) {
    const auto& [name, col] = *index.begin();
    std::string expected = "target, x, y, z, rx, ry, rz, temp_c";
    for (const std::string& j : joint_names) expected += ", " + j;
    throw InputError(
        file, header.line, header.fields[col].column,
        "header: unknown column '" + name + "' (expected " + expected + ")");
  }
  return c;
}

double Cell(const CsvLine& line, int col, const std::string& what,
            const std::string& file) {
  if (col >= static_cast<int>(line.fields.size())) {
    throw InputError(file, line.line, line.end_column,
                     what + ": missing cell (row shorter than the header)");
  }
  const CsvField& f = line.fields[col];
  double v = 0.0;
  if (!ParseFiniteDouble(f.text, &v)) {
    throw InputError(file, line.line, f.column,
                     what + ": expected a number, got '" + f.text + "'");
  }
  return v;
}

}  // namespace

TargetsFile ParseTargetsCsv(const std::string& text, const std::string& file,
                            const std::vector<std::string>& joint_names) {
  const std::vector<CsvLine> lines = TokenizeCsv(text, file);
  if (lines.empty()) throw InputError(file, 0, 0, "empty file: no header");
  const Columns c = ReadHeader(lines[0], file, joint_names);
  const bool position =
      AllOrNone({c.xyz[0], c.xyz[1], c.xyz[2]}, "x, y, z", file, lines[0]);
  const bool rotation =
      AllOrNone({c.rot[0], c.rot[1], c.rot[2]}, "rx, ry, rz", file, lines[0]);
  const bool joints = AllOrNone(c.joints, "the joint columns", file, lines[0]);
  if (rotation && !position) {
    throw InputError(file, lines[0].line, 1,
                     "header: rx, ry, rz need x, y, z (a pose target)");
  }
  if (!position && !joints) {
    throw InputError(file, lines[0].line, 1,
                     "header: expected x, y, z (tip targets) or one column "
                     "per joint (a joint program)");
  }
  TargetsFile out;
  out.source = file;
  out.program = !position;
  std::set<std::string> ids;
  for (size_t i = 1; i < lines.size(); ++i) {
    const CsvLine& l = lines[i];
    if (l.fields.size() != lines[0].fields.size()) {
      throw InputError(file, l.line, l.end_column,
                       "expected " + std::to_string(lines[0].fields.size()) +
                           " cells as in the header, got " +
                           std::to_string(l.fields.size()));
    }
    TargetRow row;
    row.line = l.line;
    row.id = l.fields[c.target].text;
    if (row.id.empty()) {
      throw InputError(file, l.line, l.fields[c.target].column,
                       "target: empty id");
    }
    if (!ids.insert(row.id).second) {
      throw InputError(file, l.line, l.fields[c.target].column,
                       "target: duplicate id '" + row.id + "'");
    }
    const char* names[3] = {"x", "y", "z"};
    const char* rnames[3] = {"rx", "ry", "rz"};
    row.has_position = position;
    row.has_rotation = rotation;
    for (int k = 0; k < 3; ++k) {
      if (position) row.position_mm[k] = Cell(l, c.xyz[k], names[k], file);
      if (rotation) row.rotation_deg[k] = Cell(l, c.rot[k], rnames[k], file);
    }
    if (joints) {
      for (size_t j = 0; j < c.joints.size(); ++j) {
        row.joints.push_back(Cell(l, c.joints[j], joint_names[j], file));
      }
    }
    if (c.temp >= 0) row.temp_c = Cell(l, c.temp, "temp_c", file);
    out.rows.push_back(row);
  }
  if (out.rows.empty()) {
    throw InputError(file, lines[0].line, 1, "no target rows after the header");
  }
  return out;
}

TargetsFile ReadTargetsCsv(const std::string& path,
                           const std::vector<std::string>& joint_names) {
  return ParseTargetsCsv(ReadFile(path), path, joint_names);
}

}  // namespace kincal
