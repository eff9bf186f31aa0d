#include "calib/compensate.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <random>

#include "calib/fit_record.h"
#include "calib/model_state.h"
#include "data/error.h"
#include "data/rigid3.h"
#include "data/yaml_util.h"

namespace kincal {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// The controller's kinematics: the recorded nominal rows, else the
// calibrated geometry without its extensions.
Chain NominalChain(const Robot& robot) {
  if (robot.HasNominal()) return Chain::FromRobot(robot.Nominal());
  Robot plain = robot;
  plain.extensions.clear();
  return Chain::FromRobot(plain);
}

// The error model's inputs that do not depend on the readings, for a target
// at temperature `temp_c`; refuses a thermal term that has no temperature.
IkContext ContextFor(const Robot& robot, const Chain& chain, double temp_c,
                     const std::string& id) {
  IkContext c;
  bool thermal = false;
  for (const auto& e : chain.joint_errors)
    thermal = thermal || e[kThermal] != 0;
  if (thermal && robot.fitted_on.thermal_input != "hours") {
    if (!(temp_c == temp_c)) {
      throw InputError(
          "target " + id +
          ": the model has a thermal term (per K of temp_c - 20) and the "
          "target has no temperature: give a temp_c column or --temp-c");
    }
    c.thermal_x = temp_c - 20.0;
  }
  return c;
}

// Readings to start the controller's solution from when a target has no
// seed, tried in turn until one reaches it: the previous solution, the start
// readings, the middle of the limits, then seeded random readings inside
// them.
std::vector<std::vector<double>> StartCandidates(
    const Robot& robot, const std::vector<double>& previous,
    const std::vector<double>& start, uint64_t seed) {
  std::vector<std::vector<double>> out;
  if (!previous.empty()) out.push_back(previous);
  if (!start.empty()) out.push_back(start);
  const int n = static_cast<int>(robot.joints.size());
  std::vector<double> mid(n, 0.0), lo(n), hi(n);
  for (int j = 0; j < n; ++j) {
    const RobotRow& r = robot.joints[j];
    const double span = r.type == JointType::kRevolute ? 180.0 : 100.0;
    lo[j] = r.HasLimits() ? r.lower : -span;
    hi[j] = r.HasLimits() ? r.upper : span;
    mid[j] = 0.5 * (lo[j] + hi[j]);
  }
  out.push_back(mid);
  std::mt19937_64 rng(seed);
  for (int k = 0; k < 30; ++k) {
    std::vector<double> q(n);
    for (int j = 0; j < n; ++j) {
      q[j] = std::uniform_real_distribution<double>(lo[j], hi[j])(rng);
    }
    out.push_back(q);
  }
  return out;
}

// The smallest distance of any joint to its limits (reading units; +inf
// without limits).
double LimitClearance(const Robot& robot, const std::vector<double>& q) {
  double clearance = std::numeric_limits<double>::infinity();
  for (size_t j = 0; j < q.size(); ++j) {
    const RobotRow& r = robot.joints[j];
    if (!r.HasLimits()) continue;
    clearance = std::min({clearance, q[j] - r.lower, r.upper - q[j]});
  }
  return clearance;
}

// Step 1: the controller's readings for the target. Without a seed, the
// first start that reaches it with max_correction of room to every limit
// (the compensation needs room to move), else the reached one with the most
// room, else the closest miss.
IkResult ControllerSolution(const Robot& robot, const Chain& nominal,
                            const CompensateTarget& t,
                            const std::vector<double>& previous,
                            const CompensateOptions& options) {
  IkOptions geometric = options.ik;
  geometric.use_error_model = false;
  if (!t.seed.empty()) {
    return SolveIk(nominal, t.target, t.seed, IkContext{}, geometric);
  }
  IkResult best;
  best.position_error_mm = std::numeric_limits<double>::infinity();
  double best_clearance = -std::numeric_limits<double>::infinity();
  for (const auto& start :
       StartCandidates(robot, previous, options.start, options.seed)) {
    IkResult r = SolveIk(nominal, t.target, start, IkContext{}, geometric);
    if (r.reached) {
      const double clearance = LimitClearance(robot, r.q);
      if (clearance >= options.max_correction) return r;
      if (!best.reached || clearance > best_clearance) {
        best = r;
        best_clearance = clearance;
      }
    } else if (!best.reached && r.position_error_mm < best.position_error_mm) {
      best = r;
    }
  }
  return best;
}

// Step 2: the readings through the whole model, from q_nom, with the
// approach directions of the move from the previous command.
IkResult ModelSolution(const Chain& chain, const CompensateTarget& t,
                       const std::vector<double>& q_nom,
                       const std::vector<double>& previous,
                       const std::vector<double>& previous_s,
                       IkContext* context, const IkOptions& options) {
  IkResult r;
  std::vector<double> guess = q_nom;
  for (int round = 0; round < 4; ++round) {
    context->s = ApproachDirections(previous, guess, previous_s);
    r = SolveIk(chain, t.target, guess, *context, options);
    const std::vector<double> s = ApproachDirections(previous, r.q, previous_s);
    if (s == context->s) break;
    guess = r.q;
  }
  return r;
}

// Step 5: reasons why the model extrapolates at q (reading units).
std::vector<std::string> Extrapolation(const Robot& robot,
                                       const std::vector<double>& q,
                                       double temp_c) {
  std::vector<std::string> out;
  const FitRecord& rec = robot.fitted_on;
  for (size_t j = 0; j < rec.joint_range.size() && j < q.size(); ++j) {
    const auto& range = rec.joint_range[j];
    if (!(range[0] == range[0])) continue;
    const double slack = 1e-9 * std::max(1.0, std::abs(q[j]));
    if (q[j] < range[0] - slack || q[j] > range[1] + slack) {
      out.push_back(robot.joints[j].name + " at " + FormatFixed(q[j], 3) +
                    " outside the fitted travel [" + FormatFixed(range[0], 3) +
                    ", " + FormatFixed(range[1], 3) + "]");
    }
  }
  for (size_t j = 0; j < rec.joint_gap.size() && j < q.size(); ++j) {
    const auto& gap = rec.joint_gap[j];
    if (gap[0] == gap[0] && q[j] > gap[0] && q[j] < gap[1]) {
      out.push_back(robot.joints[j].name + " at " + FormatFixed(q[j], 3) +
                    " inside a gap of the fitted readings (" +
                    FormatFixed(gap[0], 3) + " .. " + FormatFixed(gap[1], 3) +
                    ")");
    }
  }
  if (rec.temp_lo_c == rec.temp_lo_c && temp_c == temp_c &&
      (temp_c < rec.temp_lo_c || temp_c > rec.temp_hi_c)) {
    out.push_back("temperature " + FormatFixed(temp_c, 2) +
                  " C outside the fitted range [" +
                  FormatFixed(rec.temp_lo_c, 2) + ", " +
                  FormatFixed(rec.temp_hi_c, 2) +
                  "] (the thermal terms are held at its end)");
  }
  return out;
}

// Warnings about what the robot file cannot tell.
void WarnAboutTheModel(const Robot& robot, const Chain& chain,
                       Warnings* warnings) {
  if (!robot.HasNominal()) {
    warnings->Add("no_nominal_rows",
                  "the robot file records no nominal rows (nominal:): the "
                  "controller's kinematics are taken as the calibrated "
                  "geometry without extensions, so 'uncompensated' errors "
                  "show the extensions only; write the file with a current "
                  "calibrate / diagnose to record them");
  }
  if (robot.fitted_on.covariance_params.empty()) {
    warnings->Add("no_covariance",
                  "the robot file carries no covariance: the predicted "
                  "error is the inverse kinematics' residual alone, not "
                  "the model's uncertainty");
  }
  if (!robot.fitted_on.present()) {
    warnings->Add("no_fit_record",
                  "the robot file records no fitted_on: travel and "
                  "temperature ranges are not checked for extrapolation");
  }
  bool hours = chain.drift[kDriftX] != 0 || chain.drift[kDriftY] != 0 ||
               chain.drift[kDriftZ] != 0;
  for (const auto& e : chain.joint_errors) {
    hours =
        hours || (e[kThermal] != 0 && robot.fitted_on.thermal_input == "hours");
  }
  if (hours) {
    warnings->Add("time_terms_at_start",
                  "the model has terms in time (drift, thermal per hour): "
                  "they describe the measuring session and are compensated "
                  "at its start (t = 0)");
  }
}

// The recorded measuring frames as a state's frame blocks (rad, mm): one, or
// one per series with their labels so the covariance's frame.<series>.*
// resolve.
void SetRecordedFrames(const FitRecord& rec, ModelState* state) {
  auto block = [](const std::array<double, 6>& deg_mm) {
    std::array<double, kFrameBlockSize> b = deg_mm;
    for (int k = 0; k < 3; ++k) b[k] *= M_PI / 180.0;
    return b;
  };
  state->meas_from_base = block(rec.frame);
  state->more_frames.clear();
  state->frame_series.clear();
  if (rec.series_frames.size() < 2) return;
  state->meas_from_base = block(rec.series_frames[0].second);
  for (size_t i = 0; i < rec.series_frames.size(); ++i) {
    state->frame_series.push_back(rec.series_frames[i].first);
    if (i > 0) state->more_frames.push_back(block(rec.series_frames[i].second));
  }
}

// A target given in measuring frame `frame` of `state`, in the base frame.
IkTarget FromMeasuringFrame(const ModelState& state, int frame,
                            const IkTarget& t) {
  const Rigid3 base_from_meas =
      Rigid3FromPoseBlock(state.FrameBlock(frame)).Inverse();
  IkTarget out = t;
  out.position_mm = base_from_meas * t.position_mm;
  out.rotation = base_from_meas.R * t.rotation;
  return out;
}

// Targets in the measuring frame of a model fitted on several series, with
// no series named: the first series' frame is used, and said.
void WarnAboutTheFrame(const FitRecord& rec, const CompensateOptions& options,
                       Warnings* warnings) {
  if (!options.targets_in_measuring_frame || !options.series.empty() ||
      rec.series_frames.size() < 2) {
    return;
  }
  std::string others;
  for (size_t i = 1; i < rec.series_frames.size(); ++i) {
    others += (i > 1 ? ", " : "") + rec.series_frames[i].first;
  }
  warnings->Add("series_frame_assumed",
                "the model was fitted on several series, each with its own "
                "measuring frame: the targets are taken in series " +
                    rec.series_frames[0].first + "'s frame (others: " + others +
                    "); name the instrument's series with --series");
}

// The target of a joint program row: the nominal kinematics at its readings
// (orientation too for arms with six or more joints).
IkTarget ProgramTarget(const Chain& nominal, const std::vector<double>& q) {
  const Eigen::Matrix4d pose = ModelPoseAtReadings(nominal, q, {}, false);
  IkTarget t;
  t.position_mm = pose.block<3, 1>(0, 3);
  t.has_rotation = nominal.num_joints() >= 6;
  t.rotation = pose.block<3, 3>(0, 0);
  return t;
}

// Steps 3-5 for one solved target.
void Judge(const Robot& robot, const TipUncertainty& uncertainty,
           const IkContext& context, const IkResult& ik, double temp_c,
           const CompensateOptions& options, CompensatedTarget* out) {
  out->q = ik.q;
  out->residual_mm = ik.position_error_mm;
  out->rotation_residual_deg = ik.rotation_error_deg;
  double largest = 0.0;
  std::string joint;
  for (size_t j = 0; j < ik.q.size(); ++j) {
    const double d = std::abs(ik.q[j] - out->q_nom[j]);
    if (d > largest) {
      largest = d;
      joint = robot.joints[j].name;
    }
  }
  if (!ik.reached) {
    out->why = ik.at_limit.empty()
                   ? "the model's inverse kinematics does not reach it "
                     "(residual " +
                         FormatFixed(ik.position_error_mm, 4) + " mm)"
                   : "a joint limit stops it (" + ik.at_limit[0] + ")";
  } else if (largest > options.max_correction) {
    out->why =
        "the compensated readings leave the configuration of the "
        "controller's solution (" +
        joint + " moves " + FormatFixed(largest, 2) + ")";
  } else {
    out->reached = true;
  }
  out->extrapolated = Extrapolation(robot, ik.q, temp_c);
  out->sigma_mm = uncertainty.SigmaMm(ik.q, context);
  const double systematic = robot.fitted_on.systematic_rms_mm;
  if (out->sigma_mm == out->sigma_mm && systematic == systematic) {
    out->sigma_mm = std::hypot(out->sigma_mm, systematic);
  }
  out->predicted_mm = out->sigma_mm == out->sigma_mm
                          ? std::hypot(out->residual_mm, out->sigma_mm)
                          : out->residual_mm;
}

}  // namespace

