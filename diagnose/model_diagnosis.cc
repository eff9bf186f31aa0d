#include "diagnose/model_diagnosis.h"

#include <Eigen/QR>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <set>
#include <sstream>
#include <thread>

#include "calib/calibrate.h"
#include "calib/identifiability.h"
#include "data/csv.h"
#include "data/error.h"
#include "data/provenance.h"
#include "data/yaml_util.h"

namespace kincal {
namespace {

constexpr double kRadToDeg = 180.0 / M_PI;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
// 97.5 % point of the standard normal and 95 % point of chi-square(1).
constexpr double kZ95 = 1.959963984540054;
constexpr double kChi2One95 = 3.841458820694124;
// sin(angle) of a candidate column against the span of the model's columns
// below which the candidate is structurally equivalent to the model.
constexpr double kIdentifiableSine = 1e-5;

const std::vector<std::string>& AllCauses() {
  static const std::vector<std::string> causes = {
      "backlash", "compliance", "cyclic", "gain", "axis_tilt", "drift"};
  return causes;
}

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

double MaxAbsTau(const std::vector<Measurement>& ms, int joint) {
  double m = 0.0;
  for (const Measurement& x : ms) m = std::max(m, std::abs(x.input.tau[joint]));
  return m;
}

// Log of the regularized incomplete beta I_x(a, b) (Numerical Recipes'
// continued fraction, evaluated where it converges fast).
double BetaContinuedFraction(double a, double b, double x) {
  const double tiny = 1e-300;
  double c = 1.0, d = 1.0 - (a + b) * x / (a + 1.0);
  if (std::abs(d) < tiny) d = tiny;
  d = 1.0 / d;
  double h = d;
  for (int m = 1; m <= 500; ++m) {
    const double m2 = 2.0 * m;
    double aa = m * (b - m) * x / ((a + m2 - 1.0) * (a + m2));
    d = 1.0 + aa * d;
    if (std::abs(d) < tiny) d = tiny;
    c = 1.0 + aa / c;
    if (std::abs(c) < tiny) c = tiny;
    d = 1.0 / d;
    h *= d * c;
    aa = -(a + m) * (a + b + m) * x / ((a + m2) * (a + m2 + 1.0));
    d = 1.0 + aa * d;
    if (std::abs(d) < tiny) d = tiny;
    c = 1.0 + aa / c;
    if (std::abs(c) < tiny) c = tiny;
    d = 1.0 / d;
    const double del = d * c;
    h *= del;
    if (std::abs(del - 1.0) < 1e-15) break;
  }
  return h;
}

double LogIncompleteBeta(double a, double b, double x) {
  if (x <= 0.0) return -std::numeric_limits<double>::infinity();
  if (x >= 1.0) return 0.0;
  const double log_front = std::lgamma(a + b) - std::lgamma(a) -
                           std::lgamma(b) + a * std::log(x) +
                           b * std::log1p(-x);
  if (x < (a + 1.0) / (a + b + 2.0)) {
    return log_front + std::log(BetaContinuedFraction(a, b, x)) - std::log(a);
  }
  const double rest = std::exp(
      log_front + std::log(BetaContinuedFraction(b, a, 1.0 - x)) - std::log(b));
  return std::log1p(-std::min(rest, 1.0));
}

// log P(F > f) for F(d1, d2).
double LogFUpperTail(double f, double d1, double d2) {
  if (!(f > 0)) return 0.0;
  return LogIncompleteBeta(0.5 * d2, 0.5 * d1, d2 / (d2 + d1 * f));
}

// Column-normalised Jacobian columns; zero columns stay zero.
Eigen::MatrixXd Normalized(Eigen::MatrixXd j) {
  for (int c = 0; c < j.cols(); ++c) {
    const double n = j.col(c).norm();
    if (n > 0) j.col(c) /= n;
  }
  return j;
}

// Orthonormal basis of the column span of `a` (rank-revealing QR).
Eigen::MatrixXd Basis(const Eigen::MatrixXd& a) {
  if (a.cols() == 0) return Eigen::MatrixXd(a.rows(), 0);
  Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(a);
  qr.setThreshold(1e-10);
  const int rank = static_cast<int>(qr.rank());
  Eigen::MatrixXd q =
      qr.householderQ() * Eigen::MatrixXd::Identity(a.rows(), rank);
  return q;
}

// Which columns of `cand` (normalised) keep a part outside the span of
// `basis` and of the candidate's earlier accepted columns.
std::vector<bool> IndependentColumns(const Eigen::MatrixXd& basis,
                                     Eigen::MatrixXd cand) {
  cand = Normalized(cand);
  Eigen::MatrixXd q = basis;
  std::vector<bool> out(cand.cols(), false);
  for (int c = 0; c < cand.cols(); ++c) {
    Eigen::VectorXd rest = cand.col(c);
    if (rest.norm() == 0) continue;
    for (int pass = 0; pass < 2 && q.cols() > 0; ++pass) {
      rest -= q * (q.transpose() * rest);
    }
    if (rest.norm() < kIdentifiableSine) continue;
    out[c] = true;
    q.conservativeResize(q.rows(), q.cols() + 1);
    q.col(q.cols() - 1) = rest / rest.norm();
  }
  return out;
}

// True when every column of `cand` is independent of `basis`.
bool IdentifiableAgainst(const Eigen::MatrixXd& basis,
                         const Eigen::MatrixXd& cand) {
  const std::vector<bool> ok = IndependentColumns(basis, cand);
  return std::all_of(ok.begin(), ok.end(), [](bool b) { return b; });
}

// The candidate reduced to what the data can determine against `basis`:
// drift keeps its identifiable components (a drift along a direction that
// geometry already explains is that geometry); other causes need all their
// parameters. Returns false when nothing is left.
bool ReduceToIdentifiable(const Eigen::MatrixXd& basis,
                          const Eigen::MatrixXd& cols, Candidate* c) {
  const std::vector<bool> ok = IndependentColumns(basis, cols);
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

int IndexOf(const FitSummary& fit, const std::string& name) {
  for (size_t i = 0; i < fit.params.size(); ++i) {
    if (fit.params[i].name == name) return static_cast<int>(i);
  }
  return -1;
}

// Runs `work(i)` for i in [0, n) on up to `threads` threads.
template <typename F>
void ParallelFor(int n, int threads, const F& work) {
  threads = std::max(1, std::min(threads, n));
  if (threads == 1) {
    for (int i = 0; i < n; ++i) work(i);
    return;
  }
  std::atomic<int> next(0);
  std::vector<std::thread> pool;
  for (int t = 0; t < threads; ++t) {
    pool.emplace_back([&] {
      for (int i = next++; i < n; i = next++) work(i);
    });
  }
  for (std::thread& t : pool) t.join();
}

// The per-axis noise from rows with identical joint readings; 0 when there
// are too few repeats (fewer than 6 degrees of freedom).
double RepeatedPoseNoise(const std::vector<Measurement>& ms) {
  std::map<std::vector<double>, std::vector<int>> groups;
  for (size_t i = 0; i < ms.size(); ++i) {
    groups[ms[i].input.q].push_back(static_cast<int>(i));
  }
  double sum = 0.0;
  int dof = 0;
  for (const auto& kv : groups) {
    if (kv.second.size() < 2) continue;
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (int i : kv.second) mean += ms[i].p_in_meas;
    mean /= static_cast<double>(kv.second.size());
    for (int i : kv.second) sum += (ms[i].p_in_meas - mean).squaredNorm();
    dof += 3 * (static_cast<int>(kv.second.size()) - 1);
  }
  return dof >= 6 ? std::sqrt(sum / dof) : 0.0;
}

// An upper bound on the per-axis noise from the model residuals of pose
// pairs that are nearest neighbours in joint space (each joint scaled by its
// spread): 0.5 E|r_i - r_j|^2 / 3 over the closest quarter of the pairs. A
// systematic error that varies smoothly with the pose adds to it, so it
// bounds the noise from above.
double NearestPoseNoise(const ModelState& state,
                        const std::vector<Measurement>& ms) {
  const int n = static_cast<int>(ms.size());
  if (n < 8) return 0.0;
  const int nj = static_cast<int>(ms[0].input.q.size());
  std::vector<double> scale(nj, 1.0);
  for (int j = 0; j < nj; ++j) {
    double mean = 0, sq = 0;
    for (const Measurement& m : ms) mean += m.input.q[j];
    mean /= n;
    for (const Measurement& m : ms) sq += std::pow(m.input.q[j] - mean, 2);
    const double sd = std::sqrt(sq / n);
    scale[j] = sd > 1e-12 ? 1.0 / sd : 0.0;
  }
  std::vector<Eigen::Vector3d> r(n);
  for (int i = 0; i < n; ++i) r[i] = Residual(state, ms[i]);
  std::vector<std::pair<double, double>> pairs;  // distance, half sq diff
  for (int i = 0; i < n; ++i) {
    double best = std::numeric_limits<double>::infinity();
    int arg = -1;
    for (int k = 0; k < n; ++k) {
      if (k == i) continue;
      double d = 0;
      for (int j = 0; j < nj; ++j) {
        d += std::pow((ms[i].input.q[j] - ms[k].input.q[j]) * scale[j], 2);
      }
      if (d < best) {
        best = d;
        arg = k;
      }
    }
    if (arg >= 0 && best > 0) {
      pairs.emplace_back(best, 0.5 * (r[i] - r[arg]).squaredNorm() / 3.0);
    }
  }
  if (pairs.size() < 4) return 0.0;
  std::sort(pairs.begin(), pairs.end());
  const size_t use = std::max<size_t>(4, pairs.size() / 4);
  double sum = 0;
  for (size_t i = 0; i < use; ++i) sum += pairs[i].second;
  return std::sqrt(sum / use);
}

struct Problem {
  Chain nominal;
  std::vector<Measurement> all, train, held;
  std::vector<ParamInfo> base_free;  // nuisance + identifiable geometry
  ModelState base_state;             // fitted on the training poses
};

// Frame (and points) registration, identifiability, geometric fit.
void FitBase(const std::vector<Measurement>& fit_on, const std::string& source,
             Problem* pb) {
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
  Fit(fit_on, frame_only, &state);

  std::vector<ParamInfo> candidates = nuisance;
  for (const ParamInfo& p : GeometryParams(state.chain))
    candidates.push_back(p);
  const Identifiability id = AnalyzeIdentifiability(fit_on, state, candidates);
  const int robot_params = id.RobotParameterCount();
  const int distinct = DistinctPoses(fit_on);
  if (robot_params == 0) {
    throw InputError(source, 0, 0,
                     "the data determine no robot parameter (" +
                         std::to_string(distinct) +
                         " distinct poses): use more poses that differ in "
                         "every joint");
  }
  const int num_free = static_cast<int>(id.identifiable.size());
  if (3 * static_cast<int>(fit_on.size()) <= num_free + 3) {
    throw InputError(source, 0, 0,
                     "too few poses: " + std::to_string(fit_on.size()) +
                         " training poses give " +
                         std::to_string(3 * fit_on.size()) + " equations for " +
                         std::to_string(num_free) +
                         " identifiable parameters plus the candidates; need "
                         "at least " +
                         std::to_string(num_free / 3 + 3) +
                         " distinct training poses (more for a useful "
                         "diagnosis)");
  }
  pb->base_free = id.identifiable;
  FitOptions geo;
  geo.free = pb->base_free;
  geo.bounds_center = &pb->nominal;
  geo.compute_covariance = false;
  Fit(fit_on, geo, &state);
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

Candidate MakeCandidate(const Chain& chain, const std::string& cause,
                        int joint) {
  Candidate c;
  c.cause = cause;
  c.joint = joint;
  if (cause == "backlash") {
    c.params = {JointErrorParam(chain, joint, kBacklash)};
  } else if (cause == "compliance") {
    c.params = {JointErrorParam(chain, joint, kCompliance)};
  } else if (CyclicHarmonic(cause) > 0) {
    const int k = CyclicCosIndex(CyclicHarmonic(cause));
    c.params = {JointErrorParam(chain, joint, k),
                JointErrorParam(chain, joint, k + 1)};
  } else if (cause == "gain") {
    c.params = {JointErrorParam(chain, joint, kGain)};
  } else if (cause == "axis_tilt") {
    c.params = {AxisTiltParam(chain, joint - 1)};
  } else if (cause == "drift") {
    c.params = DriftParams();
  }
  return c;
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
  for (const std::string& c : causes) {
    Require(std::find(AllCauses().begin(), AllCauses().end(), c) !=
                AllCauses().end(),
            "unknown cause '" + c +
                "' (backlash, compliance, cyclic, gain, axis_tilt, drift)");
  }
}

int CyclicHarmonic(const std::string& cause) {
  if (cause == "cyclic") return 1;
  for (int h = 2; h <= kMaxHarmonic; ++h) {
    if (cause == CyclicCause(h)) return h;
  }
  return 0;
}

std::string CyclicCause(int harmonic) {
  return harmonic == 1 ? "cyclic" : "cyclic" + std::to_string(harmonic);
}

std::string Candidate::Label(const Chain& chain) const {
  return joint < 0 ? cause : cause + ":" + chain.rows[joint].name;
}

std::vector<Candidate> CatalogueCandidates(
    const Chain& chain, const std::vector<Measurement>& ms,
    const std::vector<std::string>& causes_in) {
  const std::vector<std::string>& causes =
      causes_in.empty() ? AllCauses() : causes_in;
  auto wanted = [&](const std::string& c) {
    return std::find(causes.begin(), causes.end(), c) != causes.end();
  };
  std::vector<Candidate> out;
  const int nj = chain.num_joints();
  const std::vector<int> parallel = ParallelAxisRows(chain);
  for (int j = 0; j < nj; ++j) {
    bool pos = false, neg = false;
    double tau_min = std::numeric_limits<double>::infinity(),
           tau_max = -tau_min;
    for (const Measurement& m : ms) {
      pos = pos || m.input.s[j] > 0;
      neg = neg || m.input.s[j] < 0;
      tau_min = std::min(tau_min, m.input.tau[j]);
      tau_max = std::max(tau_max, m.input.tau[j]);
    }
    const bool revolute = chain.rows[j].type == JointType::kRevolute;
    if (wanted("backlash") && pos && neg)
      out.push_back(MakeCandidate(chain, "backlash", j));
    if (wanted("compliance") &&
        tau_max - tau_min > 1e-6 * std::max(1.0, std::abs(tau_max))) {
      out.push_back(MakeCandidate(chain, "compliance", j));
    }
    if (wanted("cyclic") && revolute) {
      // First harmonic (the spec's cyclic), then the higher ones, which pay
      // where a transmission error is not a pure eccentricity.
      for (int h = 1; h <= kMaxHarmonic; ++h) {
        out.push_back(MakeCandidate(chain, CyclicCause(h), j));
      }
    }
    if (wanted("gain")) out.push_back(MakeCandidate(chain, "gain", j));
    if (wanted("axis_tilt") && j >= 1 &&
        std::find(parallel.begin(), parallel.end(), j - 1) != parallel.end()) {
      out.push_back(MakeCandidate(chain, "axis_tilt", j));
    }
  }
  if (wanted("drift")) {
    double t_min = std::numeric_limits<double>::infinity(), t_max = -t_min;
    for (const Measurement& m : ms) {
      t_min = std::min(t_min, m.input.t_h);
      t_max = std::max(t_max, m.input.t_h);
    }
    if (t_max - t_min > 1e-9) out.push_back(MakeCandidate(chain, "drift", -1));
  }
  return out;
}

Magnitude CandidateMagnitude(const Candidate& c, const ModelState& state,
                             const FitSummary& fit, double max_abs_tau) {
  Magnitude m;
  const Chain& chain = state.chain;
  const bool revolute =
      c.joint >= 0 && chain.rows[c.joint].type == JointType::kRevolute;
  const double angle_unit = revolute ? kRadToDeg : 1.0;
  // Values (internal) and their covariance (internal, from the fit).
  const int k = static_cast<int>(c.params.size());
  Eigen::VectorXd v(k);
  Eigen::MatrixXd cov = Eigen::MatrixXd::Constant(k, k, kNaN);
  std::vector<int> idx(k);
  for (int a = 0; a < k; ++a) {
    v[a] = ParamValue(state, c.params[a]);
    idx[a] = IndexOf(fit, c.params[a].name);
  }
  const bool have_cov =
      fit.covariance.rows() == static_cast<int>(fit.params.size()) &&
      fit.covariance.rows() > 0;
  for (int a = 0; a < k; ++a) {
    for (int b = 0; b < k; ++b) {
      if (have_cov && idx[a] >= 0 && idx[b] >= 0) {
        cov(a, b) = fit.covariance(idx[a], idx[b]);
      }
    }
  }
  // magnitude = g(v); gradient for the delta method.
  Eigen::VectorXd grad = Eigen::VectorXd::Zero(k);
  if (c.cause == "backlash") {
    m.unit = revolute ? "deg" : "mm";
    m.value = v[0] * angle_unit;
    grad[0] = angle_unit;
  } else if (c.cause == "compliance") {
    m.unit = revolute ? "deg" : "mm";
    m.value = v[0] * max_abs_tau * angle_unit;
    grad[0] = max_abs_tau * angle_unit;
  } else if (c.cause == "gain") {
    m.unit = "1";
    m.value = v[0];
    grad[0] = 1.0;
  } else if (c.cause == "axis_tilt") {
    m.unit = "deg";
    m.value = v[0] * kRadToDeg;
    grad[0] = kRadToDeg;
  } else {  // cyclic (deg amplitude) and drift (mm/h norm)
    const bool cyclic = CyclicHarmonic(c.cause) > 0;
    const double unit = cyclic ? kRadToDeg : 1.0;
    m.unit = cyclic ? "deg" : "mm/h";
    const double norm = v.norm();
    m.value = norm * unit;
    if (norm > 0) grad = v / norm * unit;
  }
  const double var = grad.dot(cov * grad);
  m.sigma = var >= 0 ? std::sqrt(var) : kNaN;
  m.ci_low = m.value - kZ95 * m.sigma;
  m.ci_high = m.value + kZ95 * m.sigma;
  if (CyclicHarmonic(c.cause) > 0 || c.cause == "drift")
    m.ci_low = std::max(0.0, m.ci_low);
  return m;
}

double FDistributionUpperTail(double f, double d1, double d2) {
  return std::exp(LogFUpperTail(f, d1, d2));
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
  std::vector<int> train_idx, held_idx;
  SplitHoldout(pb.all, options.holdout_fraction, options.seed, &train_idx,
               &held_idx);
  pb.train = Pick(pb.all, train_idx);
  pb.held = Pick(pb.all, held_idx);
  out.train_poses = static_cast<int>(pb.train.size());
  out.heldout_poses = static_cast<int>(pb.held.size());
  FitBase(pb.train, obs.source, &pb);

  ModelState current = pb.base_state;
  std::vector<ParamInfo> current_free = pb.base_free;
  out.nominal_train_rms_mm = Rms(current, pb.train);
  out.nominal_heldout_rms_mm = Rms(current, pb.held);
  double current_rss = Rss(current, pb.train);
  double current_held = out.nominal_heldout_rms_mm;
  const int n_res = 3 * static_cast<int>(pb.train.size());

  std::vector<Candidate> pool =
      CatalogueCandidates(pb.nominal, pb.all, options.causes);
  std::vector<Candidate> accepted;
  std::vector<double> max_tau(pb.nominal.num_joints());
  for (int j = 0; j < pb.nominal.num_joints(); ++j)
    max_tau[j] = MaxAbsTau(pb.all, j);

  // Residuals below this (mm per axis) are numerically exact data: nothing
  // measurable is left to explain.
  constexpr double kExactMm = 1e-7;
  for (int step = 0; step < options.max_findings && !pool.empty() &&
                     current_rss > kExactMm * kExactMm * n_res;
       ++step) {
    // Identifiability of each candidate against the current model.
    const Eigen::MatrixXd base_raw =
        ResidualJacobian(pb.train, current, current_free);
    const Eigen::MatrixXd basis = Basis(Normalized(base_raw));
    Eigen::VectorXd r0(3 * pb.train.size());
    for (size_t i = 0; i < pb.train.size(); ++i) {
      r0.segment<3>(3 * i) = Residual(current, pb.train[i]);
    }
    // One Jacobian for all candidates' parameters, sliced per candidate.
    std::vector<ParamInfo> all_params;
    std::vector<int> first(pool.size());
    for (size_t c = 0; c < pool.size(); ++c) {
      pool[c] = MakeCandidate(pb.nominal, pool[c].cause, pool[c].joint);
      first[c] = static_cast<int>(all_params.size());
      for (const ParamInfo& q : pool[c].params) all_params.push_back(q);
    }
    const Eigen::MatrixXd cand_jac =
        ResidualJacobian(pb.train, current, all_params);
    std::vector<bool> usable(pool.size());
    for (size_t c = 0; c < pool.size(); ++c) {
      const int k = static_cast<int>(pool[c].params.size());
      usable[c] = ReduceToIdentifiable(basis, cand_jac.middleCols(first[c], k),
                                       &pool[c]);
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
      FitOptions fo;
      fo.free = current_free;
      for (const ParamInfo& q : cand.params) fo.free.push_back(q);
      // Start from the Gauss-Newton step of the linearised joint model, so
      // that Ceres needs few iterations.
      Eigen::MatrixXd a(base_raw.rows(), base_raw.cols() + s.k);
      for (int q = 0; q < s.k; ++q) {
        int col = first[c];
        while (all_params[col].name != cand.params[q].name) ++col;
        a.col(base_raw.cols() + q) = cand_jac.col(col);
      }
      a.leftCols(base_raw.cols()) = base_raw;
      Eigen::VectorXd scale(a.cols());
      for (int q = 0; q < a.cols(); ++q) {
        scale[q] = a.col(q).norm() > 0 ? 1.0 / a.col(q).norm() : 1.0;
      }
      const Eigen::VectorXd step =
          scale.asDiagonal() *
          (a * scale.asDiagonal()).colPivHouseholderQr().solve(-r0);
      for (int q = 0; q < static_cast<int>(fo.free.size()); ++q) {
        if (std::isfinite(step[q]))
          *ParamAddress(&states[c], fo.free[q]) += step[q];
      }
      fo.bounds_center = &pb.nominal;
      fo.compute_covariance = false;
      fo.max_iterations = 100;
      fo.function_tolerance = 1e-10;
      fo.parameter_tolerance = 1e-10;
      fits[c] = Fit(pb.train, fo, &states[c]);
      s.rss = Rss(states[c], pb.train);
      s.train_rms_mm = Rms(states[c], pb.train);
      s.heldout_rms_mm = Rms(states[c], pb.held);
      const double d2 = n_res - p - s.k;
      // RSS changes at the solver's precision are no evidence.
      double drop = current_rss - s.rss;
      if (drop < 1e-10 * current_rss) drop = 0.0;
      s.f = s.rss > 0 ? (drop / s.k) / (s.rss / d2)
                      : std::numeric_limits<double>::infinity();
      log_p[c] = LogFUpperTail(s.f, s.k, d2);
      s.p_value = std::exp(log_p[c]);
      const bool held_better =
          pb.held.empty() || s.heldout_rms_mm < current_held;
      const double explained_mm =
          std::sqrt(drop / static_cast<double>(pb.train.size()));
      s.significant = std::log(alpha) > log_p[c] && held_better &&
                      explained_mm >= options.min_effect_mm;
      s.magnitude =
          CandidateMagnitude(cand, states[c], fits[c],
                             cand.joint >= 0 ? max_tau[cand.joint] : 0.0)
              .value;
      s.unit = CandidateMagnitude(cand, states[c], fits[c], 1.0).unit;
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
      if (best < 0 || log_p[c] < log_p[best] ||
          (log_p[c] == log_p[best] && scores[c].rss < scores[best].rss)) {
        best = static_cast<int>(c);
      }
    }
    if (best < 0) break;
    const CandidateScore& b = scores[best];
    Finding f;
    f.cause = b.cause;
    f.joint = b.joint;
    f.heldout_rms_before_mm = current_held;
    f.heldout_rms_after_mm = b.heldout_rms_mm;
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
    pool.erase(pool.begin() + best);
  }
  out.final_train_rms_mm = Rms(current, pb.train);
  out.final_heldout_rms_mm = current_held;
  out.residual_sigma_mm = std::sqrt(
      current_rss / std::max(1, n_res - static_cast<int>(current_free.size())));

  // Final model on all poses: magnitudes and 95 % intervals.
  ModelState final_state = current;
  FitOptions fo;
  fo.free = current_free;
  fo.bounds_center = &pb.nominal;
  fo.compute_covariance = true;
  const FitSummary final_fit = Fit(pb.all, fo, &final_state);
  for (size_t i = 0; i < accepted.size(); ++i) {
    const Candidate& c = accepted[i];
    const Magnitude m = CandidateMagnitude(
        c, final_state, final_fit, c.joint >= 0 ? max_tau[c.joint] : 0.0);
    out.findings[i].magnitude = m.value;
    out.findings[i].unit = m.unit;
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
      u.train_rms_after_mm = out.final_train_rms_mm;
      u.p_value = kNaN;
      u.f = s2 / n2;
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
  FitBase(pb.all, obs.source, &pb);
  const std::vector<Candidate> catalogue =
      CatalogueCandidates(pb.nominal, pb.all);
  const Eigen::MatrixXd basis =
      Basis(Normalized(ResidualJacobian(pb.all, pb.base_state, pb.base_free)));
  std::vector<Candidate> chosen(labels.size());
  std::vector<bool> found(labels.size(), false);
  FitOptions fo;
  fo.free = pb.base_free;
  fo.bounds_center = &pb.nominal;
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
        c, state, fit, c.joint >= 0 ? MaxAbsTau(pb.all, c.joint) : 0.0));
  }
  return out;
}

namespace {
nlohmann::json Num(double v) {
  return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr);
}
// Internal causes cyclic2 / cyclic3 are the spec's cyclic at a higher
// harmonic: reported as cause "cyclic" with "harmonic" 2 or 3.
std::string SpecCause(const std::string& cause) {
  return CyclicHarmonic(cause) > 0 ? "cyclic" : cause;
}
nlohmann::json HarmonicOrNull(const std::string& cause) {
  const int h = CyclicHarmonic(cause);
  return h > 0 ? nlohmann::json(h) : nlohmann::json(nullptr);
}

nlohmann::json JointOrNull(const std::string& joint) {
  return joint.empty() ? nlohmann::json(nullptr) : nlohmann::json(joint);
}
}  // namespace

nlohmann::json DiagnosisJson(const DiagnosisResult& r,
                             const DiagnoseOptions& options) {
  nlohmann::json findings = nlohmann::json::array();
  for (const Finding& f : r.findings) {
    nlohmann::json eq = nlohmann::json::array();
    for (const Equivalent& e : f.equivalent) {
      eq.push_back({{"cause", SpecCause(e.cause)},
                    {"harmonic", HarmonicOrNull(e.cause)},
                    {"joint", JointOrNull(e.joint)},
                    {"magnitude", Num(e.magnitude)},
                    {"unit", e.unit},
                    {"train_rms_mm", Num(e.train_rms_mm)},
                    {"heldout_rms_mm", Num(e.heldout_rms_mm)}});
    }
    findings.push_back({{"cause", SpecCause(f.cause)},
                        {"harmonic", HarmonicOrNull(f.cause)},
                        {"joint", JointOrNull(f.joint)},
                        {"magnitude", Num(f.magnitude)},
                        {"unit", f.unit},
                        {"ci95", {Num(f.ci_low), Num(f.ci_high)}},
                        {"heldout_rms_before_mm", Num(f.heldout_rms_before_mm)},
                        {"heldout_rms_after_mm", Num(f.heldout_rms_after_mm)},
                        {"train_rms_after_mm", Num(f.train_rms_after_mm)},
                        {"f", Num(f.f)},
                        {"p_value", Num(f.p_value)},
                        {"equivalent", eq}});
  }
  nlohmann::json steps = nlohmann::json::array();
  for (const auto& step : r.steps) {
    nlohmann::json table = nlohmann::json::array();
    for (const CandidateScore& c : step) {
      table.push_back({{"cause", SpecCause(c.cause)},
                       {"harmonic", HarmonicOrNull(c.cause)},
                       {"joint", JointOrNull(c.joint)},
                       {"identifiable", c.identifiable},
                       {"parameters", c.k},
                       {"train_rms_mm", Num(c.train_rms_mm)},
                       {"heldout_rms_mm", Num(c.heldout_rms_mm)},
                       {"f", Num(c.f)},
                       {"p_value", Num(c.p_value)},
                       {"significant", c.significant},
                       {"magnitude", Num(c.magnitude)},
                       {"unit", c.unit}});
    }
    steps.push_back(table);
  }
  nlohmann::json j;
  j["verdict"] = r.verdict;
  j["nominal"] = {{"train_rms_mm", Num(r.nominal_train_rms_mm)},
                  {"heldout_rms_mm", Num(r.nominal_heldout_rms_mm)}};
  j["findings"] = findings;
  j["final"] = {{"heldout_rms_mm", Num(r.final_heldout_rms_mm)},
                {"train_rms_mm", Num(r.final_train_rms_mm)}};
  j["train_poses"] = r.train_poses;
  j["heldout_poses"] = r.heldout_poses;
  j["noise_mm"] = Num(r.noise_mm);
  j["noise_source"] = r.noise_source;
  j["residual_sigma_mm"] = Num(r.residual_sigma_mm);
  j["systematic_rms_mm"] = Num(r.systematic_rms_mm);
  j["false_alarm"] = options.false_alarm;
  j["bonferroni_alpha"] = Num(r.bonferroni_alpha);
  j["not_identifiable"] = r.not_identifiable;
  j["steps"] = steps;
  j["seed"] = options.seed;
  j["holdout_fraction"] = options.holdout_fraction;
  j["seconds"] = r.seconds;
  return j;
}

std::string ResidualsCsv(const DiagnosisResult& r, const Observations& obs) {
  std::ostringstream os;
  os << "# written by " << ToolVersion() << ": " << CommandLine() << "\n";
  os << "# residual = final model (all poses) - measured, measuring frame\n";
  os << "pose,set,dx_mm,dy_mm,dz_mm,error_mm\n";
  for (size_t i = 0; i < r.rows.size(); ++i) {
    const Eigen::Vector3d& e = r.residuals[i];
    os << CsvQuote(obs.rows[r.rows[i]].pose) << ","
       << (r.heldout[i] ? "heldout" : "train") << "," << FormatDouble(e.x())
       << "," << FormatDouble(e.y()) << "," << FormatDouble(e.z()) << ","
       << FormatDouble(e.norm()) << "\n";
  }
  return os.str();
}

}  // namespace kincal
