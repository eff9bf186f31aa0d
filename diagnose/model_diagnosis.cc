#include "diagnose/model_diagnosis.h"

#include <Eigen/QR>
#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <set>
#include <sstream>
#include <thread>

#include "calib/calibrate.h"
#include "calib/holdout.h"
#include "calib/identifiability.h"
#include "data/csv.h"
#include "data/error.h"
#include "data/provenance.h"
#include "data/yaml_util.h"
#include "diagnose/cross_validation.h"
#include "diagnose/exact_jacobian.h"
#include "diagnose/free_fit.h"
#include "diagnose/nonparametric.h"

namespace kincal {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
// 97.5 % point of the standard normal and 95 % point of chi-square(1).
constexpr double kZ95 = 1.959963984540054;
constexpr double kChi2One95 = 3.841458820694124;

std::vector<Measurement> Pick(const std::vector<Measurement>& ms,
                              const std::vector<int>& idx) {
  std::vector<Measurement> out;
  out.reserve(idx.size());
  for (int i : idx) out.push_back(ms[i]);
  return out;
}

double Rss(const ModelState& state, const std::vector<Measurement>& ms) {
  double sum = 0.0;
  for (const Measurement& m : ms) sum += Residual(state, m).squaredNorm();
  return sum;
}

// RMS of |residual| (3D), as `calibrate` reports it; NaN for no poses.
double Rms(const ModelState& state, const std::vector<Measurement>& ms) {
  if (ms.empty()) return kNaN;
  return std::sqrt(Rss(state, ms) / static_cast<double>(ms.size()));
}

// The candidate reduced to what the data can determine against `basis`:
// drift keeps its identifiable components (a drift along a direction that
// geometry already explains is that geometry); other causes need all their
// parameters. Returns false when nothing is left.
// `projected`: the candidate's columns after ProjectedOffBasis.
bool ReduceToIdentifiable(const Eigen::MatrixXd& projected, Candidate* c) {
  const std::vector<bool> ok = IndependentProjectedColumns(projected);
  if (c->cause != "drift") {
    return std::all_of(ok.begin(), ok.end(), [](bool b) { return b; });
  }
  std::vector<ParamInfo> kept;
  for (size_t i = 0; i < ok.size(); ++i) {
    if (ok[i]) kept.push_back(c->params[i]);
  }
  c->params = kept;
  return !kept.empty();
}

struct Problem {
  Chain nominal;
  // Bounds FitBase widened where the data press a parameter against bounds
  // the robot file does not state (calib/fit.h FitOptions::bound_override),
  // for every later fit.
  std::map<std::string, double> bound_override;
  std::vector<Measurement> all, train, held;
  std::vector<ParamInfo> base_free;  // nuisance + identifiable geometry
  ModelState base_state;             // fitted on the training poses