int SeriesFrameIndex(const FitRecord& rec, const std::string& series) {
  if (series.empty() || rec.series_frames.size() < 2) return 0;
  std::string known;
  for (size_t i = 0; i < rec.series_frames.size(); ++i) {
    if (rec.series_frames[i].first == series) return static_cast<int>(i);
    known += (i ? ", " : "") + rec.series_frames[i].first;
  }
  throw InputError("--series " + series +
                   ": the model was fitted on the series " + known +
                   "; the targets' frame must be one of them");
}

TipUncertainty::TipUncertainty(const Robot& robot, const Chain& chain,
                               const std::string& series)
    : covariance_(&robot.fitted_on.covariance),
      frame_(SeriesFrameIndex(robot.fitted_on, series)) {
  const FitRecord& rec = robot.fitted_on;
  state_.chain = chain;
  // A periodic transmission's covariance names the fitted functions'
  // coefficients: the row takes their basis back (same prediction).
  ApplyPeriodicBases(rec, &state_.chain);
  SetRecordedFrames(rec, &state_);
  // The tip in the measuring frame when the covariance carries the frame:
  // the frame's correlation with the robot's parameters takes out what the
  // registration absorbs (targets are located through the instrument).
  for (const std::string& name : rec.covariance_params) {
    in_measuring_frame_ = in_measuring_frame_ || name.rfind("frame.", 0) == 0;
    params_.push_back(FindParam(state_, name));
  }
  if (in_measuring_frame_ && !rec.has_frame) {
    throw InputError(
        "covariance: names frame parameters but fitted_on has "
        "no frame");
  }
}

