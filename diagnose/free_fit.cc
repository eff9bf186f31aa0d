#include "diagnose/free_fit.h"

#include <ceres/ceres.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "diagnose/exact_jacobian.h"

namespace kincal {
namespace {

constexpr int kMaxJoints = 16;
// Derivatives per autodiff pass (32 was slower on UR10 C: 38.7 s CPU vs
// 18.6 s at 8, load ~11).
constexpr int kStride = 8;

// Where each free parameter goes: its block kind, block and index.
struct Slot {
  ParamKind kind;
  int block, index;
};

class FreeResidual {
 public:
  FreeResidual(const ModelState& state, const std::vector<Slot>& slots,
               const Measurement& m)
      : state_(state), slots_(slots), m_(m) {}

  template <typename T>
  bool operator()(T const* const* params, T* residual) const {
    const Chain& chain = state_.chain;
    const int n = chain.num_joints();
    std::array<std::array<T, kRowBlockSize>, kMaxJoints + 1> rows;
    std::array<std::array<T, kJointErrorBlockSize>, kMaxJoints> errs;
    std::array<T, kDriftBlockSize> global;
    std::array<T, kFrameBlockSize> frame;
    for (int r = 0; r <= n; ++r)
      for (int k = 0; k < kRowBlockSize; ++k)
        rows[r][k] = T(chain.rows[r].p[k]);
    for (int j = 0; j < n; ++j)
      for (int k = 0; k < kJointErrorBlockSize; ++k)
        errs[j][k] = T(chain.joint_errors[j][k]);
    for (int k = 0; k < kDriftBlockSize; ++k) global[k] = T(chain.drift[k]);
    for (int k = 0; k < kFrameBlockSize; ++k)
      frame[k] = T(state_.meas_from_base[k]);
    const T* x = params[0];
    for (size_t i = 0; i < slots_.size(); ++i) {
      const Slot& s = slots_[i];
      switch (s.kind) {
        case ParamKind::kRow:
          rows[s.block][s.index] = x[i];
          break;
        case ParamKind::kJointError:
          errs[s.block][s.index] = x[i];
          break;
        case ParamKind::kDrift:
          global[s.index] = x[i];
          break;
        case ParamKind::kFrame:
          frame[s.index] = x[i];
          break;
        case ParamKind::kPoint:
          break;  // not used by the diagnosis (measured rows only)
      }
    }
    const T* row_ptrs[kMaxJoints + 1];
    const T* err_ptrs[kMaxJoints];
    for (int r = 0; r <= n; ++r) row_ptrs[r] = rows[r].data();
    for (int j = 0; j < n; ++j) err_ptrs[j] = errs[j].data();
    const Vec3<T> tip =
        TipInBase<T>(chain, row_ptrs, err_ptrs, global.data(), m_.input);
    const Vec3<T> p = ApplyFrame(frame.data(), tip);
    for (int k = 0; k < 3; ++k) residual[k] = p[k] - m_.p_in_meas[k];
    return true;
  }

 private:
  const ModelState& state_;
  const std::vector<Slot>& slots_;
  const Measurement& m_;
};

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

// Levenberg-Marquardt on the exact Jacobian (diagnose/exact_jacobian.h),
// steps projected onto the bounds; stops as Ceres does: relative cost change
// <= function_tolerance or step <= parameter_tolerance (|x| +
// parameter_tolerance). Starts with a Gauss-Newton step (lambda 0); the
// candidate refits start at the linearised optimum, so one Jacobian and a
// few residual passes usually suffice. After a step that changed the cost by
// less than kChordChange (relative), the next step reuses the factorised
// Jacobian (a chord step: the Jacobian moved by O(step), far below what the
// tolerances see); a chord step that does not lower the cost is retried
// with a fresh Jacobian.
double ExactFreeFit(const std::vector<Measurement>& ms,
                    const FreeFitOptions& options, ModelState* state) {
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
    ResidualsAndJacobian(ms, *state, options.free, &r, nullptr);
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
      ResidualsAndJacobian(ms, *state, options.free, &r, &J);
      cost = r.squaredNorm();
      Eigen::MatrixXd A = Eigen::MatrixXd::Zero(k, k);
      A.selfadjointView<Eigen::Lower>().rankUpdate(J.transpose());
      A = A.selfadjointView<Eigen::Lower>();
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
        ResidualsAndJacobian(ms, *state, options.free, &r_new, nullptr);
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
  return o;
}

double FreeFit(const std::vector<Measurement>& measurements,
               const FreeFitOptions& options, ModelState* state) {
  if (options.exact_jacobian) return ExactFreeFit(measurements, options, state);
  const int k = static_cast<int>(options.free.size());
  std::vector<Slot> slots;
  std::vector<double> x(k);
  for (int i = 0; i < k; ++i) {
    const ParamInfo& p = options.free[i];
    slots.push_back({p.kind, p.block, p.index});
    x[i] = ParamValue(*state, p);
  }
  // The functors read the frozen values from this copy.
  const ModelState frozen = *state;
  ceres::Problem::Options po;
  ceres::Problem problem(po);
  std::vector<std::unique_ptr<FreeResidual>> keep;
  for (const Measurement& m : measurements) {
    if (m.kind != Measurement::kMeasured) continue;
    auto* cost = new ceres::DynamicAutoDiffCostFunction<FreeResidual, kStride>(
        new FreeResidual(frozen, slots, m));
    cost->AddParameterBlock(k);
    cost->SetNumResiduals(3);
    problem.AddResidualBlock(cost, nullptr, x.data());
  }
  if (k > 0 && problem.NumResidualBlocks() > 0) {
    std::vector<double> lower, upper;
    Bounds(options, &lower, &upper);
    for (int i = 0; i < k; ++i) {
      if (!std::isfinite(lower[i])) continue;  // no box (not a row entry)
      x[i] = std::min(std::max(x[i], lower[i]), upper[i]);
      problem.SetParameterLowerBound(x.data(), i, lower[i]);
      problem.SetParameterUpperBound(x.data(), i, upper[i]);
    }
    ceres::Solver::Options solver;
    solver.linear_solver_type = ceres::DENSE_QR;
    solver.max_num_iterations = options.max_iterations;
    solver.function_tolerance = options.function_tolerance;
    solver.parameter_tolerance = options.parameter_tolerance;
    solver.gradient_tolerance = 1e-14;
    solver.logging_type = ceres::SILENT;
    ceres::Solver::Summary summary;
    ceres::Solve(solver, &problem, &summary);
  }
  for (int i = 0; i < k; ++i) *ParamAddress(state, options.free[i]) = x[i];
  double rss = 0.0;
  for (const Measurement& m : measurements)
    rss += Residual(*state, m).squaredNorm();
  return rss;
}

FitSummary FreeFitWithCovariance(const std::vector<Measurement>& measurements,
                                 const FreeFitOptions& options,
                                 ModelState* state) {
  FitSummary summary;
  FreeFitOptions o = options;
  o.exact_jacobian = true;
  int m = 0;
  for (const Measurement& x : measurements)
    m += x.kind == Measurement::kMeasured ? 1 : 0;
  summary.initial_rms_mm = 0.0;
  FreeFit(measurements, o, state);
  Eigen::VectorXd r;
  Eigen::MatrixXd J;
  ResidualsAndJacobian(measurements, *state, options.free, &r, &J);
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
    Eigen::MatrixXd A = Eigen::MatrixXd::Zero(p, p);
    A.selfadjointView<Eigen::Lower>().rankUpdate(J.transpose());
    A = A.selfadjointView<Eigen::Lower>();
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(A);
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
