#ifndef KINCAL_DIAGNOSE_TRAVEL_GAPS_H_
#define KINCAL_DIAGNOSE_TRAVEL_GAPS_H_

// Gaps in a joint's readings inside the travel a joint-error function was
// fitted on. The transmission family's sine series lives on the whole travel
// [lo, hi] of the data; where the readings leave a gap, nothing holds the
// series there and its prediction is unsupported (series A of the UR10 data
// every 4th row: a 66.6 deg gap in wrist_1 let the series reach 2.1 deg).

#include <string>
#include <vector>

#include "data/observations.h"
#include "data/warnings.h"

namespace kincal {

struct TravelGap {
  double lo = 0.0, hi = 0.0;    // the travel (reading units)
  double from = 0.0, to = 0.0;  // the largest gap between readings
};

// The largest gap between consecutive distinct readings of `joint` (index in
// obs.joint_names); from == to when there are fewer than two readings.
TravelGap LargestGap(const Observations& obs, int joint);

// A `transmission_gap` warning for every joint in `joints` whose largest gap
// exceeds `fraction` of its travel and `min_gap` reading units.
std::vector<Warning> TravelGapWarnings(const Observations& obs,
                                       const std::vector<std::string>& joints,
                                       const std::vector<std::string>& units,
                                       double fraction = 0.1,
                                       double min_gap = 5.0);

}  // namespace kincal

#endif  // KINCAL_DIAGNOSE_TRAVEL_GAPS_H_