double TipUncertainty::SigmaMm(const std::vector<double>& q,
                               const IkContext& context) const {
  const int p = static_cast<int>(params_.size());
  if (p == 0) return kNaN;
  ModelState state = state_;
  auto tip = [&] {
    const Eigen::Vector3d b =
        ModelPoseAtReadings(state.chain, q, context).block<3, 1>(0, 3);
    return in_measuring_frame_ ? Eigen::Vector3d(ApplyFrame(
                                     state.FrameBlock(frame_), Vec3<double>(b)))
                               : b;
  };
  Eigen::MatrixXd jac(3, p);
  for (int k = 0; k < p; ++k) {
    double* value = ParamAddress(&state, params_[k]);
    const double v0 = *value;
    // A step of 1e-4 interface units (mm, deg, the families' units).
    const double h = params_[k].FromInterface(1e-4);
    *value = v0 + h;
    const Eigen::Vector3d plus = tip();
    *value = v0 - h;
    const Eigen::Vector3d minus = tip();
    *value = v0;
    jac.col(k) = (plus - minus) / 2e-4;
  }
  const double variance = (jac * *covariance_ * jac.transpose()).trace();
  return std::sqrt(std::max(0.0, variance));
}

CompensateResult Compensate(const Robot& robot,
                            const std::vector<CompensateTarget>& targets,
                            const CompensateOptions& options_in) {
  CompensateOptions options = options_in;
  if (options.ik.limits.empty()) options.ik.limits = JointLimits(robot);
  const Chain chain = Chain::FromRobot(robot);
  const Chain nominal = NominalChain(robot);
  const TipUncertainty uncertainty(robot, chain, options.series);
  if (options.targets_in_measuring_frame && !robot.fitted_on.has_frame) {
    throw InputError(
        "targets in the measuring frame: the robot file records no frame "
        "(fitted_on.frame); calibrate or diagnose it with a current kincal, "
        "or give the targets in the base frame");
  }
  CompensateResult result;
  WarnAboutTheFrame(robot.fitted_on, options, &result.warnings);
  WarnAboutTheModel(robot, chain, &result.warnings);
  std::vector<double> previous = options.start, previous_s;
  std::vector<double> previous_nom = options.start;
  double sum_sq = 0.0, sum_sq_nom = 0.0;
  int count_nom = 0;
  for (const CompensateTarget& t : targets) {
    CompensatedTarget out;
    out.id = t.id;
    const double temp_c = t.temp_c == t.temp_c ? t.temp_c : options.temp_c;
    IkContext context = ContextFor(robot, chain, temp_c, t.id);
    CompensateTarget target = t;
    IkResult controller;
    if (options.targets_in_measuring_frame && !t.from_joints) {
      target.target = FromMeasuringFrame(uncertainty.recorded_frames(),
                                         uncertainty.frame_index(), t.target);
    }
    if (t.from_joints) {
      target.target = ProgramTarget(nominal, t.seed);
      controller.reached = true;
      controller.q = t.seed;
    } else {
      controller =
          ControllerSolution(robot, nominal, target, previous_nom, options);
    }
    out.q_nom = controller.q;
    if (!controller.reached) {
      out.q = controller.q;
      out.residual_mm = controller.position_error_mm;
      out.why = "the nominal kinematics do not reach it (residual " +
                FormatFixed(controller.position_error_mm, 3) + " mm" +
                (controller.at_limit.empty()
                     ? ""
                     : ", limit of " + controller.at_limit[0]) +
                ")";
      result.targets.push_back(out);
      continue;
    }
    previous_nom = controller.q;
    const IkResult ik = ModelSolution(chain, target, controller.q, previous,
                                      previous_s, &context, options.ik);
    Judge(robot, uncertainty, context, ik, temp_c, options, &out);
    // What commanding the controller's readings would miss by.
    IkContext nominal_context = context;
    nominal_context.s = ApproachDirections(previous, controller.q, previous_s);
    out.uncompensated_mm =
        (ModelPoseAtReadings(chain, controller.q, nominal_context)
             .block<3, 1>(0, 3) -
         target.target.position_mm)
            .norm();
    if (out.reached) {
      previous = out.q;
      previous_s = context.s;
      ++result.reached;
      sum_sq += out.predicted_mm * out.predicted_mm;
      result.predicted_max_mm =
          std::max(result.predicted_max_mm, out.predicted_mm);
      sum_sq_nom += out.uncompensated_mm * out.uncompensated_mm;
      ++count_nom;
    }
    result.targets.push_back(out);
  }
  int extrapolated = 0;
  for (const CompensatedTarget& t : result.targets) {
    extrapolated += t.extrapolated.empty() ? 0 : 1;
  }
  if (extrapolated > 0) {
    result.warnings.Add(
        "targets_extrapolated",
        std::to_string(extrapolated) + " of " +
            std::to_string(result.targets.size()) +
            " targets lie outside the travel or temperature the model was "
            "fitted on: their predicted sigma covers the parameters' "
            "uncertainty, not the model's error where it has no data; "
            "measure there to know it (`extrapolated` per target)");
  }
  if (result.reached > 0) {
    result.predicted_rms_mm = std::sqrt(sum_sq / result.reached);
    result.uncompensated_rms_mm = std::sqrt(sum_sq_nom / count_nom);
  }
  return result;
}

}  // namespace kincal
