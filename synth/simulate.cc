#include "synth/simulate.h"

#include <ceres/jet.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <sstream>

#include "calib/model_state.h"
#include "data/csv.h"
#include "data/error.h"

namespace kincal {
namespace {

constexpr double kDegToRad = M_PI / 180.0;
constexpr int kMaxJoints = 16;
using Jet = ceres::Jet<double, kMaxJoints>;

// Joint limits in internal units; defaults when the robot file has none.
void Limits(const Robot& robot, const Chain& chain, std::vector<double>* lo,
            std::vector<double>* hi) {
  for (int j = 0; j < chain.num_joints(); ++j) {
    const RobotRow& r = robot.joints[j];
    double l = r.type == JointType::kPrismatic ? 0.0 : -170.0;
    double h = r.type == JointType::kPrismatic ? 200.0 : 170.0;
    if (r.HasLimits()) {
      l = r.lower;
      h = r.upper;
    }
    lo->push_back(chain.ReadingToInternal(j, l));
    hi->push_back(chain.ReadingToInternal(j, h));
  }
}

Vec3<Jet> TipJet(const Chain& chain, const PoseInput& in, const Jet* q_read) {
  const int n = chain.num_joints();
  std::vector<std::array<Jet, kRowBlockSize>> rows(chain.rows.size());
  std::vector<const Jet*> row_ptrs;
  for (size_t r = 0; r < chain.rows.size(); ++r) {
    for (int k = 0; k < kRowBlockSize; ++k)
      rows[r][k] = Jet(chain.rows[r].p[k]);
    row_ptrs.push_back(rows[r].data());
  }
  Jet q[kMaxJoints];
  for (int j = 0; j < n; ++j) {
    const JointErrorBlock& e = chain.joint_errors[j];
    q[j] = (1.0 + e[kGain]) * q_read[j] - Jet(0.5 * in.s[j] * e[kBacklash]) +
           Jet(e[kCompliance] * in.tau[j]);
    if (in.tau_mass.size() == chain.rows.size() - 1)
      q[j] += Jet(e[kElastostatic] * in.tau_mass[j]);
    // Its value only: d/dq of the small transmission error is left out of
    // the IK's Jacobian (Newton still converges on the error's value).
    q[j] +=
        Jet(TransmissionError(&e[kTransmission0], q_read[j].a, chain.rows[j]));
    if (chain.rows[j].type == JointType::kRevolute) {
      for (int h = 1; h <= kMaxHarmonic; ++h) {
        const int k = CyclicCosIndex(h);
        q[j] += e[k] * cos(double(h) * q_read[j]) +
                e[k + 1] * sin(double(h) * q_read[j]);
      }
    }
  }
  Vec3<Jet> p = TipPosition<Jet>(chain, row_ptrs.data(), q);
  for (int k = 0; k < 3; ++k) p[k] += Jet(chain.drift[k] * in.t_h);
  return p;
}

// The simulation's random stream: one engine and its two distributions, drawn
// in a fixed order (the distributions keep state between draws).
struct RandomStream {
  explicit RandomStream(uint64_t seed) : rng(seed) {}
  double Normal() { return normal(rng); }
  double Uniform() { return uniform(rng); }
  std::mt19937_64 rng;
  std::normal_distribution<double> normal{0.0, 1.0};
  std::uniform_real_distribution<double> uniform{0.0, 1.0};
};

// The true chain: the nominal one with Gaussian deviations of the geometry
// parameters (all, or those named in `opt.perturbed`; one draw per parameter
// either way, so the stream does not depend on the selection).
Chain PerturbedTruth(const Chain& nominal_chain, const SimulateOptions& opt,
                     RandomStream* random) {
  Chain truth = nominal_chain;
  truth.joint_errors.assign(truth.num_joints(), JointErrorBlock{});
  truth.drift = {};
  for (const ParamInfo& p : GeometryParams(truth)) {
    if (!opt.perturbed.empty() &&
        std::find(opt.perturbed.begin(), opt.perturbed.end(), p.name) ==
            opt.perturbed.end()) {
      random->Normal();
      continue;
    }
    const double sigma =
        (p.kind == ParamKind::kRow && (truth.convention == Convention::kUrdf
                                           ? p.index >= 3
                                           : (p.index == 0 || p.index == 3)))
            ? opt.sigma_angle_deg * kDegToRad
            : opt.sigma_length_mm;
    truth.rows[p.block].p[p.index] += sigma * random->Normal();
  }
  return truth;
}

// Joint readings (internal units) of every pose and, in fixed-point mode,
// the point each pose reaches.
struct PosePlan {
  std::vector<std::vector<double>> poses;
  std::vector<int> point_of_pose;  // -1 in random mode
  std::vector<Eigen::Vector3d> point_targets;
};

PosePlan DrawPoses(const Chain& truth, const SimulateOptions& opt,
                   const std::vector<double>& lo, const std::vector<double>& hi,
                   RandomStream* random) {
  const int n = truth.num_joints();
  auto random_q = [&](double shrink) {
    std::vector<double> q(n);
    for (int j = 0; j < n; ++j) {
      const double mid = 0.5 * (lo[j] + hi[j]), half = 0.5 * (hi[j] - lo[j]);
      q[j] = mid + half * shrink * (2.0 * random->Uniform() - 1.0);
    }
    return q;
  };
  PosePlan plan;
  if (opt.mode == SimulateOptions::kRandom && !opt.readings.empty()) {
    for (const std::vector<double>& r : opt.readings) {
      Require(static_cast<int>(r.size()) == n,
              "given poses need one reading per joint");
      std::vector<double> q(n);
      for (int j = 0; j < n; ++j) q[j] = truth.ReadingToInternal(j, r[j]);
      plan.poses.push_back(q);
      plan.point_of_pose.push_back(-1);
    }
    return plan;
  }
  if (opt.mode == SimulateOptions::kRandom) {
    Require(opt.poses >= 1, "--poses must be >= 1");
    for (int i = 0; i < opt.poses; ++i) {
      plan.poses.push_back(random_q(1.0));
      plan.point_of_pose.push_back(-1);
    }
    return plan;
  }
  Require(opt.fixed_points >= 1 && opt.poses_per_point >= 1,
          "--fixed-points and --poses-per-point must be >= 1");
  PoseInput in;
  in.s.assign(n, 0.0);
  in.tau.assign(n, 0.0);
  for (int k = 0; k < opt.fixed_points; ++k) {
    in.q = random_q(0.6);
    const Eigen::Vector3d point = TipInBase(truth, in);
    plan.point_targets.push_back(point);
    int made = 0;
    for (int attempt = 0;
         made < opt.poses_per_point && attempt < 200 * opt.poses_per_point;
         ++attempt) {
      in.q = random_q(1.0);
      if (SolvePositionIk(truth, point, lo, hi, &in)) {
        plan.poses.push_back(in.q);
        plan.point_of_pose.push_back(k);
        ++made;
      }
    }
    if (made < opt.poses_per_point) {
      throw InputError("could not find " + std::to_string(opt.poses_per_point) +
                       " poses reaching fixed point " + std::to_string(k) +
                       " within the joint limits (found " +
                       std::to_string(made) + ")");
    }
  }
  return plan;
}

// Observation rows (readings in file units) in visit order.
Observations PlannedObservations(const Robot& nominal,
                                 const Chain& nominal_chain,
                                 const PosePlan& plan,
                                 const SimulateOptions& opt) {
  const int n = nominal_chain.num_joints();
  Observations obs;
  obs.source = "simulated";
  obs.joint_names = nominal.JointNames();
  for (size_t i = 0; i < plan.poses.size(); ++i) {
    Observation o;
    o.pose = std::to_string(i);
    for (int j = 0; j < n; ++j) {
      o.q.push_back(nominal_chain.InternalToReading(j, plan.poses[i][j]));
    }
    if (plan.point_of_pose[i] >= 0)
      o.fixed_point = "p" + std::to_string(plan.point_of_pose[i]);
    if (opt.seconds_per_pose > 0) o.t_s = opt.seconds_per_pose * i;
    obs.rows.push_back(o);
  }
  return obs;
}

// Puts effect `e` into the true chain, scaled on the poses' `inputs`;
// returns the note that says what was drawn.
std::string ApplyEffect(const Effect& e, const Robot& nominal,
                        const Chain& nominal_chain,
                        const std::vector<PoseInput>& inputs, Chain* truth_out,
                        RandomStream* random) {
  Chain& truth = *truth_out;
  std::ostringstream note;
  if (e.cause == "drift") {
    Eigen::Vector3d v(random->Normal(), random->Normal(), random->Normal());
    v = v.normalized() * e.magnitude;
    truth.drift = {v.x(), v.y(), v.z()};
    note << "drift v = [" << v.x() << ", " << v.y() << ", " << v.z()
         << "] mm/h";
    return note.str();
  }
  if (e.cause == "mount_compliance") {
    // Isotropic: the tilt at the largest gravity moment of the poses.
    double max_m = 0;
    for (const auto& in : inputs)
      max_m = std::max(max_m, in.moment.head<2>().norm());
    Require(max_m > 1e-9, "mount_compliance: no gravity moment in these poses");
    truth.drift[kMountIso] = e.magnitude * kDegToRad / max_m;
    note << "iso " << truth.drift[kMountIso] << " rad/Nm (max |M| " << max_m
         << " N m)";
    return note.str();
  }
  const int j = nominal.JointIndex(e.joint);
  const double unit =
      nominal.joints[j].type == JointType::kRevolute ? kDegToRad : 1.0;
  JointErrorBlock& err = truth.joint_errors[j];
  if (e.cause == "backlash") {
    err[kBacklash] = e.magnitude * unit;
  } else if (e.cause == "gain") {
    err[kGain] = e.magnitude;
  } else if (e.cause.rfind("cyclic", 0) == 0) {
    // cyclic = first harmonic; cyclic2, cyclic3 = higher harmonics.
    const int h = e.cause == "cyclic" ? 1 : e.cause.back() - '0';
    const double phase = 2 * M_PI * random->Uniform();
    err[CyclicCosIndex(h)] = e.magnitude * unit * std::cos(phase);
    err[CyclicCosIndex(h) + 1] = e.magnitude * unit * std::sin(phase);
    note << "phase " << phase / kDegToRad << " deg";
  } else if (e.cause == "compliance") {
    double max_tau = 0;
    for (const auto& in : inputs)
      max_tau = std::max(max_tau, std::abs(in.tau[j]));
    Require(max_tau > 1e-9,
            "compliance on joint '" + e.joint +
                "': gravity has no torque about it in these poses");
    err[kCompliance] = e.magnitude * unit / max_tau;
    note << "per_torque " << err[kCompliance] / unit << " (max |tau| "
         << max_tau << ")";
  } else if (e.cause == "elastostatic") {
    double max_tau = 0;
    for (const auto& in : inputs)
      max_tau = std::max(max_tau, std::abs(in.tau_mass[j]));
    Require(max_tau > 1e-9,
            "elastostatic on joint '" + e.joint +
                "': the link masses have no torque about it in these poses");
    err[kElastostatic] = e.magnitude * unit / max_tau;
    note << "per N m " << err[kElastostatic] / unit << " (max |tau| " << max_tau
         << " N m)";
  } else if (e.cause == "thermal") {
    // Magnitude: growth of the row's length, mm per unit of the thermal
    // input (h here: simulated sessions have no temperature).
    const RowBlock& p = nominal_chain.rows[j].p;
    const double length =
        nominal_chain.convention == Convention::kUrdf
            ? std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2])
            : std::hypot(p[1], p[2]);
    Require(length > 1e-6, "thermal on joint '" + e.joint +
                               "': its row has no length to grow");
    err[kThermal] = e.magnitude / length;
    note << "rate " << err[kThermal] << " per h (row length " << length
         << " mm)";
  } else if (e.cause == "transmission") {
    // An error along the joint's travel that is not the diagnosis' own
    // series: sines 3, 5 and 9 over a travel wider than the readings'
    // (30 % below, 20 % above; the error is neither zero nor symmetric
    // at the data's ends), random signs. Magnitude: RMS over that travel.
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (const auto& in : inputs) {
      lo = std::min(lo, in.q[j]);
      hi = std::max(hi, in.q[j]);
    }
    Require(hi > lo, "transmission on joint '" + e.joint +
                         "': the joint does not move in these poses");
    const double range = hi - lo;
    truth.rows[j].transmission_lo = lo - 0.3 * range;
    truth.rows[j].transmission_hi = hi + 0.2 * range;
    const int terms[3] = {3, 5, 9};
    const double weights[3] = {1.0, 0.7, 0.5};
    double norm2 = 0.0, mean = 0.0;
    for (int t = 0; t < 3; ++t) {
      const double sign = random->Uniform() < 0.5 ? -1.0 : 1.0;
      err[kTransmission0 + terms[t] - 1] = sign * weights[t];
      norm2 += weights[t] * weights[t];
      mean += sign * weights[t] * TransmissionMean(terms[t]);
    }
    const double to_rms =
        e.magnitude * unit / std::sqrt(norm2 / 2 - mean * mean);
    for (int t = 0; t < 3; ++t) err[kTransmission0 + terms[t] - 1] *= to_rms;
    note << "sines 3, 5, 9 over [" << truth.rows[j].transmission_lo / unit
         << ", " << truth.rows[j].transmission_hi / unit << "]";
  } else if (e.cause == "axis_tilt") {
    truth.rows[j - 1].p[4] += e.magnitude * kDegToRad;
    note << "beta on row " << truth.rows[j - 1].name;
  }
  return note.str();
}

