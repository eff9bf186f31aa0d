#ifndef KINCAL_PLAN_COVERAGE_H_
#define KINCAL_PLAN_COVERAGE_H_

// How evenly a set of poses visits each joint's travel: the campaign guide
// of docs/DIAGNOSE.md ("What a campaign should measure"). A joint-error
// function (the diagnosis' transmission family, its harmonics) is only
// supported where readings exist; a gap over 10 % of the travel and 5 deg
// (calib/fit_record.h IsWideGap) leaves it unsupported there.
//
// The travel of a joint is its usable range [lo, hi] (limits minus the
// plan's margin), ends included: a stretch from lo to the first reading is
// a gap too. A revolute joint whose range spans a full turn or more is
// covered on the circle of the angle (readings modulo 360 deg, the gap
// across 360 wrapping round): a joint error that repeats every revolution
// needs every angle once, not every turn.

#include <string>
#include <vector>

#include "data/robot.h"

namespace kincal {

struct JointCoverage {
  std::string joint;
  bool circular = false;    // covered modulo 360 deg
  double lo = 0, hi = 0;    // the travel (circular: 0, 360), reading units
  double from = 0, to = 0;  // the largest stretch without a reading
                            // (circular: `to` may exceed 360, wrapping)
  double Gap() const { return to - from; }
  // Over 10 % of the travel and 5 reading units (IsWideGap).
  bool wide = false;
};

// Coverage of `poses` (reading units) per joint of `robot`, whose limits
// are the usable ranges (pass the robot with its limits narrowed by the
// plan's margin). No poses: each joint's whole travel is the gap.
std::vector<JointCoverage> TravelCoverage(
    const Robot& robot, const std::vector<std::vector<double>>& poses);

// Indices of `n` of the `candidates` (reading units) that spread every
// joint's readings over its travel: greedy, each step the candidate that
// lowers sum over joints of (sum of squared gaps) / travel^2 the most (the
// sum of squared gaps is least for evenly spaced readings). Ties go to the
// lower index; fewer than n candidates: all of them.
std::vector<int> CoverageDesign(
    const Robot& robot, const std::vector<std::vector<double>>& candidates,
    int n);

}  // namespace kincal

#endif  // KINCAL_PLAN_COVERAGE_H_
