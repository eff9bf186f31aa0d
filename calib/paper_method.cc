#include "calib/paper_method.h"

#include <Eigen/Dense>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numeric>
#include <sstream>

#include "data/error.h"

namespace kincal {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Fixed-point measurements with their groups renumbered 0..G-1.
struct Groups {
  std::vector<const Measurement*> ms;
  std::vector<int> group;        // per entry of ms
  std::vector<int> point_index;  // per group: ModelState point index
  std::vector<int> size;         // per group
};

Groups MakeGroups(const std::vector<Measurement>& all) {
  Groups g;
  for (const Measurement& m : all) {
    if (m.kind != Measurement::kFixedPoint) continue;
    auto it = std::find(g.point_index.begin(), g.point_index.end(), m.point);
    int k = static_cast<int>(it - g.point_index.begin());
    if (it == g.point_index.end()) {
      g.point_index.push_back(m.point);
      g.size.push_back(0);
    }
    g.ms.push_back(&m);
    g.group.push_back(k);
    ++g.size[k];
  }
  return g;
}

// Model tips of the group's poses, their group centroids and distances.
void TipsAndCentroids(const Chain& chain, const Groups& g,
                      std::vector<Eigen::Vector3d>* tips,
                      std::vector<Eigen::Vector3d>* centroids) {
  std::vector<const double*> rows;
  for (const ChainRow& r : chain.rows) rows.push_back(r.p.data());
  std::vector<const double*> errs;
  for (const auto& e : chain.joint_errors) errs.push_back(e.data());
  const bool with_errors = chain.HasJointErrors();
  tips->resize(g.ms.size());
  centroids->assign(g.size.size(), Eigen::Vector3d::Zero());
  for (size_t i = 0; i < g.ms.size(); ++i) {
    (*tips)[i] = TipInBase<double>(chain, rows.data(),
                                   with_errors ? errs.data() : nullptr,
                                   chain.drift.data(), g.ms[i]->input);
    (*centroids)[g.group[i]] += (*tips)[i];
  }
  for (size_t k = 0; k < g.size.size(); ++k) (*centroids)[k] /= g.size[k];
}

// eps(u) (+ the distance penalty) over the search variables u, where the
// parameter values are x = t0 + scale * u.
class PaperObjective {
 public:
  PaperObjective(const Groups& groups, const PaperOptions& options,
                 const std::vector<ParamInfo>& params, const ModelState& state)
      : groups_(groups), options_(options), work_(state) {
    for (const ParamInfo& p : params) {
      addr_.push_back(ParamAddress(&work_, p));
    }
    const int n = static_cast<int>(params.size());
    center_.resize(n);
    scale_.resize(n);
    lower_.resize(n);
    upper_.resize(n);
    const Chain& c = work_.chain;
    for (int i = 0; i < n; ++i) {
      const ParamInfo& p = params[i];
      const bool row = p.kind == ParamKind::kRow;
      center_[i] = row && options.bounds_center != nullptr
                       ? options.bounds_center->rows.at(p.block).p.at(p.index)
                       : *addr_[i];
      if (row || p.kind == ParamKind::kDrift) {
        scale_[i] = p.angle ? c.bound_angle_rad : c.bound_length_mm;
      } else if (p.index == kGain) {
        scale_[i] = 1e-2;  // dimensionless transmission error
      } else {
        scale_[i] = p.angle ? c.bound_angle_rad : c.bound_length_mm;
      }
      // The seed's |x - t0| <= delta holds for the geometry (rows); joint
      // error models have no such bound in the paper: a wide box.
      const double box = row && options.bounds_center != nullptr ? 1.0 : 1e3;
      lower_[i] = -box;
      upper_[i] = box;
    }
  }

  int size() const { return static_cast<int>(addr_.size()); }
  int evaluations() const { return evaluations_; }
  bool exhausted() const { return evaluations_ >= options_.max_evaluations; }