// Fixed points: re-solves the readings so the true tip (with effects) is on
// the point plus placement noise; s and tau follow the readings.
void ReachFixedPoints(const Chain& truth, const Chain& nominal_chain,
                      const PosePlan& plan, const SimulateOptions& opt,
                      Observations* obs, std::vector<PoseInput>* inputs,
                      RandomStream* random) {
  const int n = nominal_chain.num_joints();
  for (int pass = 0; pass < 2; ++pass) {
    for (size_t i = 0; i < plan.poses.size(); ++i) {
      Eigen::Vector3d target = plan.point_targets[plan.point_of_pose[i]];
      if (pass == 1) {
        for (int k = 0; k < 3; ++k)
          target[k] += opt.noise_mm * random->Normal();
      }
      PoseInput in = (*inputs)[i];
      if (SolvePositionIk(truth, target, {}, {}, &in)) {
        for (int j = 0; j < n; ++j) {
          obs->rows[i].q[j] = nominal_chain.InternalToReading(j, in.q[j]);
        }
      }
    }
    *inputs = MakePoseInputs(nominal_chain, *obs);
  }
}

// The true base_from_tip of every pose (joint errors, drift at its time).
std::vector<Eigen::Matrix4d> TrueTipPoses(
    const Chain& truth, const std::vector<PoseInput>& inputs) {
  const int n = truth.num_joints();
  std::vector<Eigen::Matrix4d> base_from_tip;
  for (const PoseInput& in : inputs) {
    std::vector<double> q(n);
    for (int j = 0; j < n; ++j) {
      q[j] =
          ModelJointValue<double>(truth.rows[j], in.q[j], in.s[j], in.tau[j],
                                  truth.joint_errors[j].data(), in.tau_mass[j]);
    }
    Eigen::Matrix4d m = BaseFromTipAt(truth, q);
    for (int k = 0; k < 3; ++k) m(k, 3) += truth.drift[k] * in.t_h;
    base_from_tip.push_back(m);
  }
  return base_from_tip;
}

}  // namespace

