#include "calib/calibrate.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <map>
#include <set>
#include <stdexcept>
#include <utility>

#include "calib/fit_record.h"
#include "calib/free_fit.h"
#include "calib/holdout.h"
#include "calib/paper_method.h"
#include "data/error.h"

namespace kincal {

std::vector<double> CentroidDistances(const ModelState& state,
                                      const std::vector<Measurement>& ms) {
  std::map<int, std::vector<Eigen::Vector3d>> tips;
  for (const Measurement& m : ms) {
    if (m.kind == Measurement::kFixedPoint) {
      tips[m.point].push_back(TipInBase(state.chain, m.input));
    }
  }
  std::vector<double> out;
  for (const auto& kv : tips) {
    Eigen::Vector3d c = Eigen::Vector3d::Zero();
    for (const auto& p : kv.second) c += p;
    c /= static_cast<double>(kv.second.size());
    for (const auto& p : kv.second) out.push_back((p - c).norm());
  }
  return out;
}

namespace {

// --free NAME: a parameter (j2.beta), or a joint-error family without a
// joint (compliance, gain, ...): that entry of every joint.
std::vector<ParamInfo> ExtraParams(const ModelState& state,
                                   const std::string& name) {
  if (name.find('.') == std::string::npos) {
    std::vector<ParamInfo> out;
    for (int j = 0; j < state.chain.num_joints(); ++j) {
      for (int k = 0; k < kJointErrorBlockSize; ++k) {
        const ParamInfo p = JointErrorParam(state.chain, j, k);
        if (p.name == state.chain.rows[j].name + "." + name) out.push_back(p);
      }
    }
    if (!out.empty()) return out;
  }
  return {FindParam(state, name)};
}

// Largest |input| over the measurements that multiplies a joint-error
// parameter into its joint's angle (or travel): the gravity torque for
// compliance and elastostatic, the reading for gain, 1 for the others (they
// are angles themselves). 0 for the thermal family (not an angle).
double JointErrorLever(const std::vector<Measurement>& ms, const ParamInfo& p) {
  if (p.index == kThermal) return 0.0;
  double lever = 0.0;
  for (const Measurement& m : ms) {
    const PoseInput& in = m.input;
    const size_t j = static_cast<size_t>(p.block);
    double x = 1.0;
    if (p.index == kCompliance) x = j < in.tau.size() ? in.tau[j] : 0.0;
    if (p.index == kElastostatic)
      x = j < in.tau_mass.size() ? in.tau_mass[j] : 0.0;
    if (p.index == kGain) x = j < in.q.size() ? in.q[j] : 0.0;
    lever = std::max(lever, std::abs(x));
  }
  return lever;
}

// The identifiability test holds a geometry parameter whose predicted
// 1-sigma exceeds max_sigma_fraction of its bound; a joint-error parameter
// has no bound of its own, so judge what it does: its 1-sigma times the
// largest input it multiplies, against the same fraction of the angle (or
// length) bound. Without this a Panda's joint-7 compliance (the ball ~7 mm
// from the axis, so almost no torque) was fitted to 3.4 +- 4.5 deg/mm and
// the predictions on other recordings went from 0.27 to 1.24 mm.
void HoldWeakJointErrors(const std::vector<Measurement>& ms,
                         const ModelState& state,
                         const IdentifiabilityOptions& options,
                         Identifiability* id) {
  if (!(options.noise_sigma_mm > 0)) return;
  // The largest lever of each family over the joints: a joint whose input
  // stays below a tenth of it (a Panda's joint 7 carries a torque arm of
  // the ball's 7 mm offset, joint 2 of ~600 mm) sees too little of the
  // cause to tell it from the geometry it shares the tip motion with.
  std::map<int, double> family_lever;
  for (const ParamInfo& p : id->identifiable) {
    if (p.kind != ParamKind::kJointError) continue;
    family_lever[p.index] =
        std::max(family_lever[p.index], JointErrorLever(ms, p));
  }
  Identifiability kept = *id;
  kept.identifiable.clear();
  kept.conditional_sigma.clear();
  for (size_t i = 0; i < id->identifiable.size(); ++i) {
    const ParamInfo& p = id->identifiable[i];
    bool keep = true;
    if (p.kind == ParamKind::kJointError && i < id->conditional_sigma.size()) {
      const bool revolute =
          state.chain.rows.at(p.block).type == JointType::kRevolute;
      const double sigma =
          id->conditional_sigma[i] * (p.angle ? M_PI / 180 : 1);
      const double bound =
          revolute ? state.chain.bound_angle_rad : state.chain.bound_length_mm;
      const double lever = JointErrorLever(ms, p);
      const double effect = sigma * lever;
      keep = !(effect >= options.max_sigma_fraction * bound) &&
             lever >= 0.1 * family_lever[p.index];
    }
    if (keep) {
      kept.identifiable.push_back(p);
      if (i < id->conditional_sigma.size())
        kept.conditional_sigma.push_back(id->conditional_sigma[i]);
    } else {
      kept.unidentifiable.push_back(p);
    }
  }
  *id = kept;
}

std::vector<double> Norms(const ModelState& state,
                          const std::vector<Measurement>& ms) {
  std::vector<double> out;
  for (const Measurement& m : ms) out.push_back(Residual(state, m).norm());
  return out;
}

// Calibrate's geometry fit in its steps (FitGeometry): the first look, the
// passes of fit -> identifiability at the solution, the bounds widened
// where the data press against them, the final refit.
class GeometryFitRun {
 public:
  GeometryFitRun(const GeometryProblem& problem,
                 const CalibrateOptions& options, ModelState* state)
      : problem_(problem),
        options_(options),
        state_(state),
        train_(*problem.train),
        nominal_(*problem.nominal) {
    joint_errors_ = std::any_of(
        problem.candidates.begin(), problem.candidates.end(),
        [](const ParamInfo& p) { return p.kind == ParamKind::kJointError; });
  }

