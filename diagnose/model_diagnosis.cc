#include "diagnose/model_diagnosis.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <set>

#include "calib/calibrate.h"
#include "calib/exact_jacobian.h"
#include "calib/fit_record.h"
#include "calib/free_fit.h"
#include "calib/holdout.h"
#include "calib/identifiability.h"
#include "data/error.h"
#include "diagnose/cross_validation.h"
#include "diagnose/nonparametric.h"
#include "diagnose/periodic_basis.h"
#include "diagnose/travel_gaps.h"

namespace kincal {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
// 97.5 % point of the standard normal and 95 % point of chi-square(1).
constexpr double kZ95 = 1.959963984540054;
constexpr double kChi2One95 = 3.841458820694124;

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
    FitOptions fit_options;
    fit_options.free = free;
    fit_options.bounds_center = &nominal;
    fit_options.bound_override = bound_override;
    return fit_options;
  }
  // A candidate's refit: the box, no covariance, the refits' tolerances.
  FitOptions CandidateRefit(const std::vector<ParamInfo>& free) const {
    FitOptions fit_options = Boxed(free);
    fit_options.compute_covariance = false;
    fit_options.max_iterations = 100;
    fit_options.function_tolerance = 1e-10;
    fit_options.parameter_tolerance = 1e-10;
    return fit_options;
  }
};

// Frame (and points) registration, then the geometry as `calibrate` fits
// it from the nominal model (calib/calibrate.h FitGeometry: the first look,
// identifiability at the solution until the free set is stable, unstated
// bounds widened where the data press against them). With the first look
// alone a 7-joint URDF arm 10 mm / 3 deg from its nominal model stopped at
// 1.88 mm RMS (another minimum, 0.14 after the passes) and the catalogue
// found nothing; with bounds pressed it named `thermal` for a backlash.
// `solver`: the least-squares solver of every fit (same problem,
// calib/fit.h's tolerances), on `threads` threads.
void FitBase(const std::vector<Measurement>& fit_on, const Observations& obs,
             bool bounds_stated, GeometrySolver solver, int threads,
             Problem* problem) {
  ModelState& state = problem->base_state;
  InitializeFrameAndPoints(fit_on, &state);
  std::vector<ParamInfo> nuisance;
  bool any_measured = false;
  for (const Measurement& m : fit_on) {
    any_measured = any_measured || m.kind == Measurement::kMeasured;
  }
  if (any_measured) nuisance = AllFrameParams(state);
  for (const ParamInfo& p : PointParams(state)) nuisance.push_back(p);
  FitOptions frame_only;
  frame_only.free = nuisance;
  frame_only.compute_covariance = false;
  frame_only.num_threads = threads;
  // The misfit after registering, per axis (calib/fit.h's sigma0).
  double registered_sigma0 = 0.0;
  if (solver == GeometrySolver::kExactJacobian) {
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
  std::vector<Measurement> train = fit_on;
  GeometryProblem geometry;
  geometry.obs = &obs;
  geometry.nominal = &problem->nominal;
  geometry.bounds_stated = bounds_stated;
  geometry.candidates = candidates;
  geometry.registered_sigma0_mm = registered_sigma0;
  geometry.train = &train;
  geometry.check = check;
  geometry.solver = solver;
  CalibrateOptions calibrate_options;
  calibrate_options.num_threads = threads;
  const GeometryFit g = FitGeometry(geometry, calibrate_options, &state);
  problem->base_free = g.identifiability.identifiable;
  problem->bound_override = g.fit_options.bound_override;
}

// Measurements of `obs` with the validity checks of the spec.
std::vector<Measurement> Measurements(const Chain& nominal,
                                      const Observations& obs,
                                      ModelState* state) {
  std::vector<Measurement> all = MakeMeasurements(nominal, obs, state);
  AssignSeriesFrames(obs, &all, state);  // one measuring frame per series
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
  // Measured points of one series only: those of several series lie in
  // different measuring frames (the test runs per series instead).
  bool points = true;
  for (const Measurement& m : train)
    points &= obs.rows[m.row].has_point && m.frame == 0;
  if (points) {
    for (const Measurement& m : train) {
      in.point_train.push_back(obs.rows[m.row].p_in_meas);
    }
  }
  return in;
}

SmoothCorrection SmoothRest(const Observations& obs, const Problem& problem,
                            const ModelState& state) {
  std::vector<Eigen::Vector3d> rt, rh;
  for (const Measurement& m : problem.train) rt.push_back(Residual(state, m));
  for (const Measurement& m : problem.held) rh.push_back(Residual(state, m));
  return FitSmoothCorrection(MakeSmoothInputs(obs, problem.train, problem.held),
                             rt, rh);
}

// RMS on the validation series with the model held fixed and only the
// measuring frame registered (what `kincal evaluate` does); NaN when none.
double ValidationRms(const ModelState& state,
                     const std::vector<Measurement>& validation) {
  if (validation.empty()) return kNaN;
  ModelState s = state;
  s.more_frames.clear();
  s.frame_series.clear();
  InitializeFrameAndPoints(validation, &s);
  return Rms(s, validation);
}

// The same with the exact-Jacobian fit (calib/free_fit.h) of the frame,
// started from `frame` (the current model's registered frame on the
// validation series, one per series) instead of Umeyama: same problem,
// calib/fit.h's tolerances.
double ValidationRmsFrom(const ModelState& state, const ModelState& frames,
                         const std::vector<Measurement>& validation) {
  if (validation.empty()) return kNaN;
  ModelState s = state;
  s.meas_from_base = frames.meas_from_base;
  s.more_frames = frames.more_frames;
  s.frame_series = frames.frame_series;
  FreeFitOptions o;
  o.free = AllFrameParams(s);
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
                "elastostatic, thermal, mount_compliance, transmission, "
                "gravity)");
  }
}

