#include "diagnose/catalogue.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "data/error.h"
#include "diagnose/periodic_basis.h"

namespace kincal {
namespace {

constexpr double kRadToDeg = 180.0 / M_PI;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
// 97.5 % point of the standard normal.
constexpr double kZ95 = 1.959963984540054;

int IndexOf(const FitSummary& fit, const std::string& name) {
  for (size_t i = 0; i < fit.params.size(); ++i) {
    if (fit.params[i].name == name) return static_cast<int>(i);
  }
  return -1;
}

double MaxAbsTau(const std::vector<Measurement>& ms, int joint) {
  double m = 0.0;
  for (const Measurement& x : ms) m = std::max(m, std::abs(x.input.tau[joint]));
  return m;
}

double MaxAbsTauMass(const std::vector<Measurement>& ms, int joint) {
  double m = 0.0;
  for (const Measurement& x : ms) {
    if (static_cast<int>(x.input.tau_mass.size()) > joint)
      m = std::max(m, std::abs(x.input.tau_mass[joint]));
  }
  return m;
}

// Largest horizontal gravity moment about the base origin, N m.
double MaxMoment(const std::vector<Measurement>& ms) {
  double m = 0.0;
  for (const Measurement& x : ms)
    m = std::max(m, x.input.moment.head<2>().norm());
  return m;
}

// Nominal length of a row (dh / mdh: hypot(d, a); urdf: |xyz|), mm.
double RowLength(const Chain& chain, int row) {
  const RowBlock& p = chain.rows[row].p;
  return chain.convention == Convention::kUrdf
             ? std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2])
             : std::hypot(p[1], p[2]);
}

}  // namespace

const std::vector<std::string>& CatalogueCauses() {
  static const std::vector<std::string> causes = {
      "backlash",         "compliance",  "cyclic",       "gain",
      "axis_tilt",        "drift",       "elastostatic", "thermal",
      "mount_compliance", "transmission", "gravity"};
  return causes;
}

namespace {
constexpr int kTransmissionTermChoices[] = {8, 16, kMaxTransmissionTerms};
}  // namespace

int TransmissionTerms(const std::string& cause) {
  for (int t = 1; t <= kMaxTransmissionTerms; ++t) {
    if (cause == TransmissionCause(t)) return t;
  }
  return 0;
}

std::vector<int> TransmissionTermChoices(const ChainRow& row) {
  std::vector<int> out;
  if (!row.periodic()) {
    if (row.transmission_hi > row.transmission_lo)
      out.assign(std::begin(kTransmissionTermChoices),
                 std::end(kTransmissionTermChoices));
    return out;
  }
  const int supported = PeriodicSupport(row);
  for (int t : kTransmissionTermChoices) {
    if (t <= supported) out.push_back(t);
  }
  if (supported >= 2 && (out.empty() || out.back() < supported))
    out.push_back(supported);
  return out;
}

std::string TransmissionCause(int terms) {
  return "transmission" + std::to_string(terms);
}

std::string SpecCauseName(const std::string& cause) {
  if (CyclicHarmonic(cause) > 0) return "cyclic";
  if (TransmissionTerms(cause) > 0) return "transmission";
  return cause;
}

void SetTransmissionTravel(const std::vector<Measurement>& ms, Chain* chain,
                           const PeriodicBasisOptions& periodic) {
  for (int j = 0; j < chain->num_joints(); ++j) {
    ChainRow& row = chain->rows[j];
    if (row.transmission_hi > row.transmission_lo) continue;
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    std::vector<double> q;
    for (const Measurement& m : ms) {
      lo = std::min(lo, m.input.q[j]);
      hi = std::max(hi, m.input.q[j]);
      q.push_back(m.input.q[j]);
    }
    if (!(hi > lo)) continue;
    row.transmission_lo = lo;
    row.transmission_hi = hi;
    if (row.type == JointType::kRevolute && !row.periodic())
      row.periodic_basis = MakePeriodicBasis(q, periodic).basis;
  }
}

