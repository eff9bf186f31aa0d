#ifndef KINCAL_DIAGNOSE_MODEL_DIAGNOSIS_H_
#define KINCAL_DIAGNOSE_MODEL_DIAGNOSIS_H_

// `kincal diagnose model`: what the geometric model gets wrong, and why.
//
// Method (docs/DIAGNOSE.md has the statistics and the measured rates):
//   1. Seeded split of the measured poses into training and held-out.
//   2. Fit frame + identifiable geometry on the training poses (the base).
//   3. Candidates from the spec's catalogue, for every joint where they apply
//      and are identifiable on this data (a candidate whose Jacobian columns
//      lie in the span of the base's is equivalent to geometry and skipped):
//      backlash (s), compliance (gravity torque), cyclic (cos q, sin q), gain
//      (q), axis_tilt (Hayati beta on nominally parallel axes), drift (t).
//   4. Each candidate is refitted JOINTLY with geometry and frame
//      (Levenberg-Marquardt on the exact Jacobian, calib/free_fit.h, with the
//      candidate's parameters freed). Nested-model F-test,
//      F = ((RSS0 - RSS1) / k) / (RSS1 / (n - p - k)), Bonferroni-corrected
//      over the candidates of the step (family-wise false-alarm rate
//      `false_alarm` per step), and the candidate must predict the left-out
//      folds of a K-fold cross-validation of the training poses better
//      (diagnose/cross_validation.h; folds = 0: the held-out RMS must drop).
//   5. Greedy forward selection: the step's winner (lowest cross-validated
//      RMS, ties to the most significant; with folds = 0 the most
//      significant) is added and the step repeats while a candidate stays
//      significant.
//   6. Candidates whose fits explain the data as well as the chosen one (RSS
//      difference below the chi-square(1) 95 % point of the noise) are
//      reported as equivalent instead of guessing between them.
//   7. Final refit of the selected model on all poses; magnitudes in the
//      spec's units with 95 % intervals from the covariance (delta method).
//   8. `unexplained` when the final residuals stay clearly above the
//      measurement noise (stated, from repeated poses, or an upper bound from
//      nearest-neighbour pose pairs).

#include <array>
#include <cstdint>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "calib/fit.h"
#include "calib/model_state.h"
#include "data/observations.h"
#include "data/robot.h"
#include "data/warnings.h"
#include "diagnose/catalogue.h"
#include "diagnose/series_checks.h"
#include "diagnose/statistics.h"

namespace kincal {

struct DiagnoseOptions {
  double holdout_fraction = 0.25;  // of the measured poses, seeded
  uint64_t seed = 1;
  // Per-axis measurement noise (mm); 0 = estimate from the data.
  double noise_mm = 0.0;
  // Family-wise false-alarm probability of one selection step (Bonferroni
  // over that step's candidates).
  double false_alarm = 0.01;
  int max_findings = 10;  // a cap; the steps stop when nothing is significant
  // Smallest effect worth naming: RMS (3D, over the training poses) of the
  // tip error a candidate explains, mm. Far below any measuring system's
  // resolution; it stops noise-free data from naming second-order
  // linearisation rests of the geometry (~1 um) as effects.
  double min_effect_mm = 0.002;
  // Residual scatter above this multiple of the noise counts as systematic.
  double unexplained_ratio = 1.5;
  int num_threads = 2;
  // Restrict candidates to these causes (empty = all of the catalogue).
  std::vector<std::string> causes;
  // Cross-series validation: other measured series of the same robot that
  // the fit never sees (e.g. train on UR10 series C, validate on B). Each
  // candidate's training fit is evaluated there with only the measuring
  // frame re-registered; with validation data a candidate must also lower
  // the validation RMS, and the lowest validation RMS wins the step.
  std::vector<Observations> validation;
  // K-fold cross-validation of the selection (diagnose/cross_validation.h):
  // the training poses in `folds` seeded folds; a candidate that passes the
  // F-test must also lower the cross-validated RMS (instead of the single
  // held-out split's RMS, which is then only reported), and the lowest
  // cross-validated RMS wins the step (with validation series, theirs).
  // 0 or 1 = one held-out split. Unless `folds_given`,
  // fewer folds when the training poses are few (at least
  // kMinPosesPerFold distinct poses per fold, else the single split); with
  // `folds_given` more folds than distinct training poses is bad input.
  int folds = 5;
  bool folds_given = false;
  static constexpr int kMinPosesPerFold = 10;
  // Full Levenberg-Marquardt refits per fold instead of the linearised
  // fold step (the reference of bench/diagnose_bench --only cv).
  bool cv_refit = false;
  // A candidate's out-of-fold improvement over the current model must
  // exceed this many standard errors (paired over the training poses; 1.645
  // = one-sided 5 %; 0 = the cross-validated RMS must drop).
  double cv_min_z = 1.645;
  // Candidates within this many standard errors of the lowest
  // cross-validated RMS count as tied; the most significant of them wins.
  double cv_tie_z = 2.0;