  GeometryFit Run() {
    FirstLook();
    InitFitOptions();
    g_.fit = LeastSquares(g_.identifiability.identifiable);
    IdentifiabilityPass pass;
    pass.num_free = static_cast<int>(g_.identifiability.identifiable.size());
    pass.train_rms_mm = g_.fit.final_rms_mm;
    g_.passes.push_back(pass);
    g_.first_set = NamesOf(g_.identifiability.identifiable);
    seen_ = {g_.first_set};
    if (options_.fit_geometry) RunPasses();
    if (options_.fit_geometry && options_.method != CalibrateOptions::kPaper &&
        !problem_.bounds_stated && WidenPressedBounds()) {
      RunPasses();  // the free set where the widened fit ended
    }
    // The inputs of the final fit from the geometry it starts at, so that
    // the calibrated model (whose `evaluate` computes them from its own
    // geometry) predicts what was fitted.
    if (joint_errors_ && options_.method != CalibrateOptions::kPaper) {
      RefreshInputs();
      g_.fit = LeastSquares(g_.identifiability.identifiable);
    }
    for (const ParamInfo& p : Pressed()) g_.at_bound.push_back(p.name);
    g_.fit_options = fit_;
    g_.fit_options.bounds_center = nullptr;  // the caller's nominal chain
    return g_;
  }

 private:
  static std::set<std::string> NamesOf(const std::vector<ParamInfo>& ps) {
    std::set<std::string> out;
    for (const ParamInfo& p : ps) out.insert(p.name);
    return out;
  }

  // First look, at the start values: structural redundancy (the sine test)
  // and, with a noise level of a fraction of the registered misfit, the
  // parameters so weakly determined that a first fit would send them
  // across the admissible range (a Panda's joint-7 tilt with single-point
  // data) and into another minimum.
  void FirstLook() {
    IdentifiabilityOptions first_look = options_.identifiability;
    if (options_.fit_geometry && options_.first_look_noise_fraction > 0 &&
        first_look.noise_sigma_mm <= 0) {
      first_look.noise_sigma_mm =
          options_.first_look_noise_fraction * problem_.registered_sigma0_mm;
    }
    g_.identifiability = AnalyzeIdentifiability(
        train_, *state_, problem_.candidates, first_look, problem_.distances);
    HoldWeakJointErrors(train_, *state_, first_look, &g_.identifiability);
    if (problem_.check) problem_.check(g_.identifiability);
  }

