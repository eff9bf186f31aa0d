#include "plan/confirm.h"

#include <Eigen/Geometry>
#include <cmath>
#include <random>

#include "calib/chain.h"
#include "calib/fit.h"
#include "data/error.h"
#include "data/rigid3.h"

namespace kincal {
namespace {

PoseInput Input(const Chain& chain, const std::vector<double>& q) {
  PoseInput in;
  for (size_t j = 0; j < q.size(); ++j) {
    in.q.push_back(chain.ReadingToInternal(static_cast<int>(j), q[j]));
  }
  in.s.assign(q.size(), 0.0);
  in.tau.assign(q.size(), 0.0);
  return in;
}

Eigen::Vector3d TipInMeas(const ModelState& s, const PoseInput& in) {
  return ApplyFrame(s.meas_from_base.data(), TipInBase(s.chain, in, false));
}

bool IsRobot(const ParamInfo& p) {
  return p.kind != ParamKind::kFrame && p.kind != ParamKind::kPoint;
}

}  // namespace

ConfirmResult ConfirmDesign(const Robot& robot, const PlanResult& plan,
                            const std::vector<std::vector<double>>& poses,
                            const PlanOptions& plan_options,
                            const ConfirmOptions& options) {
  if (plan_options.fixed_point) {
    throw InputError("the Monte Carlo check supports free (measured) plans");
  }
  const Chain nominal = Chain::FromRobot(robot);
  std::mt19937_64 rng(options.seed);
  std::normal_distribution<double> gauss(0.0, 1.0);
  const size_t p = plan.params.size();
  std::vector<double> sum_sq(p, 0.0);
  double tip_sq = 0;
  long tip_n = 0;
  ConfirmResult result;
  std::vector<PoseInput> eval;
  for (const auto& q : plan.evaluation_poses) eval.push_back(Input(nominal, q));
  for (int rep = 0; rep < options.repetitions; ++rep) {
    ModelState truth;
    truth.chain = nominal;
    truth.meas_from_base = PoseBlockFromRigid3(plan.rig_from_base);
    for (const ParamInfo& info : plan.params) {
      if (!IsRobot(info)) continue;
      const double sd = info.angle ? options.sigma_angle_deg * M_PI / 180
                                   : options.sigma_length_mm;
      *ParamAddress(&truth, info) += sd * gauss(rng);
    }
    std::vector<Measurement> ms;
    for (size_t i = 0; i < poses.size(); ++i) {
      Measurement m;
      m.row = static_cast<int>(i);
      m.input = Input(nominal, poses[i]);
      m.p_in_meas = TipInMeas(truth, m.input);
      for (int k = 0; k < 3; ++k) {
        m.p_in_meas[k] += plan_options.noise_mm * gauss(rng);
      }
      ms.push_back(m);
    }
    ModelState est;
    est.chain = nominal;
    InitializeFrameAndPoints(ms, &est);
    FitOptions fit;
    fit.free = plan.params;
    fit.compute_covariance = false;
    const FitSummary summary = Fit(ms, fit, &est);
    if (!summary.converged) ++result.failed_fits;
    for (size_t k = 0; k < p; ++k) {
      const double e = plan.params[k].ToInterface(
          ParamValue(est, plan.params[k]) - ParamValue(truth, plan.params[k]));
      sum_sq[k] += e * e;
    }
    for (const PoseInput& in : eval) {
      tip_sq += (TipInMeas(est, in) - TipInMeas(truth, in)).squaredNorm();
      ++tip_n;
    }
  }
  double log_sum = 0;
  int count = 0;
  for (size_t k = 0; k < p; ++k) {
    result.rms_error.push_back(std::sqrt(sum_sq[k] / options.repetitions));
    if (!IsRobot(plan.params[k])) continue;
    const double bound =
        plan.params[k].angle ? robot.bound_angle_deg : robot.bound_length_mm;
    log_sum += std::log(result.rms_error.back() / bound);
    ++count;
  }
  result.error_gmean = std::exp(log_sum / std::max(1, count));
  result.tip_rms_mm = std::sqrt(tip_sq / std::max(1L, tip_n));
  return result;
}

}  // namespace kincal
