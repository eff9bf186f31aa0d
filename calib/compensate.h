#ifndef KINCAL_CALIB_COMPENSATE_H_
#define KINCAL_CALIB_COMPENSATE_H_

// `kincal compensate`: the joint readings to command so that the modelled
// real robot (a calibrated, extended robot file) reaches given targets.
// Per target, in visiting order:
//   1. the controller's solution q_nom: the target through the nominal
//      kinematics (geometry only), from the target's seed, else the previous
//      solution (multi-start for the first); a joint program gives q_nom
//      directly (its targets are the nominal kinematics at its readings);
//   2. the compensated readings q: inverse kinematics through the whole
//      calibrated model (calib/inverse_kinematics.h) from q_nom, with the
//      approach direction of every joint taken from the move from the
//      previous command (backlash), re-solved until it is stable;
//   3. refused when q leaves q_nom's configuration (a joint moves more than
//      max_correction), when the IK does not reach the target, or it stops
//      on a limit;
//   4. predicted tip error: the IK residual and sigma^2 = trace(J C J^T) +
//      systematic^2, J the tip's derivative by the model's parameters at q,
//      C their covariance and systematic the model's unexplained residual
//      (robot.yaml covariance: and fitted_on:, see data/robot.h);
//   5. flagged as extrapolated where a joint reading lies outside the travel
//      the model was fitted on, or the temperature outside its range.
// Terms of time (drift, thermal per hour) describe a measuring session, not
// the robot: compensated at the session's start (t = 0), with a warning.

#include <Eigen/Core>
#include <limits>
#include <string>
#include <vector>

#include "calib/inverse_kinematics.h"
#include "calib/model_state.h"
#include "data/robot.h"
#include "data/warnings.h"

namespace kincal {

struct CompensateTarget {
  std::string id;
  IkTarget target;           // in the robot's base frame
  std::vector<double> seed;  // readings (mm | deg); empty = none
  // A joint program's readings: the target is the nominal kinematics there.
  bool from_joints = false;
  double temp_c = std::numeric_limits<double>::quiet_NaN();
};

struct CompensateOptions {
  IkOptions ik;  // limits: the robot's when empty
  // Temperature for targets without their own (deg C); NaN = none.
  double temp_c = std::numeric_limits<double>::quiet_NaN();
  // Readings before the first target (for the first approach directions);
  // empty = unknown (the model's mean backlash for the first target).
  std::vector<double> start;
  // Largest difference between the compensated and the controller's
  // readings, per joint (deg | mm): more is another configuration.
  double max_correction = 10.0;
  uint64_t seed = 1;  // multi-start of the first target without a seed
  // Targets (x,y,z and rotation) given in the measuring frame the model was
  // registered in (robot.yaml fitted_on.frame), e.g. points a tracker
  // measured; false = in the robot's base frame.
  bool targets_in_measuring_frame = false;
  // With targets in the measuring frame and a model fitted on several series
  // (fitted_on.series_frames): the series whose instrument frame the targets
  // are in; empty = the first series (a warning `series_frame_assumed`
  // names it).
  std::string series;
};

struct CompensatedTarget {
  std::string id;
  std::vector<double> q;      // readings to command (mm | deg)
  std::vector<double> q_nom;  // the controller's readings for the target
  bool reached = false;
  std::string why;  // when not reached
  double residual_mm = 0.0;
  double rotation_residual_deg = 0.0;
  // Predicted tip error after compensation: sigma from the model's
  // uncertainty, and sqrt(residual^2 + sigma^2). NaN without covariance.
  double sigma_mm = std::numeric_limits<double>::quiet_NaN();
  double predicted_mm = std::numeric_limits<double>::quiet_NaN();
  // The model's tip error when q_nom is commanded (what compensation
  // removes); NaN when there is no q_nom.
  double uncompensated_mm = std::numeric_limits<double>::quiet_NaN();
  std::vector<std::string> extrapolated;  // reasons; empty = inside
};

struct CompensateResult {
  std::vector<CompensatedTarget> targets;
  int reached = 0;
  double predicted_rms_mm = 0.0, predicted_max_mm = 0.0;  // reached targets
  double uncompensated_rms_mm = std::numeric_limits<double>::quiet_NaN();
  Warnings warnings;
};

// Compensates `targets` in visiting order for `robot` (a calibrated robot
// file; its `nominal:` rows are the controller's kinematics, else its own
// geometry). Throws InputError when the inputs cannot be right (a thermal
// term without a temperature, a joint program without nominal rows).
CompensateResult Compensate(const Robot& robot,
                            const std::vector<CompensateTarget>& targets,
                            const CompensateOptions& options);

// The uncertainty of the model's tip, prepared once per robot (the
// covariance's parameter names resolved, the recorded frame set):
// sigma = sqrt(trace(J C J^T)) at readings q, J by central differences of the
// tip, in the measuring frame when the covariance carries the frame (the
// targets are located through it).
class TipUncertainty {
 public:
  // Throws InputError when a covariance parameter names nothing in the model,
  // or names the frame while fitted_on records none.
  // `series`: the measuring frame of that series (fitted_on.series_frames;
  // empty = the first).
  TipUncertainty(const Robot& robot, const Chain& chain,
                 const std::string& series = "");
  // mm, 3D; NaN when the robot carries no covariance.
  double SigmaMm(const std::vector<double>& q, const IkContext& context) const;
  // The recorded measuring frames (fitted_on.frame or series_frames, as the
  // state's frame blocks: rad, mm) and the index of the one targets are
  // located through.
  const ModelState& recorded_frames() const { return state_; }
  int frame_index() const { return frame_; }

 private:
  const Eigen::MatrixXd* covariance_;
  ModelState state_;
  std::vector<ParamInfo> params_;
  bool in_measuring_frame_ = false;
  int frame_ = 0;  // the frame targets are located through
};

// The frame index of `series` among fitted_on.series_frames (0 for a model of
// one series or an empty `series`); throws InputError naming the recorded
// series when it is not one of them.
int SeriesFrameIndex(const FitRecord& rec, const std::string& series);

}  // namespace kincal

#endif  // KINCAL_CALIB_COMPENSATE_H_
