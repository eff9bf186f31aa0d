#include "diagnose/travel_gaps.h"

#include <algorithm>
#include <cstdio>

namespace kincal {

std::vector<Warning> TravelGapWarnings(const Observations& obs,
                                       const std::vector<std::string>& joints,
                                       const std::vector<std::string>& units,
                                       double fraction, double min_gap) {
  std::vector<Warning> out;
  for (size_t k = 0; k < joints.size(); ++k) {
    const auto it =
        std::find(obs.joint_names.begin(), obs.joint_names.end(), joints[k]);
    if (it == obs.joint_names.end()) continue;
    const TravelGap g =
        LargestGap(obs, static_cast<int>(it - obs.joint_names.begin()));
    const double gap = g.to - g.from, travel = g.hi - g.lo;
    if (!IsWideGap(g, fraction, min_gap)) continue;
    char msg[512];
    std::snprintf(msg, sizeof msg,
                  "%s: the transmission series is fitted over the travel "
                  "[%.1f, %.1f] %s, with no reading between %.1f and %.1f "
                  "(a gap of %.1f %s, %.0f %% of the travel): nothing holds "
                  "the series there, so its prediction there is not "
                  "supported; measure poses in the gap, or treat targets "
                  "there as extrapolated",
                  joints[k].c_str(), g.lo, g.hi, units[k].c_str(), g.from, g.to,
                  gap, units[k].c_str(), 100.0 * gap / travel);
    out.push_back({"transmission_gap", msg});
  }
  return out;
}

}  // namespace kincal
