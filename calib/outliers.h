#ifndef KINCAL_CALIB_OUTLIERS_H_
#define KINCAL_CALIB_OUTLIERS_H_

// Gross errors among the rows of a fit: a ball not seated, a row saved under
// the other socket's label, a laser tracker's beam break. Least squares
// spreads such a row over every parameter (MUKCa panda_7 `left`: 6 rows of
// hole_1 saved in hole_0.csv turn 0.35 mm of scatter into 14 mm), so
// `calibrate` excludes rows whose error exceeds `sigmas` robust standard
// deviations and lists them; `evaluate` lists them and adds figures without
// them.
//
// The scale is per axis, from the median error norm (the median of a
// 3-D Gaussian error's norm is 1.5382 sigma), so up to half the rows may be
// gross before it moves. The default 10 sigma is far beyond Gaussian noise
// (P ~ 1e-21 per row) and beyond the rows of the clean real sets measured:
// after calibration UR10 series A/B/C and 27 MUKCa Panda recordings reach
// at most 8.5; one row of panda_2 `back_left` is at 13.3 (1.13 mm against
// a median of 0.16 mm), docs/CALIBRATION.md.

#include <string>
#include <vector>

#include "calib/fit.h"
#include "calib/model_state.h"

namespace kincal {

constexpr double kDefaultOutlierSigmas = 10.0;

// Robust per-axis standard deviation of 3-D errors from their norms (mm):
// median / 1.5382; 0 for no rows.
double RobustAxisSigmaMm(const std::vector<double>& norms_mm);

// A row beyond the threshold.
struct RowOutlier {
  int row = 0;            // index in Observations::rows
  std::string pose;       // its pose id
  bool heldout = false;   // a held-out row (calibrate)
  bool excluded = false;  // left out of the fit / of the figures
  double error_mm = 0.0;
  double sigmas = 0.0;  // error / robust axis sigma
  // Single-point rows: another fixed point the tip is within the threshold
  // of (a row saved under the wrong label), else empty.
  std::string near_point;
  double near_point_mm = 0.0;
};

// RobustAxisSigmaMm of the rows not `excluded` (same size as errors_mm).
double RobustAxisSigmaOfKeptMm(const std::vector<double>& errors_mm,
                               const std::vector<char>& excluded);

// Flags (1 = gross) for `norms_mm` above sigmas x axis_sigma_mm; none when
// either is not positive.
std::vector<char> FlagGross(const std::vector<double>& norms_mm,
                            double axis_sigma_mm, double sigmas);

// Whether excluding `flags` leaves a fit that still means something: at
// most a quarter of the rows, and every fixed point at least 3 rows.
bool CanExclude(const std::vector<Measurement>& ms,
                const std::vector<char>& flags);

// Gross errors under a fixed model (`state`'s chain; its frame and points
// are not used): the tips of `ms` are registered in closed form to the
// measured points (a rigid transform, weighted Kabsch) and to each fixed
// point (its position), first with Cauchy weights (scale: the robust sigma
// of the unweighted fit) so that gross rows cannot pull the frame or a
// point towards them, then unweighted without the rows beyond `sigmas`
// robust sigmas, until that set is stable. Returns the flags (none when
// more than CanExclude allows).
std::vector<char> FindGrossErrors(const ModelState& state,
                                  const std::vector<Measurement>& ms,
                                  double sigmas);

RowOutlier DescribeOutlier(const ModelState& state, const Measurement& m,
                           const std::string& pose, double error_mm,
                           double axis_sigma_mm, double sigmas);

}  // namespace kincal

#endif  // KINCAL_CALIB_OUTLIERS_H_