namespace {

// Step 1: the measured poses of `obs`, split into training and held-out
// (seeded); the transmission family lives on the joints' travel in the
// training data.
Problem SplitPoses(const Robot& nominal, const Observations& obs,
                   const DiagnoseOptions& options) {
  Problem problem;
  problem.nominal = Chain::FromRobot(nominal);
  problem.base_state = StateWithChain(problem.nominal);
  problem.all = Measurements(problem.nominal, obs, &problem.base_state);
  const HoldoutSplit split =
      SplitHoldout(problem.all, options.holdout_fraction, options.seed);
  problem.train = PickRows(problem.all, split.train);
  problem.held = PickRows(problem.all, split.heldout);
  SetTransmissionTravel(problem.train, &problem.nominal);
  SetTransmissionTravel(problem.train, &problem.base_state.chain);
  for (auto* set : {&problem.all, &problem.train, &problem.held})
    for (Measurement& m : *set)
      FillTransmissionSines(problem.nominal, &m.input);
  return problem;
}

// Folds of the cross-validation (training poses only: the held-out poses
// stay out of the selection and are reported); 0 = the single held-out
// split.
int FoldCount(const Problem& problem, const Observations& obs,
              const DiagnoseOptions& options) {
  const int distinct = DistinctPoses(problem.train);
  int k = options.folds <= 1 ? 0 : options.folds;
  if (options.folds_given && k > distinct) {
    throw InputError(obs.source, 0, 0,
                     "--folds " + std::to_string(options.folds) + ": only " +
                         std::to_string(distinct) +
                         " distinct training poses (" +
                         std::to_string(problem.train.size()) + " of " +
                         std::to_string(problem.all.size()) +
                         " poses, the rest held out); use at most " +
                         std::to_string(distinct) +
                         " folds, or 0 for the single held-out split");
  }
  if (!options.folds_given) {
    k = std::min(k, distinct / DiagnoseOptions::kMinPosesPerFold);
  }
  return k >= 2 ? k : 0;
}

// The poses of the validation series (options.validation).
std::vector<Measurement> ValidationMeasurements(
    const Chain& nominal, const DiagnoseOptions& options) {
  std::vector<Measurement> validation;
  int frames = 0;  // one measuring frame per series of each file
  for (const Observations& v : options.validation) {
    ModelState scratch = StateWithChain(nominal);
    for (Measurement m : Measurements(nominal, v, &scratch)) {
      m.frame += frames;
      validation.push_back(m);
    }
    frames += scratch.NumFrames();
  }
  return validation;
}

// What every step of the selection reads.
struct Selection {
  Selection(const Problem& problem_in, const Observations& obs_in,
            const DiagnoseOptions& options_in)
      : problem(problem_in), obs(obs_in), options(options_in) {}

  const Problem& problem;
  const Observations& obs;
  const DiagnoseOptions& options;
  FoldPlan folds;
  std::vector<Measurement> validation;  // poses of the validation series
  int num_residuals = 0;                // 3 x training poses
  bool thermal_kelvin = false;          // thermal per kelvin, not per second

  // The cross-validation's refits of `free` in the geometry's box, on
  // `threads` threads (1 inside the candidates' parallel screening).
  FreeFitOptions CvOptions(const std::vector<ParamInfo>& free,
                           int threads = 1) const {
    FreeFitOptions o;
    o.free = free;
    o.bounds_center = &problem.nominal;
    o.bound_override = problem.bound_override;
    o.num_threads = threads;
    return o;
  }
  double Scale(const Candidate& c) const {
    return MagnitudeScale(c.cause, c.joint, problem.nominal, problem.all);
  }
  std::string Unit(const Candidate& c, const std::string& unit) const {
    return c.cause == "thermal" && thermal_kelvin ? std::string("mm/K") : unit;
  }
  bool WithFolds() const { return folds.folds >= 2; }
};

// The model the selection has reached and its figures.
struct CurrentModel {
  ModelState state;
  std::vector<ParamInfo> free;
  double rss = 0.0;  // training, mm^2
  double heldout_rms_mm = kNaN, validation_rms_mm = kNaN, cv_rms_mm = kNaN;
  std::vector<double> cv_err;  // out-of-fold squared error per training pose
};

// Step 2's figures: the base model (frame + identifiable geometry) on the
// training, held-out, folded and validation poses.
CurrentModel BaseModel(const Selection& selection, DiagnosisResult* out) {
  const Problem& problem = selection.problem;
  CurrentModel current;
  current.state = problem.base_state;
  current.free = problem.base_free;
  out->nominal_train_rms_mm = Rms(current.state, problem.train);
  out->nominal_heldout_rms_mm = Rms(current.state, problem.held);
  current.rss = Rss(current.state, problem.train);
  current.heldout_rms_mm = out->nominal_heldout_rms_mm;
  out->nominal_cv_rms_mm = CrossValidatedRms(
      problem.train, selection.folds, current.state,
      selection.CvOptions(current.free, selection.options.num_threads),
      selection.options.cv_refit, &current.cv_err);
  current.cv_rms_mm = out->nominal_cv_rms_mm;
  out->nominal_validation_rms_mm =
      ValidationRms(current.state, selection.validation);
  current.validation_rms_mm = out->nominal_validation_rms_mm;
  return current;
}

// One step's linearisation at the current model: residuals, the Jacobian
// of the current free parameters and of every candidate's (calib/
// exact_jacobian.h), and the normal equations the candidates' Gauss-Newton
// starts share.
struct StepLinearization {
  // The current model's measuring frames on the validation series (one per
  // series): the start of every candidate's re-registration.
  ModelState validation_frames;
  Eigen::VectorXd r0;                    // training residuals
  Eigen::MatrixXd cand_jac;              // columns of every candidate parameter
  std::map<std::string, int> column_of;  // a parameter's column, by name
  // Screening: each candidate is refitted with the geometry and the frame
  // free and the extensions accepted in earlier steps held at their fitted
  // values (a transmission series carries up to 24 of them). Holding them
  // can only raise a candidate's RSS, so its F-test is conservative; the
  // winner is refitted jointly with everything (RefitWinnerJointly).
  std::vector<ParamInfo> screen_free;
  Eigen::MatrixXd screen_jac;       // their columns
  Eigen::MatrixXd screen_normal;    // screen_jac^T screen_jac
  Eigen::VectorXd screen_gradient;  // screen_jac^T r0
  std::vector<bool> usable;         // identifiable against the current model