  Eigen::VectorXd Clamp(Eigen::VectorXd u) const {
    return u.cwiseMax(lower_).cwiseMin(upper_);
  }
  // u of the current state values.
  Eigen::VectorXd CurrentU() const {
    Eigen::VectorXd u(size());
    for (int i = 0; i < size(); ++i)
      u[i] = (*addr_[i] - center_[i]) / scale_[i];
    return Clamp(u);
  }
  void Set(const Eigen::VectorXd& u) {
    for (int i = 0; i < size(); ++i) *addr_[i] = center_[i] + scale_[i] * u[i];
  }

  double operator()(const Eigen::VectorXd& u) {
    ++evaluations_;
    Set(u);
    TipsAndCentroids(work_.chain, groups_, &tips_, &centroids_);
    double sum = 0.0;
    for (size_t i = 0; i < tips_.size(); ++i) {
      sum += (tips_[i] - centroids_[groups_.group[i]]).norm();
    }
    double f = sum / static_cast<double>(tips_.size());
    for (const PointDistance& d : options_.distances) {
      const int a = GroupOf(d.a), b = GroupOf(d.b);
      if (a < 0 || b < 0) continue;
      f += options_.distance_weight *
           std::abs((centroids_[a] - centroids_[b]).norm() - d.distance_mm);
    }
    return f;
  }

  const ModelState& state() const { return work_; }

 private:
  int GroupOf(int point) const {
    for (size_t k = 0; k < groups_.point_index.size(); ++k) {
      if (groups_.point_index[k] == point) return static_cast<int>(k);
    }
    return -1;
  }