  void InitFitOptions() {
    fit_.bounds_center = &nominal_;
    fit_.loss = options_.loss;
    fit_.loss_scale_mm = options_.loss_scale_mm;
    fit_.distances = problem_.distances;
    fit_.num_threads = options_.num_threads;
    // The automatic ridge: on for single-point data only.
    const bool measured = std::any_of(
        train_.begin(), train_.end(),
        [](const Measurement& m) { return m.kind == Measurement::kMeasured; });
    fit_.prior_weight = options_.prior_weight >= 0 ? options_.prior_weight
                        : measured                 ? 0.0
                                                   : 1.0;
    g_.prior_weight = fit_.prior_weight;
  }

  // Least squares for the passes (the seed's eq. (9), --method paper, runs
  // once on the final set, in Calibrate), by the problem's solver.
  FitSummary LeastSquares(const std::vector<ParamInfo>& free) {
    fit_.free = free;
    if (problem_.solver == GeometrySolver::kExactJacobian)
      return FreeFitWithCovariance(train_, FreeFitOptionsFrom(fit_), state_);
    return Fit(train_, fit_, state_);
  }

  // Joint-error families multiply inputs computed from the geometry (the
  // gravity torque of compliance and elastostatic): computed from the
  // nominal model at first, they are recomputed from the fitted one before
  // each pass. A tool offset the nominal model lacks (the MUKCa ball sits
  // 7 mm off the flange axis, the nominal one on it) otherwise leaves joint
  // 7's torque ~0 in the fit and ~5 mm in every prediction (docs/
  // CALIBRATION.md).
  void RefreshInputs() {
    const std::vector<PoseInput> inputs =
        MakePoseInputs(state_->chain, *problem_.obs);
    for (Measurement& m : train_) m.input = inputs[m.row];
    if (problem_.held != nullptr)
      for (Measurement& m : *problem_.held) m.input = inputs[m.row];
  }

  // Identifiability at the solution, not at the guess: a nominal model with
  // exactly perpendicular or parallel axes hides parameters that the real
  // robot's data determine (and the reverse), so decide the free set again
  // where the model fits, with the noise level the fit found, refit from
  // there, and repeat until the set is stable. A parameter that leaves the
  // set keeps its value (a jump back to nominal would throw away the fit
  // and can land LM in another minimum) and may come back in a later pass.
  // A pass whose fit ends worse than the one before is undone.
  void RunPasses() {
    for (int k = 1; k < options_.max_identifiability_passes; ++k) {
      if (!(g_.fit.sigma0_mm > 0)) break;
      if (joint_errors_) RefreshInputs();
      IdentifiabilityOptions at = options_.identifiability;
      at.noise_sigma_mm = g_.fit.sigma0_mm;
      Identifiability next = AnalyzeIdentifiability(
          train_, *state_, problem_.candidates, at, problem_.distances);
      HoldWeakJointErrors(train_, *state_, at, &next);
      const std::set<std::string> now =
          NamesOf(g_.identifiability.identifiable);
      const std::set<std::string> then = NamesOf(next.identifiable);
      if (then == now) {
        g_.identifiability = next;
        break;
      }
      IdentifiabilityPass pass;
      for (const ParamInfo& p : next.identifiable)
        if (!now.count(p.name)) pass.freed.push_back(p.name);
      for (const ParamInfo& p : g_.identifiability.identifiable)
        if (!then.count(p.name)) pass.held.push_back(p.name);
      const bool cycle =
          std::find(seen_.begin(), seen_.end(), then) != seen_.end();
      seen_.push_back(then);
      const ModelState before_state = *state_;
      const FitSummary before_fit = g_.fit;
      FitSummary refit = LeastSquares(next.identifiable);
      pass.num_free = static_cast<int>(next.identifiable.size());
      pass.train_rms_mm = refit.final_rms_mm;
      if (!(refit.final_rms_mm <=
            before_fit.final_rms_mm * (1 + 1e-6) + 1e-9)) {
        pass.undone = true;
        g_.passes.push_back(pass);
        *state_ = before_state;
        g_.fit = before_fit;
        break;
      }
      g_.passes.push_back(pass);
      g_.identifiability = next;
      g_.fit = refit;
      if (cycle) break;  // a set seen before: stop on this fit
    }
  }