  // A fit of `free` in the geometry's box: nominal +- its bounds, the
  // widened ones included.
  FitOptions Boxed(const std::vector<ParamInfo>& free) const {
    FitOptions fo;
    fo.free = free;
    fo.bounds_center = &nominal;
    fo.bound_override = bound_override;
    return fo;
  }
  // A candidate's refit: the box, no covariance, the refits' tolerances.
  FitOptions CandidateRefit(const std::vector<ParamInfo>& free) const {
    FitOptions fo = Boxed(free);
    fo.compute_covariance = false;
    fo.max_iterations = 100;
    fo.function_tolerance = 1e-10;
    fo.parameter_tolerance = 1e-10;
    return fo;
  }
};

// Frame (and points) registration, then the geometry as `calibrate` fits
// it from the nominal model (calib/calibrate.h FitGeometry: the first look,
// identifiability at the solution until the free set is stable, unstated
// bounds widened where the data press against them). With the first look
// alone a 7-joint URDF arm 10 mm / 3 deg from its nominal model stopped at
// 1.88 mm RMS (another minimum, 0.14 after the passes) and the catalogue
// found nothing; with bounds pressed it named `thermal` for a backlash.
// exact: the fits by diagnose/free_fit.h's exact-Jacobian path (same
// problem, calib/fit.h's tolerances).
void FitBase(const std::vector<Measurement>& fit_on, const Observations& obs,
             bool bounds_stated, Problem* pb, bool exact = false) {
  ModelState& state = pb->base_state;
  InitializeFrameAndPoints(fit_on, &state);
  std::vector<ParamInfo> nuisance;
  bool any_measured = false;
  for (const Measurement& m : fit_on) {
    any_measured = any_measured || m.kind == Measurement::kMeasured;
  }
  if (any_measured) nuisance = FrameParams();
  for (const ParamInfo& p : PointParams(state)) nuisance.push_back(p);
  FitOptions frame_only;
  frame_only.free = nuisance;
  frame_only.compute_covariance = false;
  // The misfit after registering, per axis (calib/fit.h's sigma0).
  double registered_sigma0 = 0.0;
  if (exact) {
    const double rss = FreeFit(fit_on, FreeFitOptionsFrom(frame_only), &state);
    registered_sigma0 = std::sqrt(
        rss / std::max(1.0, 3.0 * fit_on.size() -
                                static_cast<double>(nuisance.size())));
  } else {
    registered_sigma0 = Fit(fit_on, frame_only, &state).sigma0_mm;
  }

  std::vector<ParamInfo> candidates = nuisance;
  for (const ParamInfo& p : GeometryParams(state.chain))
    candidates.push_back(p);
  auto check = [&](const Identifiability& id) {
    const int robot_params = id.RobotParameterCount();
    const int distinct = DistinctPoses(fit_on);
    if (robot_params == 0) {
      throw InputError(obs.source, 0, 0,
                       "the data determine no robot parameter (" +
                           std::to_string(distinct) +
                           " distinct poses): use more poses that differ in "
                           "every joint");
    }
    const int num_free = static_cast<int>(id.identifiable.size());
    if (3 * static_cast<int>(fit_on.size()) <= num_free + 3) {
      throw InputError(obs.source, 0, 0,
                       "too few poses: " + std::to_string(fit_on.size()) +
                           " training poses give " +
                           std::to_string(3 * fit_on.size()) +
                           " equations for " + std::to_string(num_free) +
                           " identifiable parameters plus the candidates; "
                           "need at least " +
                           std::to_string(num_free / 3 + 3) +
                           " distinct training poses (more for a useful "
                           "diagnosis)");
    }
  };
  // The geometry's fits by the exact-Jacobian path when asked (same
  // problem and bounds, calib/fit.h's tolerances).
  GeometryFitter fitter;
  if (exact) {
    fitter = [](const std::vector<Measurement>& ms, const FitOptions& fo,
                ModelState* s) {
      return FreeFitWithCovariance(ms, FreeFitOptionsFrom(fo), s);
    };
  }
  std::vector<Measurement> train = fit_on;
  const GeometryFit g = FitGeometry(obs, pb->nominal, bounds_stated, candidates,
                                    registered_sigma0, {}, CalibrateOptions{},
                                    check, &train, nullptr, &state, fitter);
  pb->base_free = g.identifiability.identifiable;
  pb->bound_override = g.fit_options.bound_override;
}

// Measurements of `obs` with the validity checks of the spec.
std::vector<Measurement> Measurements(const Chain& nominal,
                                      const Observations& obs,
                                      ModelState* state) {
  std::vector<Measurement> all = MakeMeasurements(nominal, obs, state);
  std::vector<Measurement> measured;
  for (const Measurement& m : all) {
    if (m.kind == Measurement::kMeasured) measured.push_back(m);
  }
  if (measured.empty()) {
    throw InputError(obs.source, 0, 0,
                     "no row has a measured tip (x, y, z): the diagnosis "
                     "needs measured points");
  }
  const int distinct = DistinctPoses(measured);
  if (distinct < 2) {
    throw InputError(obs.source, 0, 0,
                     "all " + std::to_string(measured.size()) +
                         " measured rows have the same joint readings: one "
                         "pose determines no robot parameter");
  }
  if (distinct < 3) {
    throw InputError(obs.source, 0, 0,
                     "only 2 distinct poses: the measuring frame alone needs "
                     "3 non-collinear tip points; more poses are needed to "
                     "determine any robot parameter");
  }
  return measured;
}

// The inputs of the smooth correction: every joint reading, t and temp_c
// when they vary.
SmoothInputs MakeSmoothInputs(const Observations& obs,
                              const std::vector<Measurement>& train,
                              const std::vector<Measurement>& held) {
  SmoothInputs in;
  in.names = obs.joint_names;
  const bool time = obs.AnyTime(), temp = obs.AnyTemp();
  if (time) in.names.push_back("t");
  if (temp) in.names.push_back("temp_c");
  auto row = [&](const Measurement& m) {
    const Observation& o = obs.rows[m.row];
    std::vector<double> x = o.q;
    if (time) x.push_back(o.HasTime() ? o.t_s : 0.0);
    if (temp) x.push_back(o.HasTemp() ? o.temp_c : 0.0);
    return x;
  };
  for (const Measurement& m : train) in.train.push_back(row(m));
  for (const Measurement& m : held) in.held.push_back(row(m));
  bool points = true;
  for (const Measurement& m : train) points &= obs.rows[m.row].has_point;
  if (points) {
    for (const Measurement& m : train) {
      in.point_train.push_back(obs.rows[m.row].p_in_meas);
    }
  }
  return in;
}

SmoothCorrection SmoothRest(const Observations& obs, const Problem& pb,
                            const ModelState& state) {
  std::vector<Eigen::Vector3d> rt, rh;
  for (const Measurement& m : pb.train) rt.push_back(Residual(state, m));
  for (const Measurement& m : pb.held) rh.push_back(Residual(state, m));
  return FitSmoothCorrection(MakeSmoothInputs(obs, pb.train, pb.held), rt, rh);
}

// RMS on the validation series with the model held fixed and only the
// measuring frame registered (what `kincal evaluate` does); NaN when none.
double ValidationRms(const ModelState& state,
                     const std::vector<Measurement>& validation) {
  if (validation.empty()) return kNaN;
  ModelState s = state;
  InitializeFrameAndPoints(validation, &s);
  return Rms(s, validation);
}

// The same with the exact-Jacobian fit (diagnose/free_fit.h) of the frame,
// started from `frame` (the current model's registered frame on the
// validation series) instead of Umeyama: same problem, calib/fit.h's
// tolerances.
double ValidationRmsFrom(const ModelState& state,
                         const std::array<double, kFrameBlockSize>& frame,
                         const std::vector<Measurement>& validation) {
  if (validation.empty()) return kNaN;
  ModelState s = state;
  s.meas_from_base = frame;
  FreeFitOptions o;
  o.free = FrameParams();
  o.max_iterations = 200;
  o.function_tolerance = o.parameter_tolerance = 1e-12;
  const double rss = FreeFit(validation, o, &s);
  return std::sqrt(rss / static_cast<double>(validation.size()));
}

ModelState StateWithChain(const Chain& chain) {
  ModelState s;
  s.chain = chain;
  return s;
}

}  // namespace

