#ifndef KINCAL_CALIB_FREE_FIT_H_
#define KINCAL_CALIB_FREE_FIT_H_

// Bounded Levenberg-Marquardt on the exact Jacobian (calib/exact_jacobian.h)
// in the free parameters only: the candidate refits of `diagnose model` and
// its base model's geometry fits (calib/calibrate.h GeometrySolver). Same
// model (calib/chain.h TipInBase) and bounds (+-delta about the nominal
// geometry) as calib/fit.h's Fit; measured rows only.

#include <map>
#include <string>
#include <vector>

#include "calib/fit.h"
#include "calib/model_state.h"

namespace kincal {

struct FreeFitOptions {
  std::vector<ParamInfo> free;
  const Chain* bounds_center = nullptr;
  // Per-parameter bounds replacing the chain's (calib/fit.h FitOptions::
  // bound_override).
  std::map<std::string, double> bound_override;
  int max_iterations = 100;
  double function_tolerance = 1e-10;
  double parameter_tolerance = 1e-10;
  // The residual and Jacobian passes over the rows on up to this many
  // threads (calib/exact_jacobian.h).
  int num_threads = 1;
};

// The same free parameters, box and stopping rules as a calib/fit.h fit
// (its distances, prior and covariance are not carried over).
FreeFitOptions FreeFitOptionsFrom(const FitOptions& fit_options);

// The +-bound of a free row entry about options.bounds_center (calib/fit.h
// RowBound with the options' overrides).
double FreeFitBound(const FreeFitOptions& options, const ParamInfo& p);

// Fits the free parameters of `state` to the measured rows (kMeasured
// only); returns the final sum of squared residuals, mm^2.
double FreeFit(const std::vector<Measurement>& measurements,
               const FreeFitOptions& options, ModelState* state);

// FreeFit, then, as calib/fit.h's Fit with
// compute_covariance: sigma0 = sqrt(RSS / (3 m - p)) and the covariance
// sigma0^2 (J^T J)^+ of the free parameters (eigenvalues below 1e-14 of the
// largest dropped, as ceres::Covariance DENSE_SVD with null_space_rank -1).
FitSummary FreeFitWithCovariance(const std::vector<Measurement>& measurements,
                                 const FreeFitOptions& options,
                                 ModelState* state);

}  // namespace kincal

#endif  // KINCAL_CALIB_FREE_FIT_H_