  // Free row parameters that end on their bound.
  std::vector<ParamInfo> Pressed() const {
    std::vector<ParamInfo> out;
    for (const ParamInfo& p : g_.fit.params) {
      if (p.kind != ParamKind::kRow) continue;
      const double bound = RowBound(nominal_, p, fit_);
      const double center = nominal_.rows.at(p.block).p.at(p.index);
      const double deviation = std::abs(ParamValue(*state_, p) - center);
      if (deviation >= bound * (1 - 1e-6)) out.push_back(p);
    }
    return out;
  }

  // Bounds the data press against. Bounds the robot file does not state
  // (a URDF's 20 mm / 10 deg, a robot.yaml without `bounds:`) are a guess
  // that keeps weakly determined parameters from wandering into another
  // minimum, not knowledge of the robot. A free parameter (determined, by
  // the identifiability test) that ends on such a bound says the robot
  // deviates from its nominal model by more than the guess (a tool or a
  // joint origin 30 mm from its nominal place; measured: a simulated Panda
  // with 10 mm / 3 deg deviations stopped at 5.04 mm RMS with two origins
  // on the 20 mm bound, 0.050 mm after widening). Its bound is doubled and
  // the fit repeated, kept when it fits better by more than 1 %; at most
  // kMaxWidenings doublings, angles up to 180 deg. Stated bounds (the
  // seed's |x - t0| <= delta) are kept; parameters on them are reported.
  // True when a widened fit was kept.
  bool WidenPressedBounds() {
    constexpr int kMaxWidenings = 4;
    bool widened_any = false;
    for (int round = 0; round < kMaxWidenings; ++round) {
      const ModelState before_state = *state_;
      const FitSummary before_fit = g_.fit;
      const std::map<std::string, double> before_bounds = fit_.bound_override;
      std::vector<WidenedBound> widened;
      for (const ParamInfo& p : Pressed()) {
        const double from = RowBound(nominal_, p, fit_);
        const double to = p.angle ? std::min(2 * from, M_PI) : 2 * from;
        if (!(to > from)) continue;
        fit_.bound_override[p.name] = to;
        widened.push_back({p.name, p.ToInterface(from), p.ToInterface(to)});
      }
      if (widened.empty()) break;
      FitSummary refit = LeastSquares(g_.identifiability.identifiable);
      if (!(refit.final_rms_mm < 0.99 * before_fit.final_rms_mm)) {
        *state_ = before_state;
        g_.fit = before_fit;
        fit_.bound_override = before_bounds;
        break;
      }
      g_.fit = refit;
      g_.widened_bounds.insert(g_.widened_bounds.end(), widened.begin(),
                               widened.end());
      widened_any = true;
    }
    return widened_any;
  }