  const Groups& groups_;
  const PaperOptions& options_;
  ModelState work_;
  std::vector<double*> addr_;
  Eigen::VectorXd center_, scale_, lower_, upper_;
  std::vector<Eigen::Vector3d> tips_, centroids_;
  int evaluations_ = 0;
};

// Nelder-Mead from `x` with edge `step`, adaptive coefficients (Gao & Han
// 2012: reflection 1, expansion 1 + 2/n, contraction 0.75 - 1/(2n), shrink
// 1 - 1/n). Stops when the simplex is flat (f spread < ftol) and small, or
// the evaluation budget is spent. Returns the best vertex in x, fx.
void NelderMead(PaperObjective& f, double step, Eigen::VectorXd* x,
                double* fx) {
  const int n = f.size();
  const double kExpand = 1.0 + 2.0 / n;
  const double kContract = 0.75 - 1.0 / (2.0 * n);
  const double kShrink = 1.0 - 1.0 / n;
  const double kFtol = 1e-13, kXtol = 1e-9;
  std::vector<Eigen::VectorXd> v(n + 1, *x);
  std::vector<double> fv(n + 1, *fx);
  for (int i = 0; i < n; ++i) {
    // Step inwards when the start sits on the upper bound.
    v[i + 1][i] += (*x)[i] + step <= 1.0 ? step : -step;
    v[i + 1] = f.Clamp(v[i + 1]);
    fv[i + 1] = f(v[i + 1]);
  }
  std::vector<int> order(n + 1);
  while (!f.exhausted()) {
    std::iota(order.begin(), order.end(), 0);
    std::sort(order.begin(), order.end(),
              [&](int a, int b) { return fv[a] < fv[b]; });
    const int best = order[0], worst = order[n], second = order[n - 1];
    double size = 0.0;
    for (int i = 0; i <= n; ++i) {
      size = std::max(size, (v[i] - v[best]).cwiseAbs().maxCoeff());
    }
    if (fv[worst] - fv[best] <= kFtol && size <= kXtol) break;
    if (size <= 1e-12) break;  // collapsed (e.g. onto a bound face)
    Eigen::VectorXd c = Eigen::VectorXd::Zero(n);
    for (int i = 0; i <= n; ++i) {
      if (i != worst) c += v[i];
    }
    c /= n;
    const Eigen::VectorXd xr = f.Clamp(c + (c - v[worst]));
    const double fr = f(xr);
    if (fr < fv[best]) {
      const Eigen::VectorXd xe = f.Clamp(c + kExpand * (xr - c));
      const double fe = f(xe);
      if (fe < fr) {
        v[worst] = xe;
        fv[worst] = fe;
      } else {
        v[worst] = xr;
        fv[worst] = fr;
      }
      continue;
    }
    if (fr < fv[second]) {
      v[worst] = xr;
      fv[worst] = fr;
      continue;
    }
    const bool outside = fr < fv[worst];
    const Eigen::VectorXd xc = outside
                                   ? f.Clamp(c + kContract * (xr - c))
                                   : f.Clamp(c - kContract * (c - v[worst]));
    const double fc = f(xc);
    if (fc < (outside ? fr : fv[worst])) {
      v[worst] = xc;
      fv[worst] = fc;
      continue;
    }
    for (int i = 0; i <= n; ++i) {
      if (i == best) continue;
      v[i] = f.Clamp(v[best] + kShrink * (v[i] - v[best]));
      fv[i] = f(v[i]);
    }
  }
  const int best =
      static_cast<int>(std::min_element(fv.begin(), fv.end()) - fv.begin());
  if (fv[best] < *fx) {
    *x = v[best];
    *fx = fv[best];
  }
}

// Cyclic coordinate ("variable rotation") pattern search: each parameter in
// turn is stepped by +-h_i; a success keeps the step and doubles h_i, a
// failure halves it. Stops when every h_i < min_step: then no single
// parameter step of that size improves f.
void CoordinateSearch(PaperObjective& f, double step, double min_step,
                      Eigen::VectorXd* x, double* fx) {
  const int n = f.size();
  Eigen::VectorXd h = Eigen::VectorXd::Constant(n, step);
  while (h.maxCoeff() >= min_step && !f.exhausted()) {
    for (int i = 0; i < n && !f.exhausted(); ++i) {
      if (h[i] < min_step) continue;
      bool improved = false;
      for (double dir : {1.0, -1.0}) {
        Eigen::VectorXd y = *x;
        y[i] += dir * h[i];
        y = f.Clamp(y);
        if (y[i] == (*x)[i]) continue;
        const double fy = f(y);
        if (fy < *fx) {
          *x = y;
          *fx = fy;
          improved = true;
          break;
        }
      }
      h[i] = improved ? std::min(2.0 * h[i], 1.0) : 0.5 * h[i];
    }
  }
}

}  // namespace

std::vector<double> PaperDistances(const ModelState& state,
                                   const std::vector<Measurement>& ms) {
  const Groups g = MakeGroups(ms);
  std::vector<Eigen::Vector3d> tips, centroids;
  TipsAndCentroids(state.chain, g, &tips, &centroids);
  std::vector<double> out;
  for (size_t i = 0; i < tips.size(); ++i) {
    out.push_back((tips[i] - centroids[g.group[i]]).norm());
  }
  return out;
}

double PaperEpsilon(const ModelState& state,
                    const std::vector<Measurement>& ms) {
  const std::vector<double> d = PaperDistances(state, ms);
  if (d.empty()) return kNaN;
  return std::accumulate(d.begin(), d.end(), 0.0) /
         static_cast<double>(d.size());
}