  void Check() const;  // InputError on invalid values
};

// Score of one candidate in one selection step.
struct CandidateScore {
  std::string cause, joint;  // joint "" for drift
  bool identifiable = true;
  int k = 0;  // parameters added
  double train_rms_mm = 0.0, heldout_rms_mm = 0.0;
  double rss = 0.0;  // training sum of squared residuals, mm^2
  double f = 0.0, p_value = 1.0;
  bool significant = false;
  double validation_rms_mm = 0.0;  // NaN without validation data
  // Cross-validated RMS over the training poses (NaN without folds, or when
  // the F-test already rejects the candidate).
  double cv_rms_mm = std::numeric_limits<double>::quiet_NaN();
  // Its out-of-fold improvement over the current model in standard errors
  // (paired over the training poses; NaN when not computed).
  double cv_z = std::numeric_limits<double>::quiet_NaN();
  double magnitude = 0.0;  // spec units, from the training fit
  std::string unit;
};

struct Equivalent {
  std::string cause, joint;
  double magnitude = 0.0;
  std::string unit;
  double train_rms_mm = 0.0, heldout_rms_mm = 0.0;
};

struct Finding {
  std::string cause, joint;  // joint "" = none (drift, unexplained)
  double magnitude = 0.0;
  std::string unit;
  double ci_low = 0.0, ci_high = 0.0;
  double heldout_rms_before_mm = 0.0, heldout_rms_after_mm = 0.0;
  double train_rms_after_mm = 0.0;
  // Cross-series validation RMS (NaN without validation data).
  double validation_rms_before_mm = 0.0, validation_rms_after_mm = 0.0;
  // Cross-validated RMS of the training poses (NaN without folds).
  double cv_rms_before_mm = std::numeric_limits<double>::quiet_NaN();
  double cv_rms_after_mm = std::numeric_limits<double>::quiet_NaN();
  double f = 0.0, p_value = 1.0;
  std::vector<Equivalent> equivalent;
  // `unexplained` only: the inputs the systematic rest depends on, strongest
  // first, and the smooth correction's cross-validated share of the residual
  // power (diagnose/nonparametric.h); heldout_rms_after_mm is then the
  // held-out RMS after that correction.
  std::vector<std::string> depends_on;
  double cv_explained = 0.0;
  int smooth_k = 0;
  std::vector<std::pair<std::string, double>> single_inputs;
  // The same share from the measured point's position alone (robot or
  // instrument, see SmoothCorrection); NaN without measured points.
  double point_cv_explained = std::numeric_limits<double>::quiet_NaN();
  // A periodic transmission (revolute joint) only, in the reading's unit
  // (deg): the travel of the training readings that supports it, the arcs
  // of the revolution where it is extrapolated (gaps between readings wider
  // than 5 deg, and beyond the travel; diagnose/periodic_basis.h
  // ExtrapolatedArcs), its amplitude (half its peak-to-peak over the
  // readings) and its largest deviation from its mean over the readings on
  // those arcs (the regulariser keeps it near the supported part).
  bool periodic = false;
  double travel_lo = 0.0, travel_hi = 0.0;
  std::vector<std::array<double, 2>> extrapolated;
  double amplitude = 0.0, extrapolated_peak = 0.0;
};

struct DiagnosisResult {
  std::string verdict;  // "effect_found" | "no_significant_effect"
  int train_poses = 0, heldout_poses = 0;
  double nominal_train_rms_mm = 0.0, nominal_heldout_rms_mm = 0.0;
  std::vector<Finding> findings;
  double final_train_rms_mm = 0.0, final_heldout_rms_mm = 0.0;
  // Cross-series validation (options.validation), frame re-registered only.
  double nominal_validation_rms_mm = 0.0, final_validation_rms_mm = 0.0;
  // Folds of the cross-validation used (0 = the single held-out split) and
  // the cross-validated RMS of the geometric and the final model.
  int folds = 0;
  double nominal_cv_rms_mm = std::numeric_limits<double>::quiet_NaN();
  double final_cv_rms_mm = std::numeric_limits<double>::quiet_NaN();
  // Noise per axis (mm) and where it came from: "stated", "repeated poses",
  // "nearest poses (upper bound)", "none".
  double noise_mm = 0.0;
  std::string noise_source;
  double residual_sigma_mm = 0.0;  // per axis, final model, training
  double systematic_rms_mm = 0.0;  // 3D RMS above the noise
  std::vector<std::vector<CandidateScore>> steps;  // every selection step
  std::vector<std::string> not_identifiable;       // candidate labels
  double bonferroni_alpha = 0.0;  // per-candidate level of the first step
  // Per measured pose (visit order): its row in the observations, whether it
  // was held out, and the final model's residual (model - measured, mm).
  std::vector<int> rows;
  std::vector<bool> heldout;
  std::vector<Eigen::Vector3d> residuals;
  Robot extended;  // nominal + fitted geometry + extensions
  // What the selected model rests on that the data do not support (e.g.
  // transmission_gap: a gap in a joint's readings inside its series'
  // travel, diagnose/travel_gaps.h).
  std::vector<Warning> warnings;
  ModelState state;  // final model (all poses)
  // Several series (spec v3 column `series`, one measuring frame each): per
  // series figures, robot or instrument, instrument scale
  // (diagnose/series_checks.h); empty for one series.
  SeriesChecks series;
  double seconds = 0.0;
};

DiagnosisResult DiagnoseModel(const Robot& nominal, const Observations& obs,
                              const DiagnoseOptions& options);

// Fits frame + identifiable geometry + the given candidates jointly on all
// measured poses of `obs` and returns each candidate's magnitude (spec units,
// 95 % interval). Used by `diagnose compare` and the Monte-Carlo check of the
// intervals.
std::vector<Magnitude> FitCandidates(const Robot& nominal,
                                     const Observations& obs,
                                     const std::vector<std::string>& labels,
                                     double* sigma0_mm = nullptr);

// JSON per the spec ("Diagnosis result"): verdict, nominal, findings, final;
// plus the noise, the candidate table of every step and the seed.
nlohmann::json DiagnosisJson(const DiagnosisResult& result,
                             const DiagnoseOptions& options);
// CSV of the final residuals: pose,set,dx_mm,dy_mm,dz_mm,error_mm.
std::string ResidualsCsv(const DiagnosisResult& result,
                         const Observations& obs);

}  // namespace kincal

#endif  // KINCAL_DIAGNOSE_MODEL_DIAGNOSIS_H_