bool SolvePositionIk(const Chain& chain, const Eigen::Vector3d& target,
                     const std::vector<double>& lower,
                     const std::vector<double>& upper, PoseInput* in,
                     double tolerance_mm) {
  const int n = chain.num_joints();
  KINCAL_CHECK(n <= kMaxJoints, "too many joints for IK: " << n);
  double lambda = 1e-3;
  auto eval = [&](const std::vector<double>& q, Eigen::Vector3d* r,
                  Eigen::MatrixXd* jac) {
    Jet qj[kMaxJoints];
    for (int j = 0; j < n; ++j) qj[j] = Jet(q[j], j);
    const Vec3<Jet> p = TipJet(chain, *in, qj);
    jac->resize(3, n);
    for (int k = 0; k < 3; ++k) {
      (*r)[k] = p[k].a - target[k];
      for (int j = 0; j < n; ++j) (*jac)(k, j) = p[k].v[j];
    }
  };
  std::vector<double> q = in->q;
  Eigen::Vector3d r;
  Eigen::MatrixXd jac;
  eval(q, &r, &jac);
  for (int it = 0; it < 200 && r.norm() > tolerance_mm; ++it) {
    // Scale prismatic and revolute columns alike (LM on J^T J + lambda I).
    const Eigen::MatrixXd jtj = jac.transpose() * jac;
    const Eigen::VectorXd g = jac.transpose() * r;
    Eigen::MatrixXd a = jtj;
    a.diagonal().array() += lambda * (1.0 + jtj.diagonal().array());
    const Eigen::VectorXd step = a.ldlt().solve(-g);
    std::vector<double> trial = q;
    for (int j = 0; j < n; ++j) trial[j] += step[j];
    Eigen::Vector3d r2;
    Eigen::MatrixXd jac2;
    eval(trial, &r2, &jac2);
    if (r2.norm() < r.norm()) {
      q = trial;
      r = r2;
      jac = jac2;
      lambda = std::max(lambda * 0.3, 1e-12);
    } else {
      lambda *= 10.0;
      if (lambda > 1e12) break;
    }
  }
  if (r.norm() > tolerance_mm) return false;
  for (int j = 0; j < n; ++j) {
    if (!lower.empty() && (q[j] < lower[j] || q[j] > upper[j])) return false;
  }
  in->q = q;
  return true;
}