FitSummary FitPaperObjective(const std::vector<Measurement>& ms,
                             const PaperOptions& options, ModelState* state) {
  const auto start = std::chrono::steady_clock::now();
  const Groups groups = MakeGroups(ms);
  bool any_group = false;
  for (int s : groups.size) any_group = any_group || s >= 2;
  if (!any_group) {
    throw InputError(
        "the paper's method (eq. 9) needs fixed_point rows: at least one "
        "fixed point held in 2 or more poses");
  }
  std::vector<ParamInfo> params;
  for (const ParamInfo& p : options.free) {
    if (p.kind != ParamKind::kFrame && p.kind != ParamKind::kPoint) {
      params.push_back(p);
    }
  }

  FitSummary summary;
  PaperObjective f(groups, options, params, *state);
  Eigen::VectorXd u = f.CurrentU();
  double fu = f(u);
  summary.initial_rms_mm = [&] {
    const std::vector<double> d = PaperDistances(f.state(), ms);
    double s = 0;
    for (double v : d) s += v * v;
    return std::sqrt(s / d.size());
  }();
  int restarts = 0;
  std::ostringstream how;
  if (!params.empty()) {
    if (options.search != PaperOptions::kCoordinate) {
      how << "Nelder-Mead";
      for (restarts = 0; restarts <= options.max_restarts && !f.exhausted();
           ++restarts) {
        const double before = fu;
        NelderMead(f, options.initial_step, &u, &fu);
        if (before - fu < options.tolerance_mm) break;
      }
      how << " (" << restarts << " restarts)";
    }
    if (options.search != PaperOptions::kSimplex) {
      how << (how.str().empty() ? "" : " + ")
          << "cyclic coordinate search (variable rotation)";
      CoordinateSearch(f, options.initial_step, options.min_step, &u, &fu);
    }
  } else {
    how << "no free robot parameter: eps evaluated only";
  }
  f.Set(u);

  // Result into the state: parameters, fixed points = centroids.
  for (const ParamInfo& p : params) {
    *ParamAddress(state, p) = ParamValue(f.state(), p);
  }
  std::vector<Eigen::Vector3d> tips, centroids;
  TipsAndCentroids(state->chain, groups, &tips, &centroids);
  for (size_t k = 0; k < groups.point_index.size(); ++k) {
    for (int a = 0; a < 3; ++a) {
      state->points_in_base.at(groups.point_index[k])[a] = centroids[k][a];
    }
  }
  summary.residual_mm = PaperDistances(*state, ms);
  double sum_sq = 0.0;
  for (double v : summary.residual_mm) sum_sq += v * v;
  summary.final_rms_mm = std::sqrt(sum_sq / summary.residual_mm.size());
  summary.iterations = f.evaluations();
  summary.converged = !f.exhausted();
  std::ostringstream term;
  term << how.str() << ": eps " << PaperEpsilon(*state, ms) << " mm after "
       << f.evaluations() << " evaluations"
       << (f.exhausted() ? " (evaluation budget spent)" : "");
  summary.termination = term.str();

  // Linearised uncertainty: the least-squares form of the same data (points
  // free) at this solution, sigma0^2 (J^T J)^-1.
  std::vector<ParamInfo> all = params;
  for (int k : groups.point_index) {
    for (const ParamInfo& p : PointParams(*state)) {
      if (p.block == k) all.push_back(p);
    }
  }
  std::vector<Measurement> fixed;
  for (const Measurement* m : groups.ms) fixed.push_back(*m);
  const Eigen::MatrixXd J =
      ResidualJacobian(fixed, *state, all, options.distances);
  const int m_res = static_cast<int>(J.rows());
  const int p_num = static_cast<int>(all.size());
  summary.sigma0_mm =
      m_res > p_num ? std::sqrt(sum_sq / (m_res - p_num)) : kNaN;
  const Eigen::MatrixXd jtj = J.transpose() * J;
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(jtj);
  const bool regular = p_num > 0 && eig.eigenvalues().minCoeff() >
                                        1e-12 * eig.eigenvalues().maxCoeff();
  summary.covariance = regular
                           ? Eigen::MatrixXd(jtj.inverse() * summary.sigma0_mm *
                                             summary.sigma0_mm)
                           : Eigen::MatrixXd();
  for (int i = 0; i < p_num; ++i) {
    summary.params.push_back(all[i]);
    summary.values.push_back(all[i].ToInterface(ParamValue(*state, all[i])));
    summary.sigmas.push_back(
        regular ? all[i].ToInterface(std::sqrt(summary.covariance(i, i)))
                : kNaN);
  }
  summary.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
          .count();
  return summary;
}

}  // namespace kincal
