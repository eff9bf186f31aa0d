#ifndef KINCAL_TESTS_TESTING_FRESH_POSES_H_
#define KINCAL_TESTS_TESTING_FRESH_POSES_H_

// Fresh poses of a rendered session: `simulate --render` writes the rendered
// poses first and further poses of the same true robot after them; the
// bundle tests score a calibrated robot on the latter with `evaluate`.

#include <gtest/gtest.h>

#include <cmath>
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

// Renders a session of `robot` (`poses` poses from `seed`, 640 x 512, pixel
// noise 1.5, blur 0.5, `cameras` cameras, then `render_extra`), bundles it
// (`bundle_extra`) and returns the bundle's RMS error at 200 fresh poses of
// the same true robot (mm; NaN when bundle fails). `json` receives bundle's
// output. The fresh poses are written once per `dir` (dir/fresh.csv).
inline double RenderedBundleAtFreshPoses(const std::string& robot,
                                         const std::string& dir, int poses,
                                         int seed, int cameras,
                                         nlohmann::json* json,
                                         const std::string& render_extra,
                                         const std::string& bundle_extra) {
  const std::string s = dir + "/s" + std::to_string(cameras);
  RunResult r = RunKincal(
      "simulate --robot " + robot + " --out " + s + " --poses " +
      std::to_string(poses) + " --noise 0 --seed " + std::to_string(seed) +
      " --render --render-noise 1.5 --render-blur 0.5 --render-width 640 "
      "--render-height 512 --render-cameras " +
      std::to_string(cameras) + " " + render_extra);
  EXPECT_EQ(r.exit_code, 0) << r.err;
  r = RunKincal("bundle --robot " + s + "/robot.yaml --rig " + s +
                "/rig.yaml --target " + s + "/target.yaml --session " + s +
                "/session --quiet --out " + s + "/bcal.yaml --json " +
                bundle_extra);
  EXPECT_EQ(r.exit_code, 0) << r.err;
  if (r.exit_code != 0) return std::nan("");
  *json = nlohmann::json::parse(r.out);
  const std::string fresh = dir + "/fresh.csv";
  if (!std::ifstream(fresh).good()) {
    r = RunKincal("simulate --robot " + robot + " --out " + dir +
                  "/fresh --poses " + std::to_string(poses + 200) +
                  " --noise 0 --seed " + std::to_string(seed));
    EXPECT_EQ(r.exit_code, 0) << r.err;
    KeepRowsFrom(dir + "/fresh/observations.csv", fresh, poses);
  }
  return EvaluateRms(s + "/bcal.yaml", fresh);
}

}  // namespace kincal::testing

#endif  // KINCAL_TESTS_TESTING_FRESH_POSES_H_