// The scale that turns a candidate's parameter into the spec's magnitude:
// the largest |torque| (compliance, elastostatic), the largest moment
// (mount), the row length (thermal); 1 otherwise.
double MagnitudeScale(const std::string& cause, int joint, const Chain& chain,
                      const std::vector<Measurement>& ms) {
  if (cause == "compliance") return MaxAbsTau(ms, joint);
  if (cause == "elastostatic") return MaxAbsTauMass(ms, joint);
  if (cause == "mount_compliance" || cause == "gravity") return MaxMoment(ms);
  if (cause == "thermal") return RowLength(chain, joint);
  return 1.0;
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
  } else if (cause == "elastostatic") {
    c.params = {JointErrorParam(chain, joint, kElastostatic)};
  } else if (cause == "thermal") {
    c.params = {JointErrorParam(chain, joint, kThermal)};
  } else if (cause == "mount_compliance") {
    c.params = {MountParams()[0]};
  } else if (cause == "gravity") {
    // The mount's compliance first (the magnitude), then the elastostatic
    // deflection of every joint: GravityCandidate picks the joints.
    c.params = {MountParams()[0]};
  } else if (TransmissionTerms(cause) > 0) {
    for (int k = 0; k < TransmissionTerms(cause); ++k)
      c.params.push_back(JointErrorParam(chain, joint, kTransmission0 + k));
  }
  return c;
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
      causes_in.empty() ? CatalogueCauses() : causes_in;
  auto wanted = [&](const std::string& c) {
    return std::find(causes.begin(), causes.end(), c) != causes.end();
  };
  std::vector<Candidate> out;
  const int nj = chain.num_joints();
  const std::vector<int> parallel = ParallelAxisRows(chain);
  std::vector<int> elastostatic;  // joints whose link-mass torque varies
  bool has_masses = false;
  for (const ChainRow& r : chain.rows)
    has_masses = has_masses || r.mass_kg >= 0;
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
    // Elastostatics needs the robot's link masses: without them the
    // uniform-beam proxy is the tip-mass compliance again on the last
    // joints (same torque shape), and the spec's cause must win.
    if ((wanted("elastostatic") || wanted("gravity")) && has_masses) {
      double lo = std::numeric_limits<double>::infinity(), hi = -lo;
      for (const Measurement& m : ms) {
        if (m.input.tau_mass.size() != static_cast<size_t>(nj)) continue;
        lo = std::min(lo, m.input.tau_mass[j]);
        hi = std::max(hi, m.input.tau_mass[j]);
      }
      if (hi - lo > 1e-6 * std::max(1.0, std::abs(hi))) {
        elastostatic.push_back(j);
        if (wanted("elastostatic"))
          out.push_back(MakeCandidate(chain, "elastostatic", j));
      }
    }
    if (wanted("thermal") && RowLength(chain, j) > 1e-6) {
      double lo = std::numeric_limits<double>::infinity(), hi = -lo;
      for (const Measurement& m : ms) {
        lo = std::min(lo, m.input.thermal_x);
        hi = std::max(hi, m.input.thermal_x);
      }
      if (hi - lo > 1e-9) out.push_back(MakeCandidate(chain, "thermal", j));
    }
    // The joint's error along its travel, coarse to fine (nested series):
    // needs the travel (SetTransmissionTravel) and enough distinct readings.
    const ChainRow& row = chain.rows[j];
    if (wanted("transmission")) {
      for (int t : TransmissionTermChoices(row))
        out.push_back(MakeCandidate(chain, TransmissionCause(t), j));
    }
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
  if (wanted("mount_compliance") && MaxMoment(ms) > 1e-9) {
    out.push_back(MakeCandidate(chain, "mount_compliance", -1));
  }
  // Gravity as one physical model: the mount's compliance and the link
  // masses' elastostatic deflections together (each alone may not pass a
  // step's test while together they carry another series' configurations).
  if (wanted("gravity") && MaxMoment(ms) > 1e-9 && !elastostatic.empty()) {
    Candidate g = MakeCandidate(chain, "gravity", -1);
    for (int j : elastostatic)
      g.params.push_back(JointErrorParam(chain, j, kElastostatic));
    out.push_back(g);
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
  } else if (c.cause == "elastostatic") {
    m.unit = revolute ? "deg" : "mm";
    m.value = v[0] * max_abs_tau * angle_unit;
    grad[0] = max_abs_tau * angle_unit;
  } else if (c.cause == "mount_compliance" || c.cause == "gravity") {
    // gravity: the mount's tilt at the largest moment; the joints'
    // elastostatic deflections are in the robot file.
    m.unit = "deg";
    m.value = v[0] * max_abs_tau * kRadToDeg;
    grad[0] = max_abs_tau * kRadToDeg;
  } else if (c.cause == "thermal") {
    m.unit = "mm/h";  // or mm/K, set by the caller from the data
    m.value = v[0] * max_abs_tau;
    grad[0] = max_abs_tau;
  } else if (c.cause == "gain") {
    m.unit = "1";
    m.value = v[0];
    grad[0] = 1.0;
  } else if (c.cause == "axis_tilt") {
    m.unit = "deg";
    m.value = v[0] * kRadToDeg;
    grad[0] = kRadToDeg;
  } else if (TransmissionTerms(c.cause) > 0 &&
             chain.rows[c.joint].periodic()) {
    // RMS of the periodic error over the readings its basis was built on
    // (diagnose/periodic_basis.h: the functions are orthonormal there): |c|.
    m.unit = "deg";
    const double norm = v.norm();
    m.value = norm * kRadToDeg;
    if (norm > 0) grad = v / norm * kRadToDeg;
  } else if (TransmissionTerms(c.cause) > 0) {
    // RMS of the error over the travel (calib/chain.h TransmissionError):
    // sqrt(|c|^2 / 2 - (m . c)^2).
    m.unit = revolute ? "deg" : "mm";
    Eigen::VectorXd mean(k);
    for (int a = 0; a < k; ++a)
      mean[a] = TransmissionMean(c.params[a].index - kTransmission0 + 1);
    const double mc = mean.dot(v);
    const double rms = std::sqrt(std::max(0.0, v.squaredNorm() / 2 - mc * mc));
    m.value = rms * angle_unit;
    if (rms > 0) grad = (v / 2 - mc * mean) / rms * angle_unit;
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
  if (CyclicHarmonic(c.cause) > 0 || TransmissionTerms(c.cause) > 0 ||
      c.cause == "drift")
    m.ci_low = std::max(0.0, m.ci_low);
  return m;
}

}  // namespace kincal
