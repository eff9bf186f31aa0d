#ifndef KINCAL_CALIB_SENSITIVITY_H_
#define KINCAL_CALIB_SENSITIVITY_H_

// The seed paper's optimality criterion (Section 3, Fig. 2/3): vary each
// model parameter alone over +-range units (mm or deg) around the calibrated
// value, others held, and plot the accuracy objective eps (eq. 8: mean
// distance of the model tips to their fixed point's centroid). The verdict:
// when the curves' valleys (minima) are equal and below the accuracy index
// eta (1 mm in the paper), the parameters are optimal; unequal valleys, or
// valleys above eta, mean a parameter error.
//
// What the criterion cannot see (reported, not hidden): a parameter eps does
// not depend on (unidentifiable from single-point data, e.g. a rotation of
// the whole arm about the base z axis, or the tool's twist) gives a flat
// curve whose valley equals eps at the optimum trivially, and an error along
// a combination of parameters that leaves eps unchanged (e.g. j1.d + j2.d on
// parallel axes) moves no single curve. Equal valleys certify only that no
// single-parameter change improves eps (a stationary point), not that the
// parameters are right.

#include <string>
#include <vector>

#include "calib/fit.h"
#include "calib/model_state.h"
#include "data/observations.h"
#include "data/robot.h"

namespace kincal {

struct SensitivityOptions {
  double range = 5.0;   // +- units around the value (mm or deg), the paper's 5
  int steps = 41;       // grid points per curve, odd so that 0 is on the grid
  double eta_mm = 1.0;  // the paper's accuracy index
  // Valleys count as equal when max - min <= max(valley_tolerance_mm,
  // valley_tolerance_fraction * eps at the optimum).
  double valley_tolerance_mm = 1e-3;
  double valley_tolerance_fraction = 0.01;
  // A curve is flat (the parameter does not act on eps) when its range
  // (max - min) is below this, mm.
  double flat_tolerance_mm = 1e-6;
  // Parameters to vary by name; empty = every geometry parameter of the
  // chain (BH-7: 24).
  std::vector<std::string> params;

  void Check() const;  // InputError on a bad range / steps / eta
};

struct SensitivityCurve {
  ParamInfo param;
  std::string unit;             // "mm" or "deg"
  double value = 0.0;           // the robot file's value (interface units)
  std::vector<double> offsets;  // interface units, -range..+range
  std::vector<double> eps_mm;   // eps at value + offset
  double valley_mm = 0.0;       // minimum of eps (grid, refined)
  double valley_offset = 0.0;   // where (interface units)
  bool flat = false;            // eps does not depend on the parameter
  bool identifiable = true;     // by the Jacobian test at the optimum
  bool improves = false;  // valley below eps(0) by more than the tolerance
};

struct SensitivityResult {
  double eps_mm = 0.0;  // at the robot file's values
  ErrorStats epsilon;   // mean / max / std of the distances (Table 2 footer)
  std::vector<SensitivityCurve> curves;
  double valley_min_mm = 0.0, valley_max_mm = 0.0, valley_tolerance_mm = 0.0;
  bool valleys_equal = false;
  bool below_eta = false;
  // "optimal" (valleys equal and < eta) or "not_optimal" (the paper's two
  // outcomes).
  std::string verdict;
  std::vector<std::string> reasons;  // why not optimal, per parameter
  // Blind spots, e.g. "12 flat curves (unidentifiable: j1.theta, ...)".
  std::vector<std::string> notes;
  std::vector<std::string> flat, unidentifiable;  // parameter names
};

// eps over the fixed-point rows of `obs` for the robot as given. Throws
// InputError when `obs` has no fixed point held in 2 or more poses.
SensitivityResult AnalyzeSensitivity(const Robot& robot,
                                     const Observations& obs,
                                     const SensitivityOptions& options);

}  // namespace kincal

#endif  // KINCAL_CALIB_SENSITIVITY_H_
