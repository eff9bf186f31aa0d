#ifndef KINCAL_TESTS_TESTING_CSV_ROWS_H_
#define KINCAL_TESTS_TESTING_CSV_ROWS_H_

// The rows of a CSV file the tests check field by field (points.csv,
// points.poses.csv, frames.csv): `#` and empty lines skipped, a trailing
// comma keeps its empty last field. No quoting: kincal writes none there.

#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace kincal::testing {

inline std::vector<std::vector<std::string>> ReadCsvRows(
    const std::string& path) {
  std::vector<std::vector<std::string>> rows;
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::vector<std::string> fields;
    std::stringstream ss(line);
    std::string f;
    while (std::getline(ss, f, ',')) fields.push_back(f);
    if (line.back() == ',') fields.push_back("");
    rows.push_back(fields);
  }
  return rows;
}

}  // namespace kincal::testing

#endif  // KINCAL_TESTS_TESTING_CSV_ROWS_H_
