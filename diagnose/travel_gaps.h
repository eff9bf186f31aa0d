#ifndef KINCAL_DIAGNOSE_TRAVEL_GAPS_H_
#define KINCAL_DIAGNOSE_TRAVEL_GAPS_H_

// Gaps in a joint's readings inside the travel a joint-error function was
// fitted on. The transmission family's sine series lives on the whole travel
// [lo, hi] of the data; where the readings leave a gap, nothing holds the
// series there and its prediction is unsupported (series A of the UR10 data
// every 4th row: a 66.6 deg gap in wrist_1 let the series reach 2.1 deg).
// The gap itself is calib/fit_record.h's LargestGap, which the robot file's
// record keeps for compensate.

#include <string>
#include <vector>

#include "calib/fit_record.h"
#include "data/observations.h"
#include "data/warnings.h"

namespace kincal {

// A `transmission_gap` warning for every joint in `joints` whose largest gap
// is wide (IsWideGap: over `fraction` of its travel and `min_gap` reading
// units).
std::vector<Warning> TravelGapWarnings(const Observations& obs,
                                       const std::vector<std::string>& joints,
                                       const std::vector<std::string>& units,
                                       double fraction = kWideGapFraction,
                                       double min_gap = kWideGapMin);

}  // namespace kincal

#endif  // KINCAL_DIAGNOSE_TRAVEL_GAPS_H_
