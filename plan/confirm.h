#ifndef KINCAL_PLAN_CONFIRM_H_
#define KINCAL_PLAN_CONFIRM_H_

// Monte Carlo check of a plan's linearised predictions: simulate sessions at
// the given poses (true robot = nominal + random deviations of the plan's
// identifiable robot parameters, measured tips in the measuring frame with
// Gaussian noise), calibrate each with calib's Fit from the nominal model,
// and measure the actual parameter errors and tip errors.

#include <cstdint>
#include <vector>

#include "plan/plan.h"

namespace kincal {

struct ConfirmOptions {
  int repetitions = 10;
  uint64_t seed = 1;
  double sigma_length_mm = 0.5;  // true deviations
  double sigma_angle_deg = 0.2;
};

struct ConfirmResult {
  // Per PlanResult::params: RMS over repetitions of estimate - truth
  // (interface units); frame parameters are compared with the true frame.
  std::vector<double> rms_error;
  // Geometric mean over the robot parameters of rms_error / bound.
  double error_gmean = 0;
  // RMS tip error of the calibrated model on the plan's evaluation poses
  // (measuring frame), over all repetitions.
  double tip_rms_mm = 0;
  int failed_fits = 0;
};

// Free-mode plans only (fixed-point designs: InputError).
ConfirmResult ConfirmDesign(const Robot& robot, const PlanResult& plan,
                            const std::vector<std::vector<double>>& poses,
                            const PlanOptions& plan_options,
                            const ConfirmOptions& options);

}  // namespace kincal

#endif  // KINCAL_PLAN_CONFIRM_H_