  Eigen::MatrixXd CandidateColumns(const Eigen::MatrixXd& jac,
                                   const Candidate& cand) const {
    Eigen::MatrixXd cols(jac.rows(), cand.params.size());
    for (size_t q = 0; q < cand.params.size(); ++q)
      cols.col(q) = jac.col(column_of.at(cand.params[q].name));
    return cols;
  }
};

// Linearises the step and reduces each candidate of `pool` (rebuilt from
// the catalogue) to what the data can determine against the current model.
StepLinearization Linearize(const Selection& selection,
                            const CurrentModel& current,
                            std::vector<Candidate>* pool) {
  const Problem& problem = selection.problem;
  StepLinearization lin;
  if (!selection.validation.empty()) {
    lin.validation_frames = current.state;
    lin.validation_frames.more_frames.clear();
    lin.validation_frames.frame_series.clear();
    InitializeFrameAndPoints(selection.validation, &lin.validation_frames);
  }
  const int threads = selection.options.num_threads;
  Eigen::MatrixXd base_jac;
  ResidualsAndJacobian(problem.train, current.state, current.free, &lin.r0,
                       &base_jac, threads);
  const Eigen::MatrixXd basis = Basis(Normalized(base_jac), threads);
  // (Drift is trimmed to its identifiable part below, so it starts whole
  // each step; gravity's joints come from the catalogue and are kept.)
  for (Candidate& c : *pool) {
    if (c.cause != "gravity")
      c = MakeCandidate(problem.nominal, c.cause, c.joint);
  }
  // Each parameter once (nested candidates share theirs: transmission8 is
  // the start of transmission16 and 24).
  std::vector<ParamInfo> all_params;
  for (const Candidate& cand : *pool) {
    for (const ParamInfo& q : cand.params) {
      if (lin.column_of.emplace(q.name, static_cast<int>(all_params.size()))
              .second)
        all_params.push_back(q);
    }
  }
  Eigen::VectorXd unused;
  ResidualsAndJacobian(problem.train, current.state, all_params, &unused,
                       &lin.cand_jac, threads);
  std::vector<int> screen_cols;
  for (size_t q = 0; q < current.free.size(); ++q) {
    if (current.free[q].kind == ParamKind::kJointError ||
        current.free[q].kind == ParamKind::kDrift)
      continue;
    lin.screen_free.push_back(current.free[q]);
    screen_cols.push_back(static_cast<int>(q));
  }
  lin.screen_jac.resize(base_jac.rows(), screen_cols.size());
  for (size_t q = 0; q < screen_cols.size(); ++q)
    lin.screen_jac.col(q) = base_jac.col(screen_cols[q]);
  lin.screen_normal = NormalMatrix(lin.screen_jac, threads);
  lin.screen_gradient = lin.screen_jac.transpose() * lin.r0;
  // Every candidate column off the current model's span, in one product.
  const Eigen::MatrixXd projected =
      ProjectedOffBasis(basis, lin.cand_jac, threads);
  lin.usable.resize(pool->size());
  for (size_t c = 0; c < pool->size(); ++c) {
    lin.usable[c] = ReduceToIdentifiable(
        lin.CandidateColumns(projected, (*pool)[c]), &(*pool)[c]);
  }
  return lin;
}

// One candidate's screening refit and its score.
struct CandidateFit {
  CandidateScore score;
  ModelState state;            // the refitted model
  double log_p = 0.0;          // log of the F-test's p-value
  std::vector<double> cv_err;  // out-of-fold squared error per training pose
};

// The Gauss-Newton step of the linearised joint model [screened, candidate
// columns] (normal equations, Jacobi-scaled), so that the refit needs few
// iterations; `gradient` gets the normal equations' right-hand side.
Eigen::VectorXd GaussNewtonStart(const StepLinearization& lin,
                                 const Eigen::MatrixXd& cand_cols,
                                 Eigen::VectorXd* gradient) {
  const int n_screen = static_cast<int>(lin.screen_jac.cols());
  const int k = static_cast<int>(cand_cols.cols());
  Eigen::MatrixXd normal(n_screen + k, n_screen + k);
  normal.topLeftCorner(n_screen, n_screen) = lin.screen_normal;
  normal.topRightCorner(n_screen, k) = lin.screen_jac.transpose() * cand_cols;
  normal.bottomLeftCorner(k, n_screen) =
      normal.topRightCorner(n_screen, k).transpose();
  normal.bottomRightCorner(k, k) = cand_cols.transpose() * cand_cols;
  gradient->resize(n_screen + k);
  gradient->head(n_screen) = lin.screen_gradient;
  gradient->tail(k) = cand_cols.transpose() * lin.r0;
  Eigen::VectorXd scale(normal.cols());
  for (int q = 0; q < normal.cols(); ++q) {
    scale[q] = normal(q, q) > 0 ? 1.0 / std::sqrt(normal(q, q)) : 1.0;
  }
  return scale.asDiagonal() * (scale.asDiagonal() * normal * scale.asDiagonal())
                                  .ldlt()
                                  .solve(-(scale.asDiagonal() * *gradient));
}

// Step 3: screens one candidate: refit (from the Gauss-Newton start), the
// F-test against the current model at the step's level `alpha`, the
// cross-validated / held-out and validation checks, its magnitude.
CandidateFit ScreenCandidate(const Selection& selection,
                             const StepLinearization& lin,
                             const CurrentModel& current, const Candidate& cand,
                             bool usable, double alpha) {
  const Problem& problem = selection.problem;
  const DiagnoseOptions& options = selection.options;
  CandidateFit fit;
  fit.state = current.state;
  CandidateScore& s = fit.score;
  s.cause = cand.cause;
  s.joint = cand.joint >= 0 ? problem.nominal.rows[cand.joint].name : "";
  s.k = static_cast<int>(cand.params.size());
  s.identifiable = usable;
  const int p = static_cast<int>(current.free.size());
  const double d2 = selection.num_residuals - p - s.k;
  if (!usable || d2 <= 0) {
    s.identifiable = false;
    s.train_rms_mm = s.heldout_rms_mm = kNaN;
    return fit;
  }
  std::vector<ParamInfo> refit_free = lin.screen_free;
  for (const ParamInfo& q : cand.params) refit_free.push_back(q);
  const FitOptions refit_options = problem.CandidateRefit(refit_free);
  Eigen::VectorXd gradient;
  const Eigen::VectorXd step = GaussNewtonStart(
      lin, lin.CandidateColumns(lin.cand_jac, cand), &gradient);
  for (int q = 0; q < static_cast<int>(refit_options.free.size()); ++q) {
    if (std::isfinite(step[q]))
      *ParamAddress(&fit.state, refit_options.free[q]) += step[q];
  }
  // A candidate whose linearised gain (the Gauss-Newton start's) is far
  // from significant (p above 100x the step's alpha) keeps the start: its
  // RSS there is that of a feasible model, an upper bound of the refit's,
  // so its F-test can only be conservative.
  const double lin_drop = std::max(0.0, -gradient.dot(step));
  const double lin_rss = std::max(current.rss - lin_drop, 1e-300);
  const bool hopeless = LogFUpperTail((lin_drop / s.k) / (lin_rss / d2), s.k,
                                      d2) > std::log(100.0 * alpha);
  // The refit returns its training RSS; the start's is computed.
  if (hopeless) {
    Eigen::VectorXd rt;
    ResidualsAndJacobian(problem.train, fit.state, {}, &rt, nullptr);
    s.rss = rt.squaredNorm();
  } else {
    s.rss =
        FreeFit(problem.train, FreeFitOptionsFrom(refit_options), &fit.state);
  }
  Eigen::VectorXd rh;
  ResidualsAndJacobian(problem.held, fit.state, {}, &rh, nullptr);
  s.train_rms_mm = std::sqrt(s.rss / static_cast<double>(problem.train.size()));
  s.heldout_rms_mm = problem.held.empty()
                         ? kNaN
                         : std::sqrt(rh.squaredNorm() /
                                     static_cast<double>(problem.held.size()));
  // RSS changes at the solver's precision are no evidence.
  double drop = current.rss - s.rss;
  if (drop < 1e-10 * current.rss) drop = 0.0;
  s.f = s.rss > 0 ? (drop / s.k) / (s.rss / d2)
                  : std::numeric_limits<double>::infinity();
  fit.log_p = LogFUpperTail(s.f, s.k, d2);
  s.p_value = std::exp(fit.log_p);
  const double explained_mm =
      std::sqrt(drop / static_cast<double>(problem.train.size()));
  // With folds the cross-validated RMS must drop (computed only for the
  // candidates that pass the F-test: the few that can win); without, the
  // single held-out split's.
  const bool f_passes = std::log(alpha) > fit.log_p && drop > 0 &&
                        explained_mm >= options.min_effect_mm;
  if (selection.WithFolds() && f_passes) {
    s.cv_rms_mm = CrossValidatedRms(problem.train, selection.folds, fit.state,
                                    selection.CvOptions(refit_options.free),
                                    options.cv_refit, &fit.cv_err);
    s.cv_z = PairedZ(current.cv_err, fit.cv_err);
  }
  const bool held_better =
      selection.WithFolds()
          ? s.cv_rms_mm < current.cv_rms_mm && s.cv_z > options.cv_min_z
          : problem.held.empty() || s.heldout_rms_mm < current.heldout_rms_mm;
  s.validation_rms_mm =
      ValidationRmsFrom(fit.state, lin.validation_frames, selection.validation);
  const bool validation_better =
      selection.validation.empty() ||
      s.validation_rms_mm < current.validation_rms_mm;
  s.significant = std::log(alpha) > fit.log_p && held_better &&
                  validation_better && explained_mm >= options.min_effect_mm;
  const Magnitude mag =
      CandidateMagnitude(cand, fit.state, FitSummary{}, selection.Scale(cand));
  s.magnitude = mag.value;
  s.unit = selection.Unit(cand, mag.unit);
  return fit;
}

// Step 4a: the step's winner among the significant candidates, -1 when
// none. With validation series the one that predicts them best (the F-test
// only admits); else with folds the lowest cross-validated RMS, ties
// (within `cv_tie_z` standard errors, paired over the training poses) to
// the most significant: the F-test's ranking prefers fewer parameters, and
// without the tie rule a candidate that nests the true one wins by its
// extra parameter's fit to the noise (docs/DIAGNOSE.md); else the most
// significant.
int SelectWinner(const Selection& selection,
                 const std::vector<CandidateFit>& fits, int step,
                 bool only_gravity = false) {
  // Gravity first after the first step (which names the dominant effect,
  // whatever it is): once a cause of the whole arm's weight (the joint
  // `gravity` model of the mount and the link masses, or the mount's
  // compliance alone) passes its tests, the step's winner is chosen among
  // those: they predict every configuration from the
  // weight, where the functions along the travel the data happen to cover
  // (transmission, cyclic) fit those data better but say nothing about the
  // configurations they did not visit (UR10 trained on series C alone: B
  // 0.99 mm without this rule, docs/DIAGNOSE.md).
  const auto gravity = [](const std::string& cause) {
    return cause == "gravity" || cause == "mount_compliance";
  };
  bool any_gravity = false;
  for (const CandidateFit& f : fits)
    any_gravity =
        any_gravity || (f.score.significant && gravity(f.score.cause));
  if (any_gravity && !only_gravity && step > 0) {
    std::vector<CandidateFit> physical = fits;
    for (CandidateFit& f : physical)
      f.score.significant = f.score.significant && gravity(f.score.cause);
    return SelectWinner(selection, physical, step, true);
  }
  const bool validation = !selection.validation.empty();
  int best = -1;
  for (size_t c = 0; c < fits.size(); ++c) {
    const CandidateScore& s = fits[c].score;
    if (!s.significant) continue;
    if (best < 0) {
      best = static_cast<int>(c);
      continue;
    }
    const CandidateScore& b = fits[best].score;
    const bool better =
        validation ? s.validation_rms_mm < b.validation_rms_mm
        : selection.WithFolds()
            ? s.cv_rms_mm < b.cv_rms_mm
            : (fits[c].log_p < fits[best].log_p ||
               (fits[c].log_p == fits[best].log_p && s.rss < b.rss));
    if (better) best = static_cast<int>(c);
  }
  if (best < 0 || validation || !selection.WithFolds() ||
      !(selection.options.cv_tie_z > 0))
    return best;
  const int cv_best = best;
  for (size_t c = 0; c < fits.size(); ++c) {
    if (!fits[c].score.significant || static_cast<int>(c) == cv_best) continue;
    if (PairedZ(fits[c].cv_err, fits[cv_best].cv_err) <
            selection.options.cv_tie_z &&
        fits[c].log_p < fits[best].log_p) {
      best = static_cast<int>(c);
    }
  }
  return best;
}

// Step 4b: the winner refitted jointly with the extensions held in
// screening, kept only when it fits the training poses better without
// predicting the validation series worse.
void RefitWinnerJointly(const Selection& selection, const CurrentModel& current,
                        const Candidate& winner, CandidateFit* fit) {
  const Problem& problem = selection.problem;
  const CandidateFit screened = *fit;
  std::vector<ParamInfo> refit_free = current.free;
  for (const ParamInfo& q : winner.params) refit_free.push_back(q);
  const FitOptions refit_options = problem.CandidateRefit(refit_free);
  const int threads = selection.options.num_threads;
  FreeFitOptions free_options = FreeFitOptionsFrom(refit_options);
  free_options.num_threads = threads;
  FreeFit(problem.train, free_options, &fit->state);
  CandidateScore& w = fit->score;
  w.rss = Rss(fit->state, problem.train);
  w.train_rms_mm = Rms(fit->state, problem.train);
  if (!problem.held.empty()) w.heldout_rms_mm = Rms(fit->state, problem.held);
  if (!selection.validation.empty())
    w.validation_rms_mm = ValidationRms(fit->state, selection.validation);
  w.magnitude = CandidateMagnitude(winner, fit->state, FitSummary{},
                                   selection.Scale(winner))
                    .value;
  if (selection.WithFolds()) {
    w.cv_rms_mm =
        CrossValidatedRms(problem.train, selection.folds, fit->state,
                          selection.CvOptions(refit_options.free, threads),
                          selection.options.cv_refit, &fit->cv_err);
  }
  if (!(w.rss <= screened.score.rss) ||
      (!selection.validation.empty() &&
       !(w.validation_rms_mm <= screened.score.validation_rms_mm))) {
    *fit = screened;
  }
}

// Step 4c: the finding of the winner `best`, with the candidates that
// predict the same errors on this data (RSS within the chi-square(1) 95 %
// point of the noise, and significant themselves).
Finding MakeFinding(const Selection& selection, const CurrentModel& current,
                    const std::vector<CandidateFit>& fits, int best,
                    double alpha) {
  const CandidateScore& b = fits[best].score;
  Finding f;
  f.cause = b.cause;
  f.joint = b.joint;
  f.heldout_rms_before_mm = current.heldout_rms_mm;
  f.heldout_rms_after_mm = b.heldout_rms_mm;
  f.validation_rms_before_mm = current.validation_rms_mm;
  f.validation_rms_after_mm = b.validation_rms_mm;
  f.cv_rms_before_mm = current.cv_rms_mm;
  f.cv_rms_after_mm = b.cv_rms_mm;
  f.train_rms_after_mm = b.train_rms_mm;
  f.f = b.f;
  f.p_value = b.p_value;
  const int p = static_cast<int>(current.free.size());
  const double sigma2 = b.rss / (selection.num_residuals - p - b.k);
  for (size_t c = 0; c < fits.size(); ++c) {
    const CandidateScore& s = fits[c].score;
    if (static_cast<int>(c) == best || !s.identifiable) continue;
    if (s.rss - b.rss < kChi2One95 * sigma2 &&
        std::log(alpha) > fits[c].log_p) {
      f.equivalent.push_back({s.cause, s.joint, s.magnitude, s.unit,
                              s.train_rms_mm, s.heldout_rms_mm});
    }
  }
  return f;
}

// Step 4d: a joint's error along the travel (transmission) and its low
// harmonics and gain describe nearly the same function inside the travel
// and differ outside it: once one kind is in the model, the other leaves
// the pool (together they drift apart along that near-degenerate direction
// and extrapolate wildly, docs/DIAGNOSE.md).
void ExcludeAlongTravel(const Candidate& won, std::vector<Candidate>* pool) {
  auto along_travel = [](const std::string& cause) {
    return TransmissionTerms(cause) > 0                     ? 1
           : (CyclicHarmonic(cause) > 0 || cause == "gain") ? 2
                                                            : 0;
  };
  const int won_kind = along_travel(won.cause);
  if (won_kind == 0) return;
  pool->erase(std::remove_if(pool->begin(), pool->end(),
                             [&](const Candidate& c) {
                               const int kind = along_travel(c.cause);
                               return c.joint == won.joint && kind > 0 &&
                                      kind != won_kind;
                             }),
              pool->end());
}

// Steps 3-4, repeated: greedy forward selection from the catalogue while a
// candidate stays significant; returns the accepted candidates in order
// (their findings in out->findings).
std::vector<Candidate> SelectCandidates(const Selection& selection,
                                        CurrentModel* current,
                                        DiagnosisResult* out) {
  const Problem& problem = selection.problem;
  const DiagnoseOptions& options = selection.options;
  std::vector<Candidate> pool =
      CatalogueCandidates(problem.nominal, problem.all, options.causes);
  std::vector<Candidate> accepted;
  // Residuals below this (mm per axis) are numerically exact data: nothing
  // measurable is left to explain.
  constexpr double kExactMm = 1e-7;
  for (int step = 0;
       step < options.max_findings && !pool.empty() &&
       current->rss > kExactMm * kExactMm * selection.num_residuals;
       ++step) {
    const StepLinearization lin = Linearize(selection, *current, &pool);
    const int tested = static_cast<int>(
        std::count(lin.usable.begin(), lin.usable.end(), true));
    if (tested == 0) break;
    const double alpha = options.false_alarm / tested;
    if (step == 0) out->bonferroni_alpha = alpha;
    std::vector<CandidateFit> fits(pool.size());
    ParallelFor(static_cast<int>(pool.size()), options.num_threads, [&](int c) {
      fits[c] = ScreenCandidate(selection, lin, *current, pool[c],
                                lin.usable[c], alpha);
    });
    std::vector<CandidateScore> scores;
    for (const CandidateFit& fit : fits) scores.push_back(fit.score);
    out->steps.push_back(scores);
    if (step == 0) {
      for (size_t c = 0; c < pool.size(); ++c) {
        if (!lin.usable[c])
          out->not_identifiable.push_back(pool[c].Label(problem.nominal));
      }
    }
    const int best = SelectWinner(selection, fits, step);
    if (best < 0) break;
    if (lin.screen_free.size() < current->free.size())
      RefitWinnerJointly(selection, *current, pool[best], &fits[best]);
    out->findings.push_back(
        MakeFinding(selection, *current, fits, best, alpha));
    accepted.push_back(pool[best]);
    const CandidateFit& won = fits[best];
    current->state = won.state;
    for (const ParamInfo& q : pool[best].params) current->free.push_back(q);
    current->rss = won.score.rss;
    current->heldout_rms_mm = won.score.heldout_rms_mm;
    current->validation_rms_mm = won.score.validation_rms_mm;
    current->cv_rms_mm = won.score.cv_rms_mm;
    current->cv_err = won.cv_err;
    pool.erase(pool.begin() + best);
    ExcludeAlongTravel(accepted.back(), &pool);
  }
  return accepted;
}

// Step 5: the selected model refitted on all poses; the findings' magnitudes
// and 95 % intervals from its covariance. Returns the refitted model and its
// fit.
struct Refit {
  ModelState state;
  FitSummary fit;
};
Refit FinalRefit(const Selection& selection, const CurrentModel& current,
                 const std::vector<Candidate>& accepted, DiagnosisResult* out) {
  ModelState final_state = current.state;
  FitOptions fit_options = selection.problem.Boxed(current.free);
  fit_options.compute_covariance = true;
  fit_options.num_threads = selection.options.num_threads;
  const FitSummary final_fit = FreeFitWithCovariance(
      selection.problem.all, FreeFitOptionsFrom(fit_options), &final_state);
  for (size_t i = 0; i < accepted.size(); ++i) {
    const Candidate& c = accepted[i];
    const Magnitude m =
        CandidateMagnitude(c, final_state, final_fit, selection.Scale(c));
    out->findings[i].magnitude = m.value;
    out->findings[i].unit = selection.Unit(c, m.unit);
    out->findings[i].ci_low = m.ci_low;
    out->findings[i].ci_high = m.ci_high;
  }
  return {final_state, final_fit};
}

// Step 6: the measurement noise per axis: stated, from repeated poses, or an
// upper bound from the nearest pose pairs.
void EstimateNoise(const DiagnoseOptions& options, const Problem& problem,
                   const ModelState& current, DiagnosisResult* out) {
  if (options.noise_mm > 0) {
    out->noise_mm = options.noise_mm;
    out->noise_source = "stated";
  } else if (const double rep = RepeatedPoseNoise(problem.all); rep > 0) {
    out->noise_mm = rep;
    out->noise_source = "repeated poses";
  } else if (const double nn = NearestPoseNoise(current, problem.train);
             nn > 0) {
    out->noise_mm = nn;
    out->noise_source = "nearest poses (upper bound)";
  } else {
    out->noise_source = "none";
  }
}

// Step 7: the systematic rest above the noise and, when it is clearly above
// (options.unexplained_ratio), the `unexplained` finding with what it
// depends on (a smooth correction over the pose inputs, chosen by
// cross-validation, tested on the held-out poses).
void UnexplainedRest(const Selection& selection, const CurrentModel& current,
                     DiagnosisResult* out) {
  const DiagnoseOptions& options = selection.options;
  const Problem& problem = selection.problem;
  const int dof =
      selection.num_residuals - static_cast<int>(current.free.size());
  if (!(out->noise_mm > 0 && dof >= 10)) return;
  const double s2 = out->residual_sigma_mm * out->residual_sigma_mm;
  const double n2 = out->noise_mm * out->noise_mm;
  out->systematic_rms_mm = std::sqrt(std::max(0.0, 3.0 * (s2 - n2)));
  if (!(out->residual_sigma_mm > options.unexplained_ratio * out->noise_mm &&
        out->systematic_rms_mm > options.min_effect_mm))
    return;
  Finding u;
  u.cause = "unexplained";
  u.magnitude = out->systematic_rms_mm;
  u.unit = "mm";
  // Chi-square interval of the residual variance (normal approximation).
  const double rel = kZ95 * std::sqrt(2.0 / dof);
  u.ci_low = std::sqrt(std::max(0.0, 3.0 * (s2 * (1 - rel) - n2)));
  u.ci_high = std::sqrt(std::max(0.0, 3.0 * (s2 * (1 + rel) - n2)));
  u.heldout_rms_before_mm = u.heldout_rms_after_mm = current.heldout_rms_mm;
  u.validation_rms_before_mm = u.validation_rms_after_mm =
      current.validation_rms_mm;
  u.cv_rms_before_mm = u.cv_rms_after_mm = current.cv_rms_mm;
  u.train_rms_after_mm = out->final_train_rms_mm;
  u.p_value = kNaN;
  u.f = s2 / n2;
  const SmoothCorrection sc = SmoothRest(selection.obs, problem, current.state);
  u.depends_on = sc.depends_on;
  u.cv_explained = sc.cv_explained;
  u.smooth_k = sc.k;
  u.single_inputs = sc.single;
  u.point_cv_explained = sc.point_cv_explained;
  if (!problem.held.empty()) u.heldout_rms_after_mm = sc.heldout_rms_after_mm;
  out->findings.push_back(u);
}

// Step 5b: where each periodic transmission finding is supported and where
// it is extrapolated (Finding::travel_lo ... extrapolated_peak).
void PeriodicSupportOf(const Problem& problem, const ModelState& final_state,
                       const std::vector<Candidate>& accepted,
                       DiagnosisResult* out) {
  constexpr double kRadToDeg = 180.0 / M_PI;
  constexpr double kStepRad = 0.5 / kRadToDeg;
  for (size_t i = 0; i < accepted.size(); ++i) {
    const Candidate& c = accepted[i];
    if (TransmissionTerms(c.cause) == 0) continue;
    const ChainRow& row = final_state.chain.rows[c.joint];
    if (!row.periodic()) continue;
    const double* coef =
        final_state.chain.joint_errors[c.joint].data() + kTransmission0;
    std::vector<double> q;
    double sum = 0.0, lo = 1e300, hi = -1e300;
    for (const Measurement& m : problem.train) {
      q.push_back(m.input.q[c.joint]);
      const double e = TransmissionError(coef, q.back(), row);
      sum += e;
      lo = std::min(lo, e);
      hi = std::max(hi, e);
    }
    if (q.empty()) continue;
    Finding& f = out->findings[i];
    const double mean = sum / static_cast<double>(q.size());
    f.periodic = true;
    f.travel_lo = *std::min_element(q.begin(), q.end()) * kRadToDeg;
    f.travel_hi = *std::max_element(q.begin(), q.end()) * kRadToDeg;
    f.amplitude = 0.5 * (hi - lo) * kRadToDeg;
    f.extrapolated = ExtrapolatedArcs(q, kWideGapMin);
    f.extrapolated_peak = 0.0;
    for (const auto& arc : f.extrapolated) {
      for (double x = arc[0] / kRadToDeg; x <= arc[1] / kRadToDeg;
           x += kStepRad) {
        f.extrapolated_peak = std::max(
            f.extrapolated_peak,
            std::abs(TransmissionError(coef, x, row) - mean) * kRadToDeg);
      }
    }
  }
}

// Per measured pose: its row, whether it was held out, the final residual.
void PerPoseResiduals(const Problem& problem, const ModelState& final_state,
                      DiagnosisResult* out) {
  std::set<int> held_rows;
  for (const Measurement& m : problem.held) held_rows.insert(m.row);
  for (const Measurement& m : problem.all) {
    out->rows.push_back(m.row);
    out->heldout.push_back(held_rows.count(m.row) > 0);
    out->residuals.push_back(Residual(final_state, m));
  }
}

}  // namespace

