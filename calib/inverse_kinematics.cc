#include "calib/inverse_kinematics.h"

#include <Eigen/Dense>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "data/error.h"

namespace kincal {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// The model's tip pose at internal joint values.
Eigen::Matrix4d PoseAtInternal(const Chain& chain,
                               const std::vector<double>& q_internal,
                               const IkContext& context, bool error_model) {
  PoseInput in = PoseInputAt(chain, q_internal);
  if (!context.s.empty()) in.s = context.s;
  in.t_h = context.t_h;
  in.thermal_x = context.thermal_x;
  if (!error_model) return BaseFromTipAt(chain, q_internal);
  return ModelBaseFromTip(chain, in);
}

// Residual: position (mm), then the weighted rotation vector of
// R(q) R_t^T (mm) when the target has a rotation.
Eigen::VectorXd Residual(const Eigen::Matrix4d& pose, const IkTarget& target,
                         double weight) {
  Eigen::VectorXd r(target.has_rotation ? 6 : 3);
  r.head<3>() = pose.block<3, 1>(0, 3) - target.position_mm;
  if (target.has_rotation) {
    const Eigen::AngleAxisd aa(pose.block<3, 3>(0, 0) *
                               target.rotation.transpose());
    r.tail<3>() = weight * aa.angle() * aa.axis();
  }
  return r;
}

struct Limits {
  std::vector<double> lo, hi;  // internal units, +-inf where absent
};

Limits InternalLimits(const Chain& chain, const IkOptions& options) {
  const int n = chain.num_joints();
  Limits l;
  l.lo.assign(n, -std::numeric_limits<double>::infinity());
  l.hi.assign(n, std::numeric_limits<double>::infinity());
  if (options.limits.empty()) return l;
  for (int j = 0; j < n; ++j) {
    const auto& lim = options.limits[j];
    if (lim[0] == lim[0]) l.lo[j] = chain.ReadingToInternal(j, lim[0]);
    if (lim[1] == lim[1]) l.hi[j] = chain.ReadingToInternal(j, lim[1]);
  }
  return l;
}

// One damped least-squares step with the joints in `fixed` held, plus the
// pull `toward` the seed projected on the null space of the held Jacobian
// (a redundant arm moves toward the seed without leaving the target).
Eigen::VectorXd DampedStep(const Eigen::MatrixXd& jac, const Eigen::VectorXd& r,
                           const std::vector<bool>& fixed, double lambda,
                           const Eigen::VectorXd& toward) {
  Eigen::MatrixXd j = jac;
  Eigen::VectorXd pull = toward;
  for (int c = 0; c < j.cols(); ++c) {
    if (fixed[c]) {
      j.col(c).setZero();
      pull[c] = 0.0;
    }
  }
  Eigen::MatrixXd a = j * j.transpose();
  a.diagonal().array() += lambda * lambda;
  const auto solver = a.ldlt();
  const Eigen::VectorXd task = j.transpose() * solver.solve(-r);
  const Eigen::VectorXd null = pull - j.transpose() * solver.solve(j * pull);
  return task + null;
}

}  // namespace

Eigen::Matrix4d ModelPoseAtReadings(const Chain& chain,
                                    const std::vector<double>& readings,
                                    const IkContext& context,
                                    bool use_error_model) {
  std::vector<double> q(readings.size());
  for (size_t j = 0; j < readings.size(); ++j) {
    q[j] = chain.ReadingToInternal(static_cast<int>(j), readings[j]);
  }
  return PoseAtInternal(chain, q, context, use_error_model);
}

