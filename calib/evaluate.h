#ifndef KINCAL_CALIB_EVALUATE_H_
#define KINCAL_CALIB_EVALUATE_H_

// `kincal evaluate`: hold the robot model fixed (geometry and extensions),
// register only the measuring frame (and fixed points) on the data, and
// report the position error per pose. Rows of different series (spec v3
// column `series`) get one frame per series, registered on that series'
// rows alone.

#include <string>
#include <vector>

#include "calib/fit.h"
#include "calib/model_state.h"
#include "calib/outliers.h"
#include "data/observations.h"
#include "data/robot.h"

namespace kincal {

// The frame / points registered on a set of rows, and every row's error.
struct Registration {
  ErrorStats stats;               // over the rows registered on
  std::vector<double> errors_mm;  // per usable row (all of them)
  ModelState state;               // with the registered frame / points
};

// Registers the frame / fixed points on the rows not `excluded` (same size
// as `ms`), from `start`'s chain and point labels, and computes every row's
// error.
Registration Register(const ModelState& start,
                      const std::vector<Measurement>& ms,
                      const std::vector<char>& excluded);

// One series' figures: its frame registered on its usable rows.
struct SeriesEvaluation {
  std::string name;         // the series label ("" = unlabelled)
  std::vector<int> usable;  // indices into EvaluateResult::rows
  ErrorStats stats;         // registered on every one of its rows
  ModelState state;         // with this series' frame / points
  bool has_robust = false;  // gross errors left out of `robust_stats`
  ErrorStats robust_stats;  // registered without them
};

struct EvaluateResult {
  // Registered on every usable row (each series on its own rows): the
  // figures the spec names, over all rows' errors.
  ErrorStats stats;
  std::vector<double> errors_mm;  // per usable row
  std::vector<int> rows;          // their indices in the observations
  // With the registered frame (series 0's frame with 2+ series; fixed
  // points from the first series that has rows at them).
  ModelState state;
  // Per series in first-seen order (one entry for a file without the
  // column).
  std::vector<SeriesEvaluation> series;
  // Gross errors (calib/outliers.h FindGrossErrors, per series): rows
  // beyond `outlier_sigmas` robust sigmas. When there are any (and few
  // enough to leave out), `robust` is the registration without them, its
  // stats over the other rows.
  std::vector<RowOutlier> outliers;
  double outlier_axis_sigma_mm = 0.0;  // of the rows kept in `robust`
  bool has_robust = false;
  Registration robust;
  std::vector<char> excluded;  // per usable row, in `robust`
};

EvaluateResult Evaluate(const Robot& robot, const Observations& obs,
                        double outlier_sigmas = kDefaultOutlierSigmas);

// Rows of two campaigns concatenated without a series label, the
// instrument moved in between: one frame for all rows leaves a large error,
// one frame for each of two contiguous blocks of rows does not.
struct FrameJumpOptions {
  // Searched only when the one-frame RMS (model held fixed) exceeds this:
  // far above a nominal model's error, so data of one campaign are left
  // alone.
  double min_one_frame_rms_mm = 20.0;
  // Found when both blocks' RMS, each on its own frame, stay below this
  // fraction of the one-frame RMS.
  double max_ratio = 0.1;
};

struct FrameJump {
  bool found = false;
  int first_row_after = 0;  // index in Observations::rows of the 2nd block
  double one_frame_rms_mm = 0.0;
  double before_rms_mm = 0.0;  // first block on its own frame
  double after_rms_mm = 0.0;   // second block on its own frame
};

// Looks for the jump: the frame registered on the first (else the last)
// tenth of the measured rows splits the rows into those it fits and those
// it does not; both blocks are then registered on their own. Rows with only
// a fixed_point label take no part.
FrameJump FindFrameJump(const Robot& robot, const Observations& obs,
                        const FrameJumpOptions& options = {});

// Throws InputError (at the first row of the second block) when
// FindFrameJump finds a jump in the rows of one series (each series
// searched on its own): the hint is to add a `series` column. `command`
// names the refusing command in the message.
void RequireNoFrameJump(const Robot& robot, const Observations& obs,
                        const std::string& command);

}  // namespace kincal

#endif  // KINCAL_CALIB_EVALUATE_H_
