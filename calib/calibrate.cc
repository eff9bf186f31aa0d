#include "calib/calibrate.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <map>
#include <set>
#include <stdexcept>
#include <utility>

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

std::vector<Measurement> Pick(const std::vector<Measurement>& ms,
                              const std::vector<int>& idx) {
  std::vector<Measurement> out;
  for (int i : idx) out.push_back(ms[i]);
  return out;
}

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

}  // namespace

GeometryFit FitGeometry(
    const Observations& obs, const Chain& nominal_chain, bool bounds_stated,
    const std::vector<ParamInfo>& candidates, double registered_sigma0_mm,
    const std::vector<PointDistance>& distances,
    const CalibrateOptions& options,
    const std::function<void(const Identifiability&)>& check,
    std::vector<Measurement>* train, std::vector<Measurement>* held,
    ModelState* state, const GeometryFitter& fitter) {
  GeometryFit g;
  // First look, at the start values: structural redundancy (the sine test)
  // and, with a noise level of a fraction of the registered misfit, the
  // parameters so weakly determined that a first fit would send them
  // across the admissible range (a Panda's joint-7 tilt with single-point
  // data) and into another minimum.
  IdentifiabilityOptions first_look = options.identifiability;
  if (options.fit_geometry && options.first_look_noise_fraction > 0 &&
      first_look.noise_sigma_mm <= 0) {
    first_look.noise_sigma_mm =
        options.first_look_noise_fraction * registered_sigma0_mm;
  }
  g.identifiability =
      AnalyzeIdentifiability(*train, *state, candidates, first_look, distances);
  HoldWeakJointErrors(*train, *state, first_look, &g.identifiability);
  check(g.identifiability);
  const int num_free = static_cast<int>(g.identifiability.identifiable.size());
  FitOptions fit;
  fit.bounds_center = &nominal_chain;
  fit.loss = options.loss;
  fit.loss_scale_mm = options.loss_scale_mm;
  fit.distances = distances;
  // The automatic ridge: on for single-point data only.
  const bool measured = std::any_of(
      train->begin(), train->end(),
      [](const Measurement& m) { return m.kind == Measurement::kMeasured; });
  fit.prior_weight = options.prior_weight >= 0 ? options.prior_weight
                     : measured                ? 0.0
                                               : 1.0;
  g.prior_weight = fit.prior_weight;
  // Least squares for the passes (the seed's eq. (9), --method paper, runs
  // once on the final set, in Calibrate).
  auto lsq_fit = [&](const std::vector<ParamInfo>& free) {
    fit.free = free;
    return fitter ? fitter(*train, fit, state) : Fit(*train, fit, state);
  };
  // Joint-error families multiply inputs computed from the geometry (the
  // gravity torque of compliance and elastostatic): computed from the
  // nominal model at first, they are recomputed from the fitted one before
  // each pass. A tool offset the nominal model lacks (the MUKCa ball sits
  // 7 mm off the flange axis, the nominal one on it) otherwise leaves joint
  // 7's torque ~0 in the fit and ~5 mm in every prediction: measured 1.24 mm
  // held-out RMS instead of 0.25 on panda_4 with --free compliance.
  const bool joint_errors = std::any_of(
      candidates.begin(), candidates.end(),
      [](const ParamInfo& p) { return p.kind == ParamKind::kJointError; });
  auto refresh_inputs = [&]() {
    const std::vector<PoseInput> inputs = MakePoseInputs(state->chain, obs);
    for (Measurement& m : *train) m.input = inputs[m.row];
    if (held != nullptr)
      for (Measurement& m : *held) m.input = inputs[m.row];
  };
  auto names_of = [](const std::vector<ParamInfo>& ps) {
    std::set<std::string> out;
    for (const ParamInfo& p : ps) out.insert(p.name);
    return out;
  };
  g.fit = lsq_fit(g.identifiability.identifiable);
  {
    IdentifiabilityPass pass;
    pass.num_free = num_free;
    pass.train_rms_mm = g.fit.final_rms_mm;
    g.passes.push_back(pass);
  }

  // Identifiability at the solution, not at the guess: a nominal model with
  // exactly perpendicular or parallel axes hides parameters that the real
  // robot's data determine (and the reverse), so decide the free set again
  // where the model fits, with the noise level the fit found, refit from
  // there, and repeat until the set is stable. A parameter that leaves the
  // set keeps its value (a jump back to nominal would throw away the fit
  // and can land LM in another minimum) and may come back in a later pass.
  // A pass whose fit ends worse than the one before is undone.
  const std::set<std::string> first_set =
      names_of(g.identifiability.identifiable);
  std::vector<std::set<std::string>> seen = {first_set};
  auto run_passes = [&]() {
    for (int k = 1; k < options.max_identifiability_passes; ++k) {
      if (!(g.fit.sigma0_mm > 0)) break;
      if (joint_errors) refresh_inputs();
      IdentifiabilityOptions at = options.identifiability;
      at.noise_sigma_mm = g.fit.sigma0_mm;
      Identifiability next =
          AnalyzeIdentifiability(*train, *state, candidates, at, distances);
      HoldWeakJointErrors(*train, *state, at, &next);
      const std::set<std::string> now =
          names_of(g.identifiability.identifiable);
      const std::set<std::string> then = names_of(next.identifiable);
      if (then == now) {
        g.identifiability = next;
        break;
      }
      IdentifiabilityPass pass;
      for (const ParamInfo& p : next.identifiable)
        if (!now.count(p.name)) pass.freed.push_back(p.name);
      for (const ParamInfo& p : g.identifiability.identifiable)
        if (!then.count(p.name)) pass.held.push_back(p.name);
      const bool cycle =
          std::find(seen.begin(), seen.end(), then) != seen.end();
      seen.push_back(then);
      const ModelState before_state = *state;
      const FitSummary before_fit = g.fit;
      FitSummary refit = lsq_fit(next.identifiable);
      pass.num_free = static_cast<int>(next.identifiable.size());
      pass.train_rms_mm = refit.final_rms_mm;
      if (!(refit.final_rms_mm <=
            before_fit.final_rms_mm * (1 + 1e-6) + 1e-9)) {
        pass.undone = true;
        g.passes.push_back(pass);
        *state = before_state;
        g.fit = before_fit;
        break;
      }
      g.passes.push_back(pass);
      g.identifiability = next;
      g.fit = refit;
      if (cycle) break;  // a set seen before: stop on this fit
    }
  };
  if (options.fit_geometry) run_passes();

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
  auto pressed = [&]() {
    std::vector<ParamInfo> out;
    for (size_t i = 0; i < g.fit.params.size(); ++i) {
      const ParamInfo& p = g.fit.params[i];
      if (p.kind != ParamKind::kRow) continue;
      const double bound = RowBound(nominal_chain, p, fit);
      const double center = nominal_chain.rows.at(p.block).p.at(p.index);
      const double deviation = std::abs(ParamValue(*state, p) - center);
      if (deviation >= bound * (1 - 1e-6)) out.push_back(p);
    }
    return out;
  };
  if (options.fit_geometry && options.method != CalibrateOptions::kPaper &&
      !bounds_stated) {
    constexpr int kMaxWidenings = 4;
    bool widened_any = false;
    for (int round = 0; round < kMaxWidenings; ++round) {
      const ModelState before_state = *state;
      const FitSummary before_fit = g.fit;
      const std::map<std::string, double> before_bounds = fit.bound_override;
      std::vector<WidenedBound> widened;
      for (const ParamInfo& p : pressed()) {
        const double from = RowBound(nominal_chain, p, fit);
        const double to = p.angle ? std::min(2 * from, M_PI) : 2 * from;
        if (!(to > from)) continue;
        fit.bound_override[p.name] = to;
        widened.push_back({p.name, p.ToInterface(from), p.ToInterface(to)});
      }
      if (widened.empty()) break;
      FitSummary refit = lsq_fit(g.identifiability.identifiable);
      if (!(refit.final_rms_mm < 0.99 * before_fit.final_rms_mm)) {
        *state = before_state;
        g.fit = before_fit;
        fit.bound_override = before_bounds;
        break;
      }
      g.fit = refit;
      g.widened_bounds.insert(g.widened_bounds.end(), widened.begin(),
                              widened.end());
      widened_any = true;
    }
    // The free set where the widened fit ended.
    if (widened_any) run_passes();
  }

  // The inputs of the final fit from the geometry it starts at, so that the
  // calibrated model (whose `evaluate` computes them from its own geometry)
  // predicts what was fitted.
  if (joint_errors && options.method != CalibrateOptions::kPaper) {
    refresh_inputs();
    g.fit = lsq_fit(g.identifiability.identifiable);
  }
  for (const ParamInfo& p : pressed()) g.at_bound.push_back(p.name);
  g.first_set = first_set;
  g.fit_options = fit;
  g.fit_options.bounds_center = nullptr;  // the caller's nominal chain
  return g;
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
  if (any_measured) nuisance = FrameParams();
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
  GeometryFit g = FitGeometry(obs, nominal_chain, bounds_stated, candidates,
                              registered.sigma0_mm, distances, options, check,
                              &train, others, &state);
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

  HoldoutSplit split =
      SplitHoldout(all, options.holdout_fraction, options.seed);
  result.train_rows = std::move(split.train);
  result.heldout_rows = std::move(split.heldout);
  const std::vector<Measurement> all_train = Pick(all, result.train_rows);
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
    std::vector<Measurement> others = Pick(all, result.heldout_rows);
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
  // Held-out rows beyond the same threshold are listed and left out of the
  // held-out figures, as the training ones; unless more than a quarter are
  // (a model that predicts badly, not gross rows: all are kept, so the
  // held-out figures cannot flatter it).
  {
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
      result.outliers.push_back(o);
    }
    if (!leave_out) result.outliers_too_many = true;
    held = kept;
  }
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
  result.calibrated = state.chain.ToRobot(nominal);
  result.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
          .count();
  return result;
}

}  // namespace kincal
