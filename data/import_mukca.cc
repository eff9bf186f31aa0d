#include "data/import_mukca.h"

#include <cmath>

#include "data/atomic_file.h"
#include "data/csv.h"
#include "data/error.h"

namespace kincal {

std::vector<std::string> PandaJointNames() {
  std::vector<std::string> names;
  for (int j = 1; j <= 7; ++j)
    names.push_back("panda_joint" + std::to_string(j));
  return names;
}

void ParseMukcaHole(const std::string& text, const std::string& file,
                    const std::string& label, Observations* obs) {
  const size_t n = obs->joint_names.size();
  const std::vector<CsvLine> lines = TokenizeCsv(text, file, ',');
  if (lines.empty()) {
    throw InputError(file, 1, 1,
                     "expected joint sets (" + std::to_string(n) +
                         " angles in rad per line), found none");
  }
  int k = 0;
  for (const CsvLine& line : lines) {
    if (line.fields.size() != n) {
      throw InputError(file, line.line, line.end_column,
                       "expected " + std::to_string(n) +
                           " joint angles (rad), found " +
                           std::to_string(line.fields.size()) + " fields");
    }
    Observation row;
    row.pose = label + "_" + std::to_string(k++);
    row.line = line.line;
    row.fixed_point = label;
    for (const CsvField& f : line.fields) {
      double v = 0.0;
      if (!ParseFiniteDouble(f.text, &v)) {
        throw InputError(
            file, line.line, f.column,
            "expected a joint angle in rad, found '" + f.text + "'");
      }
      row.q.push_back(v * 180.0 / M_PI);
    }
    obs->rows.push_back(row);
  }
}

Observations ReadMukcaDir(const std::string& dir,
                          const std::vector<std::string>& joint_names) {
  Observations obs;
  obs.source = dir;
  obs.joint_names = joint_names;
  for (const std::string label : {"hole_0", "hole_1"}) {
    const std::string path = dir + "/" + label + ".csv";
    ParseMukcaHole(ReadFile(path), path, label, &obs);
  }
  return obs;
}

}  // namespace kincal
