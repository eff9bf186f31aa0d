#ifndef KINCAL_TESTS_TESTING_FRESH_POSES_H_
#define KINCAL_TESTS_TESTING_FRESH_POSES_H_

// Fresh poses of a rendered session: `simulate --render` writes the rendered
// poses first and further poses of the same true robot after them; the
// bundle tests score a calibrated robot on the latter with `evaluate`.

#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "tests/testing/run.h"

namespace kincal::testing {

// Rows `skip`.. of an observations.csv (header kept, `#` lines dropped).
inline void KeepRowsFrom(const std::string& in, const std::string& out,
                         int skip) {
  std::ifstream f(in);
  std::ostringstream os;
  std::string line;
  int row = -1;
  while (std::getline(f, line)) {
    if (!line.empty() && line[0] == '#') continue;
    if (row < 0 || row >= skip) os << line << "\n";
    ++row;
  }
  std::ofstream(out) << os.str();
}

// `kincal evaluate --json`'s rms_mm of `robot` on `obs` (expects exit 0).
inline double EvaluateRms(const std::string& robot, const std::string& obs) {
  const RunResult r =
      RunKincal("evaluate --robot " + robot + " --obs " + obs + " --json");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  return nlohmann::json::parse(r.out)["rms_mm"].get<double>();
}

}  // namespace kincal::testing

#endif  // KINCAL_TESTS_TESTING_FRESH_POSES_H_