IkResult SolveIk(const Chain& chain, const IkTarget& target,
                 const std::vector<double>& seed_readings,
                 const IkContext& context, const IkOptions& options) {
  const int n = chain.num_joints();
  KINCAL_CHECK(
      static_cast<int>(seed_readings.size()) == n,
      "IK seed has " << seed_readings.size() << " joints, chain " << n);
  const Limits limits = InternalLimits(chain, options);
  std::vector<double> q(n);
  for (int j = 0; j < n; ++j) {
    q[j] = std::clamp(chain.ReadingToInternal(j, seed_readings[j]),
                      limits.lo[j], limits.hi[j]);
  }
  const double w = options.rotation_weight_mm;
  auto residual_at = [&](const std::vector<double>& x) {
    return Residual(PoseAtInternal(chain, x, context, options.use_error_model),
                    target, w);
  };
  auto converged = [&](const Eigen::VectorXd& r) {
    if (r.head<3>().norm() > options.tolerance_mm) return false;
    return !target.has_rotation ||
           r.tail<3>().norm() / w <= options.tolerance_deg * M_PI / 180.0;
  };
  std::vector<double> unit(n);  // internal units per reading unit
  for (int j = 0; j < n; ++j) {
    unit[j] = chain.rows[j].type == JointType::kRevolute ? M_PI / 180.0 : 1.0;
  }
  Eigen::VectorXd seed_q(n);
  for (int j = 0; j < n; ++j) seed_q[j] = q[j];
  Eigen::VectorXd r = residual_at(q);
  int it = 0;
  std::vector<bool> fixed(n, false);
  // Phase 0 pulls toward the seed; phase 1, only when phase 0 ends short of
  // the target, finishes from there without the pull (plain damped least
  // squares converges where the pull and the task fight).
  for (int phase = 0; phase < 2 && !(phase == 1 && converged(r)); ++phase) {
    double lambda = 1e-3;
    // Stops when the target is reached and the seed pull has no component
    // left that keeps the target (the nearest solution to the seed).
    double null_motion = std::numeric_limits<double>::infinity();
    // Shrinks with rejected steps, like 1 / lambda; 0 in phase 1.
    double pull_gain = phase == 0 ? 1.0 : 0.0;
    for (int k = 0;
         k < options.max_iterations && !(converged(r) && null_motion < 1e-9);
         ++k, ++it) {
      // Central-difference Jacobian (internal units).
      Eigen::MatrixXd jac(r.size(), n);
      for (int j = 0; j < n; ++j) {
        constexpr double kH = 1e-6;
        std::vector<double> plus = q, minus = q;
        plus[j] += kH;
        minus[j] -= kH;
        // Columns per reading unit (deg | mm): steps and the seed pull are
        // measured in the units the joints are read in.
        jac.col(j) =
            (residual_at(plus) - residual_at(minus)) / (2 * kH) * unit[j];
      }
      // Joints on a limit whose unconstrained step points outward are held.
      std::fill(fixed.begin(), fixed.end(), false);
      Eigen::VectorXd toward(n);
      for (int j = 0; j < n; ++j) {
        toward[j] = pull_gain * (seed_q[j] - q[j]) / unit[j];
      }
      Eigen::VectorXd step = DampedStep(jac, r, fixed, lambda, toward);
      for (int j = 0; j < n; ++j) {
        fixed[j] = (q[j] <= limits.lo[j] && step[j] < 0) ||
                   (q[j] >= limits.hi[j] && step[j] > 0);
      }
      step = DampedStep(jac, r, fixed, lambda, toward);
      null_motion =
          (step - DampedStep(jac, r, fixed, lambda, Eigen::VectorXd::Zero(n)))
              .norm();
      // Limit the largest joint change per iteration (reading units).
      const double largest = step.cwiseAbs().maxCoeff();
      if (largest > options.max_step) step *= options.max_step / largest;
      std::vector<double> trial = q;
      for (int j = 0; j < n; ++j) {
        trial[j] =
            std::clamp(q[j] + step[j] * unit[j], limits.lo[j], limits.hi[j]);
      }
      const Eigen::VectorXd r_trial = residual_at(trial);
      // Accepted when the residual falls, or stays within the tolerance while
      // the null-space pull moves toward the seed.
      if (r_trial.squaredNorm() < r.squaredNorm() ||
          (converged(r_trial) && null_motion > 1e-9)) {
        q = trial;
        r = r_trial;
        lambda = std::max(lambda / 3.0, 1e-9);
        if (phase == 0) pull_gain = std::min(1.0, 2.0 * pull_gain);
      } else {
        lambda *= 4.0;
        pull_gain *= 0.25;
        if (lambda > 1e8) break;
      }
    }
  }
  IkResult out;
  out.iterations = it;
  out.reached = converged(r);
  out.position_error_mm = r.head<3>().norm();
  out.rotation_error_deg =
      target.has_rotation ? r.tail<3>().norm() / w * 180.0 / M_PI : 0.0;
  out.q.resize(n);
  for (int j = 0; j < n; ++j) {
    out.q[j] = chain.InternalToReading(j, q[j]);
    const double span = 1e-9 * std::max(1.0, std::abs(q[j]));
    if (!out.reached &&
        (q[j] <= limits.lo[j] + span || q[j] >= limits.hi[j] - span)) {
      out.at_limit.push_back(chain.rows[j].name);
    }
  }
  return out;
}

std::vector<double> ApproachDirections(const std::vector<double>& from,
                                       const std::vector<double>& to,
                                       const std::vector<double>& previous) {
  std::vector<double> s =
      previous.empty() ? std::vector<double>(to.size(), 0.0) : previous;
  if (from.empty()) return s;
  for (size_t j = 0; j < to.size(); ++j) {
    if (to[j] > from[j]) s[j] = 1.0;
    if (to[j] < from[j]) s[j] = -1.0;
  }
  return s;
}

std::vector<std::array<double, 2>> JointLimits(const Robot& robot) {
  std::vector<std::array<double, 2>> limits;
  for (const RobotRow& j : robot.joints) {
    limits.push_back(j.HasLimits() ? std::array<double, 2>{j.lower, j.upper}
                                   : std::array<double, 2>{kNaN, kNaN});
  }
  return limits;
}

}  // namespace kincal