void DiagnoseOptions::Check() const {
  Require(
      holdout_fraction >= 0 && holdout_fraction < 0.9,
      "--holdout must be in [0, 0.9), got " + std::to_string(holdout_fraction));
  Require(std::isfinite(noise_mm) && noise_mm >= 0,
          "--noise must be >= 0 mm (0 = estimate)");
  Require(false_alarm > 0 && false_alarm < 0.5,
          "false-alarm probability must be in (0, 0.5)");
  Require(max_findings >= 1, "max findings must be >= 1");
  Require(std::isfinite(min_effect_mm) && min_effect_mm >= 0,
          "min effect must be >= 0 mm");
  Require(unexplained_ratio > 1, "unexplained ratio must be > 1");
  Require(folds >= 0,
          "--folds must be >= 0 (0 or 1 = the single held-out "
          "split), got " +
              std::to_string(folds));
  for (const std::string& c : causes) {
    Require(std::find(CatalogueCauses().begin(), CatalogueCauses().end(), c) !=
                CatalogueCauses().end(),
            "unknown cause '" + c +
                "' (backlash, compliance, cyclic, gain, axis_tilt, drift, "
                "elastostatic, thermal, mount_compliance, transmission)");
  }
}

DiagnosisResult DiagnoseModel(const Robot& nominal, const Observations& obs,
                              const DiagnoseOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  options.Check();
  DiagnosisResult out;
  Problem pb;
  pb.nominal = Chain::FromRobot(nominal);
  pb.base_state = StateWithChain(pb.nominal);
  pb.all = Measurements(pb.nominal, obs, &pb.base_state);
  const HoldoutSplit split =
      SplitHoldout(pb.all, options.holdout_fraction, options.seed);
  pb.train = Pick(pb.all, split.train);
  pb.held = Pick(pb.all, split.heldout);
  // The transmission family lives on the joints' travel in the training data.
  SetTransmissionTravel(pb.train, &pb.nominal);
  SetTransmissionTravel(pb.train, &pb.base_state.chain);
  for (auto* set : {&pb.all, &pb.train, &pb.held})
    for (Measurement& m : *set) FillTransmissionSines(pb.nominal, &m.input);
  out.train_poses = static_cast<int>(pb.train.size());
  out.heldout_poses = static_cast<int>(pb.held.size());
  // Folds of the cross-validation (training poses only: the held-out poses
  // stay out of the selection and are reported).
  {
    const int distinct = DistinctPoses(pb.train);
    int k = options.folds <= 1 ? 0 : options.folds;
    if (options.folds_given && k > distinct) {
      throw InputError(obs.source, 0, 0,
                       "--folds " + std::to_string(options.folds) + ": only " +
                           std::to_string(distinct) +
                           " distinct training poses (" +
                           std::to_string(pb.train.size()) + " of " +
                           std::to_string(pb.all.size()) +
                           " poses, the rest held out); use at most " +
                           std::to_string(distinct) +
                           " folds, or 0 for the single held-out split");
    }
    if (!options.folds_given) {
      k = std::min(k, distinct / DiagnoseOptions::kMinPosesPerFold);
    }
    out.folds = k >= 2 ? k : 0;
  }
  FitBase(pb.train, obs, nominal.bounds_stated, &pb, options.exact_jacobian);
  const FoldPlan folds = out.folds >= 2
                             ? MakeFolds(pb.train, out.folds, options.seed)
                             : FoldPlan{};

  ModelState current = pb.base_state;
  std::vector<ParamInfo> current_free = pb.base_free;
  out.nominal_train_rms_mm = Rms(current, pb.train);
  out.nominal_heldout_rms_mm = Rms(current, pb.held);
  double current_rss = Rss(current, pb.train);
  double current_held = out.nominal_heldout_rms_mm;
  auto cv_options = [&](const std::vector<ParamInfo>& free) {
    FreeFitOptions o;
    o.free = free;
    o.bounds_center = &pb.nominal;
    o.bound_override = pb.bound_override;
    o.exact_jacobian = options.exact_jacobian;
    return o;
  };
  // Out-of-fold squared error per training pose of the current model.
  std::vector<double> current_cv_err;
  out.nominal_cv_rms_mm =
      CrossValidatedRms(pb.train, folds, current, cv_options(current_free),
                        options.cv_refit, &current_cv_err);
  double current_cv = out.nominal_cv_rms_mm;
  std::vector<Measurement> validation;
  for (const Observations& v : options.validation) {
    ModelState scratch = StateWithChain(pb.nominal);
    for (const Measurement& m : Measurements(pb.nominal, v, &scratch))
      validation.push_back(m);
  }
  out.nominal_validation_rms_mm = ValidationRms(current, validation);
  double current_validation = out.nominal_validation_rms_mm;
  const int n_res = 3 * static_cast<int>(pb.train.size());

  std::vector<Candidate> pool =
      CatalogueCandidates(pb.nominal, pb.all, options.causes);
  std::vector<Candidate> accepted;
  const bool thermal_kelvin = ThermalUsesTemperature(obs);
  auto scale_of = [&](const Candidate& c) {
    return MagnitudeScale(c.cause, c.joint, pb.nominal, pb.all);
  };
  auto unit_of = [&](const Candidate& c, const std::string& unit) {
    return c.cause == "thermal" && thermal_kelvin ? std::string("mm/K") : unit;
  };

  // Residuals below this (mm per axis) are numerically exact data: nothing
  // measurable is left to explain.
  constexpr double kExactMm = 1e-7;
  for (int step = 0; step < options.max_findings && !pool.empty() &&
                     current_rss > kExactMm * kExactMm * n_res;
       ++step) {
    // The current model's measuring frame on the validation series: the
    // start of every candidate's re-registration.
    std::array<double, kFrameBlockSize> validation_frame{};
    if (!validation.empty()) {
      ModelState v = current;
      InitializeFrameAndPoints(validation, &v);
      validation_frame = v.meas_from_base;
    }
    // Identifiability of each candidate against the current model
    // (residuals and Jacobians: diagnose/exact_jacobian.h).
    // exact_jacobian = false: calib/fit.h's autodiff, as before.
    Eigen::VectorXd r0;
    Eigen::MatrixXd base_raw;
    if (options.exact_jacobian) {
      ResidualsAndJacobian(pb.train, current, current_free, &r0, &base_raw);
    } else {
      base_raw = ResidualJacobian(pb.train, current, current_free);
      r0.resize(3 * pb.train.size());
      for (size_t i = 0; i < pb.train.size(); ++i)
        r0.segment<3>(3 * i) = Residual(current, pb.train[i]);
    }
    const Eigen::MatrixXd basis = Basis(Normalized(base_raw));
    // One Jacobian for all candidates' parameters, sliced per candidate.
    std::vector<ParamInfo> all_params;
    for (size_t c = 0; c < pool.size(); ++c) {
      pool[c] = MakeCandidate(pb.nominal, pool[c].cause, pool[c].joint);
    }
    // Each parameter once (nested candidates share theirs: transmission8 is
    // the start of transmission16 and 24), its column by name.
    std::map<std::string, int> column_of;
    for (const Candidate& cand : pool) {
      for (const ParamInfo& q : cand.params) {
        if (column_of.emplace(q.name, static_cast<int>(all_params.size()))
                .second)
          all_params.push_back(q);
      }
    }
    auto candidate_columns = [&](const Eigen::MatrixXd& jac,
                                 const Candidate& cand) {
      Eigen::MatrixXd cols(jac.rows(), cand.params.size());
      for (size_t q = 0; q < cand.params.size(); ++q)
        cols.col(q) = jac.col(column_of.at(cand.params[q].name));
      return cols;
    };
    Eigen::MatrixXd cand_jac;
    if (options.exact_jacobian) {
      Eigen::VectorXd unused;
      ResidualsAndJacobian(pb.train, current, all_params, &unused, &cand_jac);
    } else {
      cand_jac = ResidualJacobian(pb.train, current, all_params);
    }
    // Normal equations of the base model, shared by every candidate's
    // Gauss-Newton start.
    // Screening: each candidate is refitted with the geometry and the frame
    // free and the extensions accepted in earlier steps held at their fitted
    // values (a transmission series carries up to 24 of them; freeing them
    // all in every candidate's refit made series C 10x slower). Holding them
    // can only raise a candidate's RSS, so its F-test is conservative; the
    // winner is refitted jointly with everything below.
    std::vector<ParamInfo> screen_free;
    std::vector<int> screen_cols;
    for (size_t q = 0; q < current_free.size(); ++q) {
      if (current_free[q].kind == ParamKind::kJointError ||
          current_free[q].kind == ParamKind::kDrift)
        continue;
      screen_free.push_back(current_free[q]);
      screen_cols.push_back(static_cast<int>(q));
    }
    Eigen::MatrixXd screen_raw(base_raw.rows(), screen_cols.size());
    for (size_t q = 0; q < screen_cols.size(); ++q)
      screen_raw.col(q) = base_raw.col(screen_cols[q]);
    const Eigen::MatrixXd base_ntn = screen_raw.transpose() * screen_raw;
    const Eigen::VectorXd base_ntr = screen_raw.transpose() * r0;
    // Every candidate column off the current model's span, in one product.
    const Eigen::MatrixXd projected = ProjectedOffBasis(basis, cand_jac);
    std::vector<bool> usable(pool.size());
    for (size_t c = 0; c < pool.size(); ++c) {
      usable[c] =
          ReduceToIdentifiable(candidate_columns(projected, pool[c]), &pool[c]);
    }
    const int p = static_cast<int>(current_free.size());
    int tested = 0;
    for (size_t c = 0; c < pool.size(); ++c) tested += usable[c] ? 1 : 0;
    if (tested == 0) break;
    const double alpha = options.false_alarm / tested;
    if (step == 0) out.bonferroni_alpha = alpha;

    std::vector<CandidateScore> scores(pool.size());
    std::vector<ModelState> states(pool.size(), current);
    std::vector<FitSummary> fits(pool.size());
    std::vector<double> log_p(pool.size(), 0.0);
    std::vector<std::vector<double>> cv_err(pool.size());
    ParallelFor(static_cast<int>(pool.size()), options.num_threads, [&](int c) {
      CandidateScore& s = scores[c];
      const Candidate& cand = pool[c];
      s.cause = cand.cause;
      s.joint = cand.joint >= 0 ? pb.nominal.rows[cand.joint].name : "";
      s.k = static_cast<int>(cand.params.size());
      s.identifiable = usable[c];
      if (!usable[c] || n_res - p - s.k <= 0) {
        s.identifiable = false;
        s.train_rms_mm = s.heldout_rms_mm = kNaN;
        return;
      }
      std::vector<ParamInfo> refit_free = screen_free;
      for (const ParamInfo& q : cand.params) refit_free.push_back(q);
      const FitOptions fo = pb.CandidateRefit(refit_free);
      // Start from the Gauss-Newton step of the linearised joint model, so
      // that the refit needs few iterations: normal equations of [base,
      // candidate columns], Jacobi-scaled.
      const int pb_cols = static_cast<int>(screen_raw.cols());
      const Eigen::MatrixXd cc = candidate_columns(cand_jac, cand);
      Eigen::MatrixXd ntn(pb_cols + s.k, pb_cols + s.k);
      ntn.topLeftCorner(pb_cols, pb_cols) = base_ntn;
      ntn.topRightCorner(pb_cols, s.k) = screen_raw.transpose() * cc;
      ntn.bottomLeftCorner(s.k, pb_cols) =
          ntn.topRightCorner(pb_cols, s.k).transpose();
      ntn.bottomRightCorner(s.k, s.k) = cc.transpose() * cc;
      Eigen::VectorXd ntr(pb_cols + s.k);
      ntr.head(pb_cols) = base_ntr;
      ntr.tail(s.k) = cc.transpose() * r0;
      Eigen::VectorXd scale(ntn.cols());
      for (int q = 0; q < ntn.cols(); ++q) {
        scale[q] = ntn(q, q) > 0 ? 1.0 / std::sqrt(ntn(q, q)) : 1.0;
      }
      Eigen::VectorXd step;
      if (options.exact_jacobian) {
        step =
            scale.asDiagonal() * (scale.asDiagonal() * ntn * scale.asDiagonal())
                                     .ldlt()
                                     .solve(-(scale.asDiagonal() * ntr));
      } else {  // QR of the scaled Jacobian, as before
        Eigen::MatrixXd a(screen_raw.rows(), pb_cols + s.k);
        a << screen_raw, cc;
        step = scale.asDiagonal() *
               (a * scale.asDiagonal()).colPivHouseholderQr().solve(-r0);
      }
      for (int q = 0; q < static_cast<int>(fo.free.size()); ++q) {
        if (std::isfinite(step[q]))
          *ParamAddress(&states[c], fo.free[q]) += step[q];
      }
      // Differentiated in the free parameters only (diagnose/free_fit.h).
      FreeFitOptions ffo = FreeFitOptionsFrom(fo);
      ffo.exact_jacobian = options.exact_jacobian;
      // A candidate whose linearised gain (the Gauss-Newton start's) is far
      // from significant (p above 100x the step's alpha) keeps the start:
      // its RSS there is that of a feasible model, an upper bound of the
      // refit's, so its F-test can only be conservative. Most candidates of
      // the later steps are such; the refits were most of the time.
      const double lin_drop = std::max(0.0, -ntr.dot(step));
      const double lin_d2 = n_res - p - s.k;
      const double lin_rss = std::max(current_rss - lin_drop, 1e-300);
      const bool hopeless =
          options.exact_jacobian && options.free_parameter_fit && lin_d2 > 0 &&
          LogFUpperTail((lin_drop / s.k) / (lin_rss / lin_d2), s.k, lin_d2) >
              std::log(100.0 * alpha);
      if (hopeless) {
        // the start is the model scored below
      } else if (options.free_parameter_fit) {
        FreeFit(pb.train, ffo, &states[c]);
      } else {
        fits[c] = Fit(pb.train, fo, &states[c]);
      }
      if (options.exact_jacobian) {
        // The same sums from the exact Jacobian's residual pass.
        Eigen::VectorXd rt, rh;
        ResidualsAndJacobian(pb.train, states[c], {}, &rt, nullptr);
        ResidualsAndJacobian(pb.held, states[c], {}, &rh, nullptr);
        s.rss = rt.squaredNorm();
        s.train_rms_mm =
            std::sqrt(s.rss / static_cast<double>(pb.train.size()));
        s.heldout_rms_mm = pb.held.empty()
                               ? kNaN
                               : std::sqrt(rh.squaredNorm() /
                                           static_cast<double>(pb.held.size()));
      } else {
        s.rss = Rss(states[c], pb.train);
        s.train_rms_mm = Rms(states[c], pb.train);
        s.heldout_rms_mm = Rms(states[c], pb.held);
      }
      const double d2 = n_res - p - s.k;
      // RSS changes at the solver's precision are no evidence.
      double drop = current_rss - s.rss;
      if (drop < 1e-10 * current_rss) drop = 0.0;
      s.f = s.rss > 0 ? (drop / s.k) / (s.rss / d2)
                      : std::numeric_limits<double>::infinity();
      log_p[c] = LogFUpperTail(s.f, s.k, d2);
      s.p_value = std::exp(log_p[c]);
      // With folds the cross-validated RMS must drop (computed only for
      // the candidates that pass the F-test: the few that can win);
      // without, the single held-out split's.
      const bool f_passes =
          std::log(alpha) > log_p[c] && drop > 0 &&
          std::sqrt(drop / static_cast<double>(pb.train.size())) >=
              options.min_effect_mm;
      if (folds.folds >= 2 && f_passes) {
        s.cv_rms_mm =
            CrossValidatedRms(pb.train, folds, states[c], cv_options(fo.free),
                              options.cv_refit, &cv_err[c]);
        s.cv_z = PairedZ(current_cv_err, cv_err[c]);
      }
      const bool held_better =
          folds.folds >= 2
              ? s.cv_rms_mm < current_cv && s.cv_z > options.cv_min_z
              : pb.held.empty() || s.heldout_rms_mm < current_held;
      const double explained_mm =
          std::sqrt(drop / static_cast<double>(pb.train.size()));
      s.validation_rms_mm =
          options.exact_jacobian
              ? ValidationRmsFrom(states[c], validation_frame, validation)
              : ValidationRms(states[c], validation);
      const bool validation_better =
          validation.empty() || s.validation_rms_mm < current_validation;
      s.significant = std::log(alpha) > log_p[c] && held_better &&
                      validation_better &&
                      explained_mm >= options.min_effect_mm;
      const Magnitude mag =
          CandidateMagnitude(cand, states[c], fits[c], scale_of(cand));
      s.magnitude = mag.value;
      s.unit = unit_of(cand, mag.unit);
    });
    out.steps.push_back(scores);
    if (step == 0) {
      for (size_t c = 0; c < pool.size(); ++c) {
        if (!usable[c])
          out.not_identifiable.push_back(pool[c].Label(pb.nominal));
      }
    }

    int best = -1;
    for (size_t c = 0; c < pool.size(); ++c) {
      if (!scores[c].significant) continue;
      // With validation series the candidate that predicts them best wins
      // (the F-test only admits); else with folds the lowest
      // cross-validated RMS; else the most significant one.
      const bool better =
          !validation.empty()
              ? scores[c].validation_rms_mm < scores[best].validation_rms_mm
          : folds.folds >= 2
              ? scores[c].cv_rms_mm < scores[best].cv_rms_mm
              : (log_p[c] < log_p[best] ||
                 (log_p[c] == log_p[best] && scores[c].rss < scores[best].rss));
      if (best < 0 || better) {
        best = static_cast<int>(c);
      }
    }
    // With folds and no validation series: candidates whose out-of-fold
    // errors are within `cv_tie_z` standard errors of the winner's (paired
    // over the training poses) predict as well on this data; among them the
    // most significant (the F-test's ranking, which prefers fewer
    // parameters) wins. Without this rule a candidate that nests the true
    // one (cyclic j5's cos, sin against compliance j5 on BH-7) wins by its
    // extra parameter's fit to the noise (bench --only cv-sim: compliance
    // j5 named 35/40 instead of 40/40).
    if (best >= 0 && validation.empty() && folds.folds >= 2 &&
        options.cv_tie_z > 0) {
      const int cv_best = best;
      for (size_t c = 0; c < pool.size(); ++c) {
        if (!scores[c].significant || static_cast<int>(c) == cv_best) continue;
        if (PairedZ(cv_err[c], cv_err[cv_best]) < options.cv_tie_z &&
            log_p[c] < log_p[best]) {
          best = static_cast<int>(c);
        }
      }
    }
    if (best < 0) break;
    if (screen_free.size() < current_free.size()) {
      // The winner refitted jointly with the extensions held in screening,
      // kept only when it fits the training poses better without predicting
      // the validation series worse.
      const ModelState screened_state = states[best];
      const CandidateScore screened = scores[best];
      const std::vector<double> screened_cv_err = cv_err[best];
      std::vector<ParamInfo> refit_free = current_free;
      for (const ParamInfo& q : pool[best].params) refit_free.push_back(q);
      const FitOptions fo = pb.CandidateRefit(refit_free);
      if (options.free_parameter_fit) {
        FreeFitOptions ffo = FreeFitOptionsFrom(fo);
        ffo.exact_jacobian = options.exact_jacobian;
        FreeFit(pb.train, ffo, &states[best]);
      } else {
        fits[best] = Fit(pb.train, fo, &states[best]);
      }
      CandidateScore& w = scores[best];
      w.rss = Rss(states[best], pb.train);
      w.train_rms_mm = Rms(states[best], pb.train);
      if (!pb.held.empty()) w.heldout_rms_mm = Rms(states[best], pb.held);
      if (!validation.empty())
        w.validation_rms_mm = ValidationRms(states[best], validation);
      w.magnitude = CandidateMagnitude(pool[best], states[best], fits[best],
                                       scale_of(pool[best]))
                        .value;
      if (folds.folds >= 2) {
        w.cv_rms_mm = CrossValidatedRms(pb.train, folds, states[best],
                                        cv_options(fo.free), options.cv_refit,
                                        &cv_err[best]);
      }
      if (!(w.rss <= screened.rss) ||
          (!validation.empty() &&
           !(w.validation_rms_mm <= screened.validation_rms_mm))) {
        states[best] = screened_state;
        scores[best] = screened;
        cv_err[best] = screened_cv_err;
      }
    }
    const CandidateScore& b = scores[best];
    Finding f;
    f.cause = b.cause;
    f.joint = b.joint;
    f.heldout_rms_before_mm = current_held;
    f.heldout_rms_after_mm = b.heldout_rms_mm;
    f.validation_rms_before_mm = current_validation;
    f.validation_rms_after_mm = b.validation_rms_mm;
    f.cv_rms_before_mm = current_cv;
    f.cv_rms_after_mm = b.cv_rms_mm;
    f.train_rms_after_mm = b.train_rms_mm;
    f.f = b.f;
    f.p_value = b.p_value;
    // Candidates that predict the same errors on this data.
    const double sigma2 = b.rss / (n_res - p - b.k);
    for (size_t c = 0; c < pool.size(); ++c) {
      if (static_cast<int>(c) == best || !scores[c].identifiable) continue;
      if (scores[c].rss - b.rss < kChi2One95 * sigma2 &&
          std::log(alpha) > log_p[c]) {
        f.equivalent.push_back(
            {scores[c].cause, scores[c].joint, scores[c].magnitude,
             scores[c].unit, scores[c].train_rms_mm, scores[c].heldout_rms_mm});
      }
    }
    out.findings.push_back(f);
    accepted.push_back(pool[best]);
    current = states[best];
    for (const ParamInfo& q : pool[best].params) current_free.push_back(q);
    current_rss = b.rss;
    current_held = b.heldout_rms_mm;
    current_validation = b.validation_rms_mm;
    current_cv = b.cv_rms_mm;
    current_cv_err = cv_err[best];
    pool.erase(pool.begin() + best);
    // A joint's error along the travel (transmission) and its low harmonics
    // and gain describe nearly the same function inside the travel and
    // differ outside it: once one kind is in the model, the other leaves the
    // pool (together they drift apart along that near-degenerate direction
    // and extrapolate wildly: UR10 C --validate A gave 128 mm on A).
    const Candidate& won = accepted.back();
    auto along_travel = [](const std::string& cause) {
      return TransmissionTerms(cause) > 0                     ? 1
             : (CyclicHarmonic(cause) > 0 || cause == "gain") ? 2
                                                              : 0;
    };
    if (along_travel(won.cause) > 0) {
      pool.erase(std::remove_if(pool.begin(), pool.end(),
                                [&](const Candidate& c) {
                                  const int kind = along_travel(c.cause);
                                  return c.joint == won.joint && kind > 0 &&
                                         kind != along_travel(won.cause);
                                }),
                 pool.end());
    }
  }
  out.final_train_rms_mm = Rms(current, pb.train);
  out.final_heldout_rms_mm = current_held;
  out.final_validation_rms_mm = current_validation;
  out.final_cv_rms_mm = current_cv;
  out.residual_sigma_mm = std::sqrt(
      current_rss / std::max(1, n_res - static_cast<int>(current_free.size())));

  // Final model on all poses: magnitudes and 95 % intervals.
  ModelState final_state = current;
  FitOptions fo = pb.Boxed(current_free);
  fo.compute_covariance = true;
  FitSummary final_fit;
  if (options.exact_jacobian) {
    final_fit =
        FreeFitWithCovariance(pb.all, FreeFitOptionsFrom(fo), &final_state);
  } else {
    final_fit = Fit(pb.all, fo, &final_state);
  }
  for (size_t i = 0; i < accepted.size(); ++i) {
    const Candidate& c = accepted[i];
    const Magnitude m =
        CandidateMagnitude(c, final_state, final_fit, scale_of(c));
    out.findings[i].magnitude = m.value;
    out.findings[i].unit = unit_of(c, m.unit);
    out.findings[i].ci_low = m.ci_low;
    out.findings[i].ci_high = m.ci_high;
  }

  // Noise and the systematic rest.
  if (options.noise_mm > 0) {
    out.noise_mm = options.noise_mm;
    out.noise_source = "stated";
  } else if (const double rep = RepeatedPoseNoise(pb.all); rep > 0) {
    out.noise_mm = rep;
    out.noise_source = "repeated poses";
  } else if (const double nn = NearestPoseNoise(current, pb.train); nn > 0) {
    out.noise_mm = nn;
    out.noise_source = "nearest poses (upper bound)";
  } else {
    out.noise_source = "none";
  }
  const int dof = n_res - static_cast<int>(current_free.size());
  if (out.noise_mm > 0 && dof >= 10) {
    const double excess = out.residual_sigma_mm * out.residual_sigma_mm -
                          out.noise_mm * out.noise_mm;
    out.systematic_rms_mm = std::sqrt(std::max(0.0, 3.0 * excess));
    if (out.residual_sigma_mm > options.unexplained_ratio * out.noise_mm &&
        out.systematic_rms_mm > options.min_effect_mm) {
      Finding u;
      u.cause = "unexplained";
      u.magnitude = out.systematic_rms_mm;
      u.unit = "mm";
      // Chi-square interval of the residual variance (normal approximation).
      const double rel = kZ95 * std::sqrt(2.0 / dof);
      const double s2 = out.residual_sigma_mm * out.residual_sigma_mm;
      const double n2 = out.noise_mm * out.noise_mm;
      u.ci_low = std::sqrt(std::max(0.0, 3.0 * (s2 * (1 - rel) - n2)));
      u.ci_high = std::sqrt(std::max(0.0, 3.0 * (s2 * (1 + rel) - n2)));
      u.heldout_rms_before_mm = u.heldout_rms_after_mm = current_held;
      u.validation_rms_before_mm = u.validation_rms_after_mm =
          current_validation;
      u.cv_rms_before_mm = u.cv_rms_after_mm = current_cv;
      u.train_rms_after_mm = out.final_train_rms_mm;
      u.p_value = kNaN;
      u.f = s2 / n2;
      // What the rest depends on: a smooth correction over the pose inputs,
      // chosen by cross-validation, tested on the held-out poses.
      const SmoothCorrection sc = SmoothRest(obs, pb, current);
      u.depends_on = sc.depends_on;
      u.cv_explained = sc.cv_explained;
      u.smooth_k = sc.k;
      u.single_inputs = sc.single;
      u.point_cv_explained = sc.point_cv_explained;
      if (!pb.held.empty()) u.heldout_rms_after_mm = sc.heldout_rms_after_mm;
      out.findings.push_back(u);
    }
  }
  out.verdict = out.findings.empty() ? "no_significant_effect" : "effect_found";
  {
    std::set<int> held_rows;
    for (const Measurement& m : pb.held) held_rows.insert(m.row);
    for (const Measurement& m : pb.all) {
      out.rows.push_back(m.row);
      out.heldout.push_back(held_rows.count(m.row) > 0);
      out.residuals.push_back(Residual(final_state, m));
    }
  }
  out.state = final_state;
  out.extended = final_state.chain.ToRobot(nominal);
  out.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
          .count();
  return out;
}