Effect ParseEffect(const std::string& text, const Robot& robot) {
  std::vector<std::string> parts;
  std::stringstream ss(text);
  for (std::string p; std::getline(ss, p, ':');) parts.push_back(p);
  Effect e;
  double value = 0;
  const std::string usage =
      "--effect '" + text +
      "': expected cause:joint:magnitude (backlash, compliance, cyclic, gain, "
      "axis_tilt, elastostatic, thermal, transmission) or drift:magnitude "
      "or mount_compliance:magnitude";
  if (parts.size() == 2 &&
      (parts[0] == "drift" || parts[0] == "mount_compliance") &&
      ParseFiniteDouble(parts[1], &value)) {
    e.cause = parts[0];
    e.magnitude = value;
    return e;
  }
  if (parts.size() != 3 || !ParseFiniteDouble(parts[2], &value)) {
    throw InputError(usage);
  }
  e.cause = parts[0];
  e.joint = parts[1];
  e.magnitude = value;
  const bool cyclic =
      e.cause == "cyclic" || e.cause == "cyclic2" || e.cause == "cyclic3";
  if (e.cause != "backlash" && e.cause != "compliance" && !cyclic &&
      e.cause != "gain" && e.cause != "axis_tilt" &&
      e.cause != "elastostatic" && e.cause != "thermal" &&
      e.cause != "transmission") {
    throw InputError(usage);
  }
  const int j = robot.JointIndex(e.joint);
  if (j < 0) throw InputError(usage + ": no joint named '" + e.joint + "'");
  if (cyclic && robot.joints[j].type != JointType::kRevolute) {
    throw InputError(usage + ": cyclic applies to revolute joints");
  }
  if (e.cause == "axis_tilt") {
    const Chain c = Chain::FromRobot(robot);
    bool ok = false;
    for (int r : ParallelAxisRows(c)) ok = ok || r == j - 1;
    if (!ok) {
      throw InputError(usage + ": axis_tilt needs joint '" + e.joint +
                       "' to be nominally parallel to the joint before it");
    }
  }
  return e;
}