  const GeometryProblem& problem_;
  const CalibrateOptions& options_;
  ModelState* state_;
  std::vector<Measurement>& train_;
  const Chain& nominal_;
  bool joint_errors_ = false;
  FitOptions fit_;
  GeometryFit g_;
  std::vector<std::set<std::string>> seen_;
};

}  // namespace

GeometryFit FitGeometry(const GeometryProblem& problem,
                        const CalibrateOptions& options, ModelState* state) {
  return GeometryFitRun(problem, options, state).Run();
}

namespace {

// Rounds of fit -> flag gross errors -> refit without them.
constexpr int kMaxOutlierRounds = 6;

// One calibration of `train` from the nominal model (state on entry: the
// nominal chain and the fixed points' labels): register the frame / points,
// fit the geometry (FitGeometry) or the seed's objective. `others` get their
// joint-error inputs from the fitted geometry.
void CalibrateOn(const Observations& obs, const Chain& nominal_chain,
                 bool bounds_stated, int distinct,
                 const std::vector<PointDistance>& distances,
                 const CalibrateOptions& options,
                 std::vector<Measurement>* train_rows,
                 std::vector<Measurement>* others, CalibrateResult* out) {
  CalibrateResult& result = *out;
  ModelState& state = result.state;
  std::vector<Measurement>& train = *train_rows;
  result.freed.clear();
  result.held.clear();
  InitializeFrameAndPoints(train, &state);

  const bool any_measured = std::any_of(
      train.begin(), train.end(),
      [](const Measurement& m) { return m.kind == Measurement::kMeasured; });
  std::vector<ParamInfo> nuisance;  // frame and fixed points
  if (any_measured) nuisance = AllFrameParams(state);
  for (const ParamInfo& p : PointParams(state)) nuisance.push_back(p);

  // Frame / points alone first: a good start for the full fit.
  FitOptions frame_only;
  frame_only.free = nuisance;
  frame_only.compute_covariance = false;
  frame_only.distances = distances;
  const FitSummary registered = Fit(train, frame_only, &state);

  std::vector<ParamInfo> candidates = nuisance;
  if (options.fit_geometry) {
    for (const ParamInfo& p : GeometryParams(state.chain))
      candidates.push_back(p);
    for (const std::string& name : options.extra_params) {
      for (const ParamInfo& p : ExtraParams(state, name))
        candidates.push_back(p);
    }
  }
  auto check = [&](const Identifiability& id) {
    const int robot_params = id.RobotParameterCount();
    if (options.fit_geometry && robot_params == 0) {
      throw InputError(obs.source, 0, 0,
                       "the data determine no robot parameter (" +
                           std::to_string(distinct) +
                           " distinct poses): use more poses that differ in "
                           "every joint");
    }
    const int num_free = static_cast<int>(id.identifiable.size());
    const int num_residuals =
        3 * static_cast<int>(train.size()) + static_cast<int>(distances.size());
    if (num_residuals <= num_free) {
      throw InputError(obs.source, 0, 0,
                       "too few poses: " + std::to_string(train.size()) +
                           " training poses give " +
                           std::to_string(num_residuals) + " equations for " +
                           std::to_string(num_free) +
                           " identifiable parameters; need at least " +
                           std::to_string(num_free / 3 + 1) +
                           " distinct training poses (more for a useful fit)");
    }
  };
  GeometryProblem problem;
  problem.obs = &obs;
  problem.nominal = &nominal_chain;
  problem.bounds_stated = bounds_stated;
  problem.candidates = candidates;
  problem.registered_sigma0_mm = registered.sigma0_mm;
  problem.distances = distances;
  problem.train = &train;
  problem.held = others;
  problem.check = check;
  GeometryFit g = FitGeometry(problem, options, &state);
  result.identifiability = g.identifiability;
  result.passes = g.passes;
  result.fit = g.fit;
  result.widened_bounds = g.widened_bounds;
  result.prior_weight = g.prior_weight;
  result.at_bound = g.at_bound;
  auto names_of = [](const std::vector<ParamInfo>& ps) {
    std::set<std::string> out;
    for (const ParamInfo& p : ps) out.insert(p.name);
    return out;
  };
  const std::set<std::string>& first_set = g.first_set;
  const std::set<std::string> final_set =
      names_of(result.identifiability.identifiable);
  for (const std::string& n : final_set)
    if (!first_set.count(n)) result.freed.push_back(n);
  for (const std::string& n : first_set)
    if (!final_set.count(n)) result.held.push_back(n);
  if (options.method == CalibrateOptions::kPaper) {
    PaperOptions paper;
    for (const ParamInfo& p : result.identifiability.identifiable) {
      if (p.kind != ParamKind::kFrame && p.kind != ParamKind::kPoint) {
        paper.free.push_back(p);
      }
    }
    paper.bounds_center = &nominal_chain;
    paper.distances = distances;
    result.fit = FitPaperObjective(train, paper, &state);
  }
  if (!std::isfinite(result.fit.final_rms_mm)) {
    throw std::runtime_error(
        "the fit ended in a non-finite state (NaN or infinity): the data or "
        "the model carry values out of any physical range");
  }
}

// The known distances of options.distances between fixed points of `state`
// (InputError for a label the data lack).
std::vector<PointDistance> PointDistances(const CalibrateOptions& options,
                                          const ModelState& state,
                                          const Observations& obs) {
  std::vector<PointDistance> distances;
  for (const FixedDistance& d : options.distances) {
    PointDistance pd;
    pd.a = state.PointIndex(d.a);
    pd.b = state.PointIndex(d.b);
    if (pd.a < 0 || pd.b < 0) {
      throw InputError("--fixed-distance " + d.a + "," + d.b +
                       ": no fixed_point label '" + (pd.a < 0 ? d.a : d.b) +
                       "' in " + obs.source);
    }
    pd.distance_mm = d.distance_mm;
    pd.weight = options.distance_weight;
    distances.push_back(pd);
  }
  return distances;
}

// Held-out rows beyond the gross-error threshold (axis_sigma x options.
// outlier_sigmas under result->state) are listed in result->outliers and
// left out of the held-out figures, as the training ones; unless more than
// a quarter are (a model that predicts badly, not gross rows: all are kept,
// so the held-out figures cannot flatter it). Returns the rows kept.
std::vector<Measurement> HeldOutWithoutGross(
    const Observations& obs, const std::vector<Measurement>& held,
    double axis_sigma, const CalibrateOptions& options,
    CalibrateResult* result) {
  const ModelState& state = result->state;
  std::vector<Measurement> kept;
  const std::vector<double> norms = Norms(state, held);
  const std::vector<char> flags =
      FlagGross(norms, axis_sigma, options.outlier_sigmas);
  const size_t flagged = std::count(flags.begin(), flags.end(), 1);
  const bool leave_out = 4 * flagged <= held.size();
  for (size_t i = 0; i < held.size(); ++i) {
    if (!flags[i] || !leave_out) kept.push_back(held[i]);
    if (!flags[i]) continue;
    RowOutlier o =
        DescribeOutlier(state, held[i], obs.rows[held[i].row].pose, norms[i],
                        axis_sigma, options.outlier_sigmas);
    o.heldout = true;
    o.excluded = leave_out;
    result->outliers.push_back(o);
  }
  if (!leave_out) result->outliers_too_many = true;
  return kept;
}

}  // namespace

CalibrateResult Calibrate(const Robot& nominal, const Observations& obs,
                          const CalibrateOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  Require(options.holdout_fraction >= 0 && options.holdout_fraction < 0.9,
          "--holdout must be in [0, 0.9)");
  Require(options.distance_weight > 0 && std::isfinite(options.distance_weight),
          "--distance-weight must be positive and finite");
  CalibrateResult result;
  result.method =
      options.method == CalibrateOptions::kPaper ? "paper" : "least_squares";
  const Chain nominal_chain = Chain::FromRobot(nominal);
  ModelState& state = result.state;
  state.chain = nominal_chain;
  std::vector<Measurement> all = MakeMeasurements(nominal_chain, obs, &state);
  // One measuring frame per series, the robot shared.
  AssignSeriesFrames(obs, &all, &state);
  if (all.empty()) {
    throw InputError(obs.source, 0, 0,
                     "no row has a measured tip (x, y, z) or a fixed_point "
                     "label: nothing to calibrate against");
  }
  const int distinct = DistinctPoses(all);
  if (distinct < 2) {
    throw InputError(obs.source, 0, 0,
                     "all " + std::to_string(all.size()) +
                         " usable rows have the same joint readings: one pose "
                         "determines no robot parameter");
  }
  const std::vector<PointDistance> distances =
      PointDistances(options, state, obs);

  HoldoutSplit split =
      SplitHoldout(all, options.holdout_fraction, options.seed);
  result.train_rows = std::move(split.train);
  result.heldout_rows = std::move(split.heldout);
  const std::vector<Measurement> all_train = PickRows(all, result.train_rows);
  std::vector<Measurement> train, held;
  const ModelState initial = state;

  // Gross errors (calib/outliers.h): fit without the rows flagged, flag the
  // training rows beyond options.outlier_sigmas robust sigmas of the fitted
  // model, refit from the nominal model, until the flagged set is stable. A
  // row flagged in one round may come back in the next.
  // The first set from the nominal model with only the frame / points
  // registered (robustly: calib/outliers.h FindGrossErrors), at half the
  // threshold: the nominal model's own error widens the scale (MUKCa Panda:
  // 8.5 mm median, so a row saved under the socket 50 mm away is only ~9
  // sigma there; 550 after calibration). The rounds below readmit any row
  // the calibrated model fits.
  std::vector<char> excluded(all_train.size(), 0);
  if (options.outlier_sigmas > 0) {
    excluded =
        FindGrossErrors(initial, all_train, 0.5 * options.outlier_sigmas);
  }
  std::vector<double> train_norms;
  double axis_sigma = 0.0;
  for (int round = 1;; ++round) {
    result.outlier_rounds = round;
    state = initial;
    train.clear();
    // The rows out of the fit ride along with the held-out ones so that
    // their joint-error inputs follow the fitted geometry too.
    std::vector<Measurement> others = PickRows(all, result.heldout_rows);
    for (size_t i = 0; i < all_train.size(); ++i)
      (excluded[i] ? others : train).push_back(all_train[i]);
    CalibrateOn(obs, nominal_chain, nominal.bounds_stated, distinct, distances,
                options, &train, &others, &result);
    const size_t num_held = result.heldout_rows.size();
    held.assign(others.begin(), others.begin() + static_cast<long>(num_held));
    // Every training row's error under this round's model (the copies whose
    // inputs followed the fitted geometry: in `train`, or after the
    // held-out rows in `others`).
    train_norms.clear();
    for (size_t i = 0, t = 0, o = num_held; i < all_train.size(); ++i) {
      const Measurement& m = excluded[i] ? others[o++] : train[t++];
      train_norms.push_back(Residual(state, m).norm());
    }
    // The scale from the rows fitted, robust to those left in.
    axis_sigma = RobustAxisSigmaOfKeptMm(train_norms, excluded);
    const std::vector<char> flags =
        FlagGross(train_norms, axis_sigma, options.outlier_sigmas);
    if (flags == excluded) break;
    if (!CanExclude(all_train, flags)) {
      result.outliers_too_many = true;
      break;
    }
    if (round >= kMaxOutlierRounds) break;
    excluded = flags;
  }
  result.outlier_axis_sigma_mm = axis_sigma;
  const std::vector<char> gross =
      FlagGross(train_norms, axis_sigma, options.outlier_sigmas);
  for (size_t i = 0; i < all_train.size(); ++i) {
    if (!excluded[i] && !gross[i]) continue;
    RowOutlier o =
        DescribeOutlier(state, all_train[i], obs.rows[all_train[i].row].pose,
                        train_norms[i], axis_sigma, options.outlier_sigmas);
    o.excluded = excluded[i] != 0;
    result.outliers.push_back(o);
  }
  held = HeldOutWithoutGross(obs, held, axis_sigma, options, &result);
  result.train = ComputeErrorStats(Norms(state, train));
  result.heldout = ComputeErrorStats(Norms(state, held));
  for (size_t i = 0; i < distances.size(); ++i) {
    const auto& a = state.points_in_base[distances[i].a];
    const auto& b = state.points_in_base[distances[i].b];
    const double d = std::sqrt((a[0] - b[0]) * (a[0] - b[0]) +
                               (a[1] - b[1]) * (a[1] - b[1]) +
                               (a[2] - b[2]) * (a[2] - b[2]));
    result.distance_errors_mm.push_back(d - distances[i].distance_mm);
  }
  const std::vector<double> eps = CentroidDistances(state, train);
  if (!eps.empty()) {
    result.has_epsilon = true;
    result.epsilon = ComputeErrorStats(eps);
  }
  FitRecordInput record;
  record.obs = &obs;
  record.rows = result.train_rows;
  record.fit = &result.fit;
  record.state = &state;
  record.heldout_rms_mm =
      result.heldout.n > 0 ? result.heldout.rms_mm : result.train.rms_mm;
  result.calibrated =
      WithFitRecord(state.chain.ToRobot(nominal), nominal, record);
  result.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
          .count();
  return result;
}

}  // namespace kincal
