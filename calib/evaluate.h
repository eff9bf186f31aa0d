#ifndef KINCAL_CALIB_EVALUATE_H_
#define KINCAL_CALIB_EVALUATE_H_

// `kincal evaluate`: hold the robot model fixed (geometry and extensions),
// register only the measuring frame (and fixed points) on the data, and
// report the position error per pose.

#include <vector>

#include "calib/fit.h"
#include "calib/model_state.h"
#include "data/observations.h"
#include "data/robot.h"

namespace kincal {

struct EvaluateResult {
  ErrorStats stats;
  std::vector<double> errors_mm;  // per usable row
  std::vector<int> rows;          // their indices in the observations
  ModelState state;               // with the registered frame
};

EvaluateResult Evaluate(const Robot& robot, const Observations& obs);

}  // namespace kincal

#endif  // KINCAL_CALIB_EVALUATE_H_
