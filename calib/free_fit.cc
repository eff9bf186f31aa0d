#include "calib/free_fit.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>

#include "calib/exact_jacobian.h"

namespace kincal {
namespace {

// Bounds of the free parameters: +-delta about the nominal geometry for row
// entries (as calib/fit.h), none otherwise.
void Bounds(const FreeFitOptions& options, std::vector<double>* lower,
            std::vector<double>* upper) {
  const int k = static_cast<int>(options.free.size());
  lower->assign(k, -std::numeric_limits<double>::infinity());
  upper->assign(k, std::numeric_limits<double>::infinity());
  if (options.bounds_center == nullptr) return;
  const Chain& c = *options.bounds_center;
  for (int i = 0; i < k; ++i) {
    const ParamInfo& p = options.free[i];
    if (p.kind != ParamKind::kRow) continue;
    const double center = c.rows.at(p.block).p.at(p.index);
    (*lower)[i] = center - FreeFitBound(options, p);
    (*upper)[i] = center + FreeFitBound(options, p);
  }
}

// Levenberg-Marquardt on the exact Jacobian (calib/exact_jacobian.h),
// steps projected onto the bounds; stops as Ceres does: relative cost change
// <= function_tolerance or step <= parameter_tolerance (|x| +
// parameter_tolerance). Starts with a Gauss-Newton step (lambda 0); the
// candidate refits start at the linearised optimum, so one Jacobian and a
// few residual passes usually suffice. After a step that changed the cost by
// less than kChordChange (relative), the next step reuses the factorised
// Jacobian (a chord step: the Jacobian moved by O(step), far below what the
// tolerances see); a chord step that does not lower the cost is retried
// with a fresh Jacobian.
double BoundedLevenbergMarquardt(const std::vector<Measurement>& ms,
                                 const FreeFitOptions& options,
                                 ModelState* state) {
  constexpr double kChordChange = 1e-6;
  const int k = static_cast<int>(options.free.size());
  std::vector<double> lower, upper;
  Bounds(options, &lower, &upper);
  Eigen::VectorXd x(k);
  for (int i = 0; i < k; ++i) {
    x[i] = std::min(std::max(ParamValue(*state, options.free[i]), lower[i]),
                    upper[i]);
  }
  auto set = [&](const Eigen::VectorXd& v) {
    for (int i = 0; i < k; ++i) *ParamAddress(state, options.free[i]) = v[i];
  };
  set(x);
  Eigen::VectorXd r;
  Eigen::MatrixXd J;
  if (k == 0 || ms.empty()) {
    ResidualsAndJacobian(ms, *state, options.free, &r, nullptr,
                         options.num_threads);
    return r.squaredNorm();
  }
  double cost = 0.0;
  double lambda = 0.0;
  bool fresh = false;  // J belongs to x
  bool need_jacobian = true;
  Eigen::MatrixXd As;  // Jacobi-scaled J^T J of the last Jacobian
  Eigen::VectorXd s(k);
  for (int it = 0; it < options.max_iterations; ++it) {
    if (need_jacobian) {
      ResidualsAndJacobian(ms, *state, options.free, &r, &J,
                           options.num_threads);
      cost = r.squaredNorm();
      const Eigen::MatrixXd A = NormalMatrix(J, options.num_threads);
      for (int i = 0; i < k; ++i)  // Jacobi scaling, as Ceres
        s[i] = A(i, i) > 0 ? 1.0 / std::sqrt(A(i, i)) : 1.0;
      As = s.asDiagonal() * A * s.asDiagonal();
      fresh = true;
      need_jacobian = false;
    }
    const Eigen::VectorXd gs = s.asDiagonal() * (J.transpose() * r);
    bool accepted = false, converged = false;
    while (!accepted) {
      Eigen::MatrixXd M = As;
      M.diagonal().array() += lambda;
      const Eigen::VectorXd step = s.asDiagonal() * M.ldlt().solve(-gs);
      Eigen::VectorXd x_new = x + step;
      for (int i = 0; i < k; ++i)
        x_new[i] = std::min(std::max(x_new[i], lower[i]), upper[i]);
      const double step_norm = (x_new - x).norm();
      if (step.allFinite() &&
          step_norm <= options.parameter_tolerance *
                           (x.norm() + options.parameter_tolerance)) {
        converged = true;
        break;
      }
      Eigen::VectorXd r_new;
      double cost_new = std::numeric_limits<double>::infinity();
      if (step.allFinite()) {
        set(x_new);
        ResidualsAndJacobian(ms, *state, options.free, &r_new, nullptr,
                             options.num_threads);
        cost_new = r_new.squaredNorm();
      }
      if (std::isfinite(cost_new) && cost_new <= cost) {
        accepted = true;
        const double change = (cost - cost_new) / cost;
        x = x_new;
        r = r_new;
        cost = cost_new;
        lambda = lambda < 1e-9 ? 0.0 : lambda / 10.0;
        if (change <= options.function_tolerance) converged = true;
        need_jacobian = !(change < kChordChange && lambda == 0.0);
        fresh = false;
      } else {
        set(x);
        if (!fresh) {  // a chord step failed: take a fresh Jacobian
          need_jacobian = true;
          break;
        }
        lambda = lambda == 0.0 ? 1e-6 : 10.0 * lambda;
        if (lambda > 1e12) {
          converged = true;
          break;
        }
      }
    }
    if (converged) break;
  }
  set(x);
  return cost;
}

}  // namespace

double FreeFitBound(const FreeFitOptions& options, const ParamInfo& p) {
  auto it = options.bound_override.find(p.name);
  return it != options.bound_override.end()
             ? it->second
             : RowBound(*options.bounds_center, p);
}

FreeFitOptions FreeFitOptionsFrom(const FitOptions& fit_options) {
  FreeFitOptions o;
  o.free = fit_options.free;
  o.bounds_center = fit_options.bounds_center;
  o.bound_override = fit_options.bound_override;
  o.max_iterations = fit_options.max_iterations;
  o.function_tolerance = fit_options.function_tolerance;
  o.parameter_tolerance = fit_options.parameter_tolerance;
  o.num_threads = fit_options.num_threads;
  return o;
}

double FreeFit(const std::vector<Measurement>& measurements,
               const FreeFitOptions& options, ModelState* state) {
  return BoundedLevenbergMarquardt(measurements, options, state);
}

FitSummary FreeFitWithCovariance(const std::vector<Measurement>& measurements,
                                 const FreeFitOptions& options,
                                 ModelState* state) {
  FitSummary summary;
  int m = 0;
  for (const Measurement& x : measurements)
    m += x.kind == Measurement::kMeasured ? 1 : 0;
  summary.initial_rms_mm = 0.0;
  FreeFit(measurements, options, state);
  Eigen::VectorXd r;
  Eigen::MatrixXd J;
  ResidualsAndJacobian(measurements, *state, options.free, &r, &J,
                       options.num_threads);
  const int p = static_cast<int>(options.free.size());
  summary.converged = true;
  summary.params = options.free;
  for (int i = 0; i < static_cast<int>(measurements.size()); ++i)
    summary.residual_mm.push_back(r.segment<3>(3 * i).norm());
  summary.final_rms_mm = m > 0 ? std::sqrt(r.squaredNorm() / m) : 0.0;
  const int dof = 3 * static_cast<int>(measurements.size()) - p;
  summary.sigma0_mm = dof > 0 ? std::sqrt(r.squaredNorm() / dof) : 0.0;
  summary.values.resize(p);
  summary.sigmas.assign(p, std::numeric_limits<double>::quiet_NaN());
  for (int i = 0; i < p; ++i)
    summary.values[i] =
        options.free[i].ToInterface(ParamValue(*state, options.free[i]));
  if (p > 0 && dof > 0) {
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(NormalMatrix(J));
    const Eigen::VectorXd& l = eig.eigenvalues();
    const double lmax = l.maxCoeff();
    Eigen::VectorXd inv = Eigen::VectorXd::Zero(p);
    for (int i = 0; i < p; ++i)
      if (lmax > 0 && l[i] > 1e-14 * lmax) inv[i] = 1.0 / l[i];
    summary.covariance = summary.sigma0_mm * summary.sigma0_mm *
                         eig.eigenvectors() * inv.asDiagonal() *
                         eig.eigenvectors().transpose();
    for (int i = 0; i < p; ++i) {
      const double var = summary.covariance(i, i);
      const double sigma = var >= 0 ? std::sqrt(var) : NAN;
      summary.sigmas[i] =
          options.free[i].angle ? options.free[i].ToInterface(sigma) : sigma;
    }
  }
  return summary;
}

}  // namespace kincal