std::vector<Magnitude> FitCandidates(const Robot& nominal,
                                     const Observations& obs,
                                     const std::vector<std::string>& labels,
                                     double* sigma0_mm) {
  Problem pb;
  pb.nominal = Chain::FromRobot(nominal);
  pb.base_state = StateWithChain(pb.nominal);
  pb.all = Measurements(pb.nominal, obs, &pb.base_state);
  SetTransmissionTravel(pb.all, &pb.nominal);
  SetTransmissionTravel(pb.all, &pb.base_state.chain);
  for (Measurement& m : pb.all) FillTransmissionSines(pb.nominal, &m.input);
  FitBase(pb.all, obs, nominal.bounds_stated, &pb);
  const std::vector<Candidate> catalogue =
      CatalogueCandidates(pb.nominal, pb.all);
  const Eigen::MatrixXd basis =
      Basis(Normalized(ResidualJacobian(pb.all, pb.base_state, pb.base_free)));
  std::vector<Candidate> chosen(labels.size());
  std::vector<bool> found(labels.size(), false);
  FitOptions fo = pb.Boxed(pb.base_free);
  Eigen::MatrixXd model = basis;
  for (size_t i = 0; i < labels.size(); ++i) {
    for (const Candidate& c : catalogue) {
      if (c.Label(pb.nominal) != labels[i]) continue;
      const Eigen::MatrixXd cols =
          ResidualJacobian(pb.all, pb.base_state, c.params);
      if (!IdentifiableAgainst(model, cols)) break;
      model = Basis(Normalized([&] {
        Eigen::MatrixXd m(model.rows(), model.cols() + cols.cols());
        m << model, Normalized(cols);
        return m;
      }()));
      chosen[i] = c;
      found[i] = true;
      for (const ParamInfo& q : c.params) fo.free.push_back(q);
    }
  }
  ModelState state = pb.base_state;
  const FitSummary fit = Fit(pb.all, fo, &state);
  if (sigma0_mm) *sigma0_mm = fit.sigma0_mm;
  std::vector<Magnitude> out;
  for (size_t i = 0; i < labels.size(); ++i) {
    if (!found[i]) {
      Magnitude m;
      m.value = m.sigma = m.ci_low = m.ci_high = kNaN;
      out.push_back(m);
      continue;
    }
    const Candidate& c = chosen[i];
    out.push_back(CandidateMagnitude(
        c, state, fit, MagnitudeScale(c.cause, c.joint, pb.nominal, pb.all)));
  }
  return out;
}

}  // namespace kincal
