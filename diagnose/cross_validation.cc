#include "diagnose/cross_validation.h"

#include <Eigen/Cholesky>
#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <random>

#include "calib/exact_jacobian.h"
#include "calib/holdout.h"

namespace kincal {
namespace {

// The +-delta box of the free row entries (calib/fit.h's RowBound, as
// calib/free_fit.cc); no box for the other parameters.
void Box(const FreeFitOptions& o, Eigen::VectorXd* lower,
         Eigen::VectorXd* upper) {
  const int k = static_cast<int>(o.free.size());
  lower->setConstant(k, -std::numeric_limits<double>::infinity());
  upper->setConstant(k, std::numeric_limits<double>::infinity());
  if (o.bounds_center == nullptr) return;
  for (int i = 0; i < k; ++i) {
    const ParamInfo& p = o.free[i];
    if (p.kind != ParamKind::kRow) continue;
    const double center = o.bounds_center->rows.at(p.block).p.at(p.index);
    (*lower)[i] = center - FreeFitBound(o, p);
    (*upper)[i] = center + FreeFitBound(o, p);
  }
}

// Solves A d = b for the symmetric positive semi-definite A, Jacobi-scaled;
// the minimum-norm least-squares solution when A is singular.
Eigen::VectorXd SolveNormal(const Eigen::MatrixXd& A,
                            const Eigen::VectorXd& b) {
  const int k = static_cast<int>(A.rows());
  Eigen::VectorXd s(k);
  for (int i = 0; i < k; ++i)
    s[i] = A(i, i) > 0 ? 1.0 / std::sqrt(A(i, i)) : 1.0;
  const Eigen::MatrixXd As = s.asDiagonal() * A * s.asDiagonal();
  const Eigen::VectorXd bs = s.asDiagonal() * b;
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(As);
  Eigen::VectorXd y;
  if (ldlt.info() == Eigen::Success) y = ldlt.solve(bs);
  if (y.size() != k || !y.allFinite() || !ldlt.isPositive()) {
    y = Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd>(As).solve(bs);
  }
  return s.asDiagonal() * y;
}

}  // namespace

FoldPlan MakeFolds(const std::vector<Measurement>& ms, int folds,
                   uint64_t seed) {
  FoldPlan plan;
  plan.folds = folds;
  plan.fold_of.assign(ms.size(), 0);
  // Groups of identical joint readings within one series' frame, in order
  // of first appearance.
  std::map<std::pair<int, std::vector<double>>, int> group_of;
  std::vector<std::vector<int>> groups;
  for (size_t i = 0; i < ms.size(); ++i) {
    const std::pair<int, std::vector<double>> key(ms[i].frame, ms[i].input.q);
    auto it = group_of.find(key);
    if (it == group_of.end()) {
      it = group_of.emplace(key, static_cast<int>(groups.size())).first;
      groups.emplace_back();
    }
    groups[it->second].push_back(static_cast<int>(i));
  }
  std::vector<int> groups_in_order(groups.size());
  for (size_t g = 0; g < groups.size(); ++g)
    groups_in_order[g] = static_cast<int>(g);
  // A stream of its own, so that the folds do not repeat the held-out
  // split's shuffle (calib/holdout.h SplitHoldout uses `seed`).
  std::mt19937_64 rng(seed ^ 0x9e3779b97f4a7c15ULL);
  const std::vector<int> order = ShuffledIndices(groups_in_order, &rng);
  // Each group to the fold with the fewest poses of its series so far
  // (lowest index on ties): round robin when every pose is distinct, and
  // every series spread over the folds (stratified).
  std::map<int, std::vector<int>> size_of_frame;
  for (int g : order) {
    std::vector<int>& size = size_of_frame[ms[groups[g][0]].frame];
    size.resize(folds, 0);
    const int f = static_cast<int>(std::min_element(size.begin(), size.end()) -
                                   size.begin());
    for (int i : groups[g]) plan.fold_of[i] = f;
    size[f] += static_cast<int>(groups[g].size());
  }
  return plan;
}

double CrossValidatedRms(const std::vector<Measurement>& ms,
                         const FoldPlan& plan, const ModelState& fitted,
                         const FreeFitOptions& options, bool refit,
                         std::vector<double>* per_pose,
                         const Eigen::VectorXd* r_in,
                         const Eigen::MatrixXd* J_in) {
  const int K = plan.folds;
  if (K < 2 || ms.empty()) return std::numeric_limits<double>::quiet_NaN();
  std::vector<std::vector<int>> members(K);
  for (size_t i = 0; i < ms.size(); ++i)
    members[plan.fold_of[i]].push_back(static_cast<int>(i));
  const int P = static_cast<int>(options.free.size());
  double sum = 0.0;
  if (per_pose) per_pose->assign(ms.size(), 0.0);

  if (refit) {
    for (int f = 0; f < K; ++f) {
      std::vector<Measurement> rest, fold;
      for (size_t i = 0; i < ms.size(); ++i)
        (plan.fold_of[i] == f ? fold : rest).push_back(ms[i]);
      ModelState s = fitted;
      FreeFit(rest, options, &s);
      Eigen::VectorXd rk;
      ResidualsAndJacobian(fold, s, {}, &rk, nullptr);
      sum += rk.squaredNorm();
      if (per_pose) {
        for (int j = 0; j < static_cast<int>(members[f].size()); ++j)
          (*per_pose)[members[f][j]] = rk.segment<3>(3 * j).squaredNorm();
      }
    }
    return std::sqrt(sum / static_cast<double>(ms.size()));
  }

  Eigen::VectorXd r_own;
  Eigen::MatrixXd J_own;
  if (r_in == nullptr || J_in == nullptr) {
    ResidualsAndJacobian(ms, fitted, options.free, &r_own, &J_own,
                         options.num_threads);
    r_in = &r_own;
    J_in = &J_own;
  }
  const Eigen::VectorXd& r = *r_in;
  const Eigen::MatrixXd& J = *J_in;
  // Each fold's rows gathered once; its J^T J and J^T r; their totals.
  std::vector<Eigen::MatrixXd> Jf(K), Af(K);
  std::vector<Eigen::VectorXd> rf(K), gf(K);
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(P, P);
  Eigen::VectorXd g = Eigen::VectorXd::Zero(P);
  for (int f = 0; f < K; ++f) {
    const int m = static_cast<int>(members[f].size());
    Jf[f].resize(3 * m, P);
    rf[f].resize(3 * m);
    for (int j = 0; j < m; ++j) {
      Jf[f].middleRows<3>(3 * j) = J.middleRows<3>(3 * members[f][j]);
      rf[f].segment<3>(3 * j) = r.segment<3>(3 * members[f][j]);
    }
    Af[f] = NormalMatrix(Jf[f]);
    gf[f] = Jf[f].transpose() * rf[f];
    A += Af[f];
    g += gf[f];
  }
  Eigen::VectorXd lower, upper, x(P);
  Box(options, &lower, &upper);
  for (int i = 0; i < P; ++i) x[i] = ParamValue(fitted, options.free[i]);
  for (int f = 0; f < K; ++f) {
    Eigen::VectorXd d = Eigen::VectorXd::Zero(P);
    if (P > 0) {
      d = SolveNormal(A - Af[f], -(g - gf[f]));
      for (int i = 0; i < P; ++i)  // projected onto the box
        d[i] = std::min(std::max(x[i] + d[i], lower[i]), upper[i]) - x[i];
    }
    const Eigen::VectorXd e = rf[f] + Jf[f] * d;
    sum += e.squaredNorm();
    if (per_pose) {
      for (int j = 0; j < static_cast<int>(members[f].size()); ++j)
        (*per_pose)[members[f][j]] = e.segment<3>(3 * j).squaredNorm();
    }
  }
  return std::sqrt(sum / static_cast<double>(ms.size()));
}

double PairedZ(const std::vector<double>& a, const std::vector<double>& b) {
  const size_t n = std::min(a.size(), b.size());
  if (n < 2) return 0.0;
  double mean = 0.0;
  for (size_t i = 0; i < n; ++i) mean += a[i] - b[i];
  mean /= static_cast<double>(n);
  double var = 0.0;
  for (size_t i = 0; i < n; ++i) {
    const double d = a[i] - b[i] - mean;
    var += d * d;
  }
  var /= static_cast<double>(n - 1);
  if (var <= 0.0) {
    return mean == 0.0
               ? 0.0
               : std::copysign(std::numeric_limits<double>::infinity(), mean);
  }
  return mean / std::sqrt(var / static_cast<double>(n));
}

}  // namespace kincal
