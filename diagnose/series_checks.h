#ifndef KINCAL_DIAGNOSE_SERIES_CHECKS_H_
#define KINCAL_DIAGNOSE_SERIES_CHECKS_H_

// Per-series checks of `diagnose model` on several series (spec v3 column
// `series`, one measuring frame each, the robot shared):
//   - robot or instrument, per series: the smooth-correction test of
//     diagnose/nonparametric.h (what a smooth function of the joint
//     readings predicts of the final residual in cross-validation, against
//     what one of the measured point's position in the series' own
//     measuring frame predicts) run on each series' training poses;
//   - instrument scale: a length scale factor per series relative to the
//     first (p_in_meas = s_k R_k tip + t_k), tested by one Gauss-Newton
//     step from the final model with every free parameter refitted and an
//     F-test. One scale shared by every series is not identifiable when
//     every length of the robot is free and no joint reading is a length
//     (scaling every length and the frames' translations moves no
//     residual; a prismatic joint's readings carry the unit): the check
//     measures it as the sine of the angle between the shared scale's
//     column and the span of the free parameters' columns.

#include <Eigen/Core>
#include <string>
#include <vector>

#include "calib/fit.h"
#include "calib/model_state.h"
#include "data/observations.h"

namespace kincal {

struct SeriesCheck {
  std::string name;  // series label ("" = unlabelled rows)
  int train_poses = 0, heldout_poses = 0;
  double train_rms_mm = 0.0, heldout_rms_mm = 0.0;  // final model, own frame
  // Shares of the series' training residual power predicted in
  // cross-validation by a smooth function of the joint readings / of the
  // measured point (diagnose/nonparametric.h); NaN with < 20 poses.
  double joints_cv_explained = 0.0, point_cv_explained = 0.0;
  // "robot" (the joints predict more, by 0.05 of the power and at least
  // 0.1), "instrument" (the point does), or "undecided".
  std::string follows;
  // The scale factor relative to the first series, parts per million, its
  // 1-sigma; 0 and NaN for the first series.
  double scale_ppm = 0.0, scale_sigma_ppm = 0.0;
};

struct SeriesChecks {
  std::vector<SeriesCheck> series;
  // Relative scales (one per series after the first) tested jointly: the
  // training RSS drop's F statistic and its p-value; significant when p <
  // false_alarm.
  double scale_f = 0.0, scale_p_value = 1.0;
  bool scale_significant = false;
  // sin of the angle between the column of one scale shared by all series
  // and the span of the free parameters' columns: ~0 = not identifiable.
  double shared_scale_sine = 0.0;
};

// `train` / `held`: the measurements (Measurement::frame = series index,
// ModelState::frame_series), `state` the final model, `free` its free
// parameters (frames included). `false_alarm`: the scale test's level;
// `threads`: its Jacobian and normal equations on up to that many threads.
SeriesChecks CheckSeries(const Observations& obs,
                         const std::vector<Measurement>& train,
                         const std::vector<Measurement>& held,
                         const ModelState& state,
                         const std::vector<ParamInfo>& free, double false_alarm,
                         int threads = 1);

}  // namespace kincal

#endif  // KINCAL_DIAGNOSE_SERIES_CHECKS_H_