DiagnosisResult DiagnoseModel(const Robot& nominal, const Observations& obs,
                              const DiagnoseOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  options.Check();
  DiagnosisResult out;
  Problem problem = SplitPoses(nominal, obs, options);
  out.train_poses = static_cast<int>(problem.train.size());
  out.heldout_poses = static_cast<int>(problem.held.size());
  out.folds = FoldCount(problem, obs, options);
  FitBase(problem.train, obs, nominal.bounds_stated,
          GeometrySolver::kExactJacobian, options.num_threads, &problem);

  Selection selection(problem, obs, options);
  if (out.folds >= 2)
    selection.folds = MakeFolds(problem.train, out.folds, options.seed);
  selection.num_residuals = 3 * static_cast<int>(problem.train.size());
  selection.thermal_kelvin = ThermalUsesTemperature(obs);
  selection.validation = ValidationMeasurements(problem.nominal, options);
  CurrentModel current = BaseModel(selection, &out);
  const std::vector<Candidate> accepted =
      SelectCandidates(selection, &current, &out);
  out.final_train_rms_mm = Rms(current.state, problem.train);
  out.final_heldout_rms_mm = current.heldout_rms_mm;
  out.final_validation_rms_mm = current.validation_rms_mm;
  out.final_cv_rms_mm = current.cv_rms_mm;
  out.residual_sigma_mm = std::sqrt(
      current.rss / std::max(1, selection.num_residuals -
                                    static_cast<int>(current.free.size())));

  const Refit refit = FinalRefit(selection, current, accepted, &out);
  const ModelState& final_state = refit.state;
  PeriodicSupportOf(problem, final_state, accepted, &out);
  EstimateNoise(options, problem, current.state, &out);
  UnexplainedRest(selection, current, &out);
  out.verdict = out.findings.empty() ? "no_significant_effect" : "effect_found";
  PerPoseResiduals(problem, final_state, &out);
  if (current.state.NumFrames() > 1)
    out.series =
        CheckSeries(obs, problem.train, problem.held, current.state,
                    current.free, options.false_alarm, options.num_threads);
  out.state = final_state;
  FitRecordInput record;
  record.obs = &obs;
  record.fit = &refit.fit;
  record.state = &final_state;
  record.heldout_rms_mm = out.final_heldout_rms_mm;
  // The unexplained part of the residual: above a noise level that is known
  // (stated, or from repeated poses), the systematic rest where the residual
  // variance exceeds the noise's by more than 3 of its standard errors
  // (s^2 / n^2 - 1 > 3 sqrt(2 / dof); below that it is the sampling scatter
  // of s); above the nearest-pose estimate, which can fall either side of
  // the noise, only an `unexplained` finding (else 0); unknown without a
  // noise level.
  const int dof =
      selection.num_residuals - static_cast<int>(current.free.size());
  if ((out.noise_source == "stated" || out.noise_source == "repeated poses") &&
      dof > 0) {
    const double excess = out.residual_sigma_mm * out.residual_sigma_mm /
                              (out.noise_mm * out.noise_mm) -
                          1.0;
    record.systematic_rms_mm =
        excess > 3.0 * std::sqrt(2.0 / dof) ? out.systematic_rms_mm : 0.0;
  } else if (out.noise_source != "none") {
    record.systematic_rms_mm = 0.0;
    for (const Finding& f : out.findings) {
      if (f.cause == "unexplained") record.systematic_rms_mm = f.magnitude;
    }
  }
  out.extended =
      WithFitRecord(final_state.chain.ToRobot(nominal), nominal, record);
  std::vector<std::string> series_joints, units;
  for (const Finding& f : out.findings) {
    const int j = nominal.JointIndex(f.joint);
    // The cause label carries the series length (transmission8, ...); a
    // periodic series is held in its gaps by its regulariser and says where
    // it extrapolates (Finding::extrapolated) instead.
    if (f.cause.rfind("transmission", 0) != 0 || j < 0 || f.periodic) continue;
    series_joints.push_back(f.joint);
    units.push_back(nominal.joints[j].type == JointType::kPrismatic ? "mm"
                                                                    : "deg");
  }
  out.warnings = TravelGapWarnings(obs, series_joints, units);
  out.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
          .count();
  return out;
}