SimulatedSession Simulate(const Robot& nominal, const SimulateOptions& opt) {
  Require(opt.noise_mm >= 0, "noise must be >= 0");
  RandomStream random(opt.seed);

  SimulatedSession out;
  out.nominal = nominal;
  out.effects = opt.effects;
  const Chain nominal_chain = Chain::FromRobot(nominal);
  Chain truth = PerturbedTruth(nominal_chain, opt, &random);
  // Measuring frame: random rotation, origin at frame_distance.
  Eigen::Vector3d axis(random.Normal(), random.Normal(), random.Normal());
  axis.normalize();
  const double angle = M_PI * (0.2 + 0.6 * random.Uniform());
  Eigen::Vector3d dir(random.Normal(), random.Normal(), random.Normal());
  dir = dir.normalized() * opt.frame_distance_mm;
  out.meas_from_base = {axis.x() * angle, axis.y() * angle, axis.z() * angle,
                        dir.x(),          dir.y(),          dir.z()};
  if (opt.meas_from_base) out.meas_from_base = *opt.meas_from_base;

  std::vector<double> lo, hi;
  Limits(nominal, nominal_chain, &lo, &hi);
  const PosePlan plan = DrawPoses(truth, opt, lo, hi, &random);
  Observations& obs = out.observations;
  obs = PlannedObservations(nominal, nominal_chain, plan, opt);

  std::vector<PoseInput> inputs = MakePoseInputs(nominal_chain, obs);
  for (const Effect& e : opt.effects) {
    out.effect_notes.push_back(
        ApplyEffect(e, nominal, nominal_chain, inputs, &truth, &random));
  }
  if (opt.mode == SimulateOptions::kFixedPoint) {
    ReachFixedPoints(truth, nominal_chain, plan, opt, &obs, &inputs, &random);
  }

  const bool measure =
      opt.mode == SimulateOptions::kRandom || opt.measure_points;
  if (measure) {
    for (size_t i = 0; i < obs.rows.size(); ++i) {
      const Eigen::Vector3d tip = TipInBase(truth, inputs[i]);
      Eigen::Vector3d p =
          ApplyFrame(out.meas_from_base.data(), Vec3<double>(tip));
      for (int k = 0; k < 3; ++k) p[k] += opt.noise_mm * random.Normal();
      obs.rows[i].has_point = true;
      obs.rows[i].p_in_meas = p;
    }
  }
  out.base_from_tip = TrueTipPoses(truth, inputs);
  out.truth = truth.ToRobot(nominal);
  return out;
}

}  // namespace kincal