std::vector<Magnitude> FitCandidates(const Robot& nominal,
                                     const Observations& obs,
                                     const std::vector<std::string>& labels,
                                     double* sigma0_mm) {
  Problem problem;
  problem.nominal = Chain::FromRobot(nominal);
  problem.base_state = StateWithChain(problem.nominal);
  problem.all = Measurements(problem.nominal, obs, &problem.base_state);
  SetTransmissionTravel(problem.all, &problem.nominal);
  SetTransmissionTravel(problem.all, &problem.base_state.chain);
  for (Measurement& m : problem.all)
    FillTransmissionSines(problem.nominal, &m.input);
  FitBase(problem.all, obs, nominal.bounds_stated, GeometrySolver::kCeres,
          /*threads=*/1, &problem);
  const std::vector<Candidate> catalogue =
      CatalogueCandidates(problem.nominal, problem.all);
  const Eigen::MatrixXd basis = Basis(Normalized(
      ResidualJacobian(problem.all, problem.base_state, problem.base_free)));
  std::vector<Candidate> chosen(labels.size());
  std::vector<bool> found(labels.size(), false);
  FitOptions fit_options = problem.Boxed(problem.base_free);
  Eigen::MatrixXd model = basis;
  for (size_t i = 0; i < labels.size(); ++i) {
    for (const Candidate& c : catalogue) {
      if (c.Label(problem.nominal) != labels[i]) continue;
      const Eigen::MatrixXd cols =
          ResidualJacobian(problem.all, problem.base_state, c.params);
      if (!IdentifiableAgainst(model, cols)) break;
      model = Basis(Normalized([&] {
        Eigen::MatrixXd m(model.rows(), model.cols() + cols.cols());
        m << model, Normalized(cols);
        return m;
      }()));
      chosen[i] = c;
      found[i] = true;
      for (const ParamInfo& q : c.params) fit_options.free.push_back(q);
    }
  }
  ModelState state = problem.base_state;
  const FitSummary fit = Fit(problem.all, fit_options, &state);
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
        c, state, fit,
        MagnitudeScale(c.cause, c.joint, problem.nominal, problem.all)));
  }
  return out;
}

}  // namespace kincal
