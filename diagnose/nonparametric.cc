#include "diagnose/nonparametric.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <random>

#include "diagnose/statistics.h"

namespace kincal {
namespace {

const std::vector<int>& Ks() {
  static const std::vector<int> ks = {3, 5, 10, 20, 40};
  return ks;
}

// Standardised copy of the columns (training SD; constant columns zero).
struct Scaled {
  std::vector<std::vector<double>> train, held;
  std::vector<bool> varies;
};

Scaled Standardise(const SmoothInputs& in) {
  Scaled s;
  const size_t d = in.names.size();
  s.varies.assign(d, false);
  std::vector<double> mean(d, 0.0), sd(d, 0.0);
  const double n = std::max<size_t>(1, in.train.size());
  for (const auto& x : in.train)
    for (size_t c = 0; c < d; ++c) mean[c] += x[c] / n;
  for (const auto& x : in.train)
    for (size_t c = 0; c < d; ++c) sd[c] += std::pow(x[c] - mean[c], 2) / n;
  for (size_t c = 0; c < d; ++c) {
    sd[c] = std::sqrt(sd[c]);
    s.varies[c] = sd[c] > 1e-12;
  }
  auto scale = [&](const std::vector<std::vector<double>>& rows) {
    std::vector<std::vector<double>> out = rows;
    for (auto& x : out)
      for (size_t c = 0; c < d; ++c)
        x[c] = s.varies[c] ? (x[c] - mean[c]) / sd[c] : 0.0;
    return out;
  };
  s.train = scale(in.train);
  s.held = scale(in.held);
  return s;
}

// Squared prediction errors for every k in Ks() of the queries `q` from the
// references `ref` (kNN mean of their residuals) over the input subset. The
// neighbours are ordered by (distance, index), a strict order, so selecting
// them with nth_element gives the same neighbours as a full sort; queries
// run on two threads, their errors summed in query order.
void KnnErrors(const std::vector<std::vector<double>>& x_ref,
               const std::vector<Eigen::Vector3d>& r_ref,
               const std::vector<std::vector<double>>& x_q,
               const std::vector<Eigen::Vector3d>& r_q,
               const std::vector<int>& subset, std::vector<double>* sse) {
  const int kmax = std::min<int>(Ks().back(), static_cast<int>(x_ref.size()));
  const int nk = static_cast<int>(Ks().size());
  const int nq = static_cast<int>(x_q.size());
  std::vector<double> err(static_cast<size_t>(nq) * nk, 0.0);
  constexpr int kThreads = 2;
  ParallelFor(kThreads, kThreads, [&](int part) {
    std::vector<std::pair<double, int>> d(x_ref.size());
    for (int i = part; i < nq; i += kThreads) {
      for (size_t j = 0; j < x_ref.size(); ++j) {
        double s = 0;
        for (int c : subset) {
          const double t = x_q[i][c] - x_ref[j][c];
          s += t * t;
        }
        d[j] = {s, static_cast<int>(j)};
      }
      if (kmax > 0) {
        std::nth_element(d.begin(), d.begin() + (kmax - 1), d.end());
        std::sort(d.begin(), d.begin() + kmax);
      }
      double* e = &err[static_cast<size_t>(i) * nk];
      Eigen::Vector3d sum = Eigen::Vector3d::Zero();
      int next_k = 0;
      for (int a = 0; a < kmax && next_k < nk; ++a) {
        sum += r_ref[d[a].second];
        while (next_k < nk && Ks()[next_k] == a + 1) {
          e[next_k] = (r_q[i] - sum / (a + 1)).squaredNorm();
          ++next_k;
        }
      }
      for (; next_k < nk; ++next_k)  // fewer references than k
        e[next_k] = (r_q[i] - sum / kmax).squaredNorm();
    }
  });
  for (int i = 0; i < nq; ++i)
    for (int k = 0; k < nk; ++k)
      (*sse)[k] += err[static_cast<size_t>(i) * nk + k];
}

// Cross-validated share of the residual power explained; best k.
double CrossValidate(const std::vector<std::vector<double>>& x,
                     const std::vector<Eigen::Vector3d>& r,
                     const std::vector<int>& fold_of, int folds,
                     const std::vector<int>& subset, int* best_k) {
  std::vector<double> sse(Ks().size(), 0.0);
  double ss0 = 0;
  for (const auto& v : r) ss0 += v.squaredNorm();
  for (int f = 0; f < folds; ++f) {
    std::vector<std::vector<double>> xr, xq;
    std::vector<Eigen::Vector3d> rr, rq;
    for (size_t i = 0; i < x.size(); ++i) {
      if (fold_of[i] == f) {
        xq.push_back(x[i]);
        rq.push_back(r[i]);
      } else {
        xr.push_back(x[i]);
        rr.push_back(r[i]);
      }
    }
    if (xr.empty() || xq.empty()) continue;
    KnnErrors(xr, rr, xq, rq, subset, &sse);
  }
  const size_t arg = std::min_element(sse.begin(), sse.end()) - sse.begin();
  *best_k = Ks()[arg];
  return ss0 > 0 ? 1.0 - sse[arg] / ss0 : 0.0;
}

}  // namespace

SmoothCorrection FitSmoothCorrection(
    const SmoothInputs& inputs, const std::vector<Eigen::Vector3d>& train_res,
    const std::vector<Eigen::Vector3d>& held_res, int folds, int max_train) {
  SmoothCorrection out;
  const Scaled s = Standardise(inputs);
  double ss_held = 0;
  for (const auto& v : held_res) ss_held += v.squaredNorm();
  out.heldout_rms_before_mm = out.heldout_rms_after_mm =
      held_res.empty() ? 0.0 : std::sqrt(ss_held / held_res.size());
  if (train_res.size() < 20) return out;

  // Seeded subsample for the search, seeded folds.
  std::vector<int> order(train_res.size());
  std::iota(order.begin(), order.end(), 0);
  std::mt19937_64 rng(12345);
  std::shuffle(order.begin(), order.end(), rng);
  if (static_cast<int>(order.size()) > max_train) order.resize(max_train);
  std::vector<std::vector<double>> x;
  std::vector<Eigen::Vector3d> r;
  std::vector<int> fold_of;
  for (size_t i = 0; i < order.size(); ++i) {
    x.push_back(s.train[order[i]]);
    r.push_back(train_res[order[i]]);
    fold_of.push_back(static_cast<int>(i) % folds);
  }

  // Robot or instrument: the measured point as the only input (one common
  // scale for x, y, z: they are lengths in one frame).
  if (inputs.point_train.size() == train_res.size()) {
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (int i : order) mean += inputs.point_train[i] / order.size();
    double var = 0;
    for (int i : order) {
      var += (inputs.point_train[i] - mean).squaredNorm() / order.size();
    }
    const double sd = std::sqrt(std::max(var / 3.0, 1e-24));
    std::vector<std::vector<double>> xp;
    for (int i : order) {
      const Eigen::Vector3d z = (inputs.point_train[i] - mean) / sd;
      xp.push_back({z.x(), z.y(), z.z()});
    }
    int k = 0;
    out.point_cv_explained =
        CrossValidate(xp, r, fold_of, folds, {0, 1, 2}, &k);
  }

  // Each input alone, ranked.
  const int d = static_cast<int>(inputs.names.size());
  std::vector<std::pair<double, int>> ranked;
  for (int c = 0; c < d; ++c) {
    if (!s.varies[c]) continue;
    int k = 0;
    const double e = CrossValidate(x, r, fold_of, folds, {c}, &k);
    out.single.push_back({inputs.names[c], e});
    ranked.push_back({e, c});
  }
  std::sort(ranked.begin(), ranked.end(),
            [](const auto& a, const auto& b) { return a.first > b.first; });
  if (ranked.empty()) return out;

  // Greedy forward selection of inputs while the CV share grows by > 2 %
  // of the residual power (at most 4 inputs).
  constexpr double kMinGain = 0.02;
  std::vector<int> subset;
  double best = 0.0;
  int best_k = 0;
  for (int round = 0; round < 4; ++round) {
    int add = -1, add_k = 0;
    double add_e = best + kMinGain;
    for (const auto& cand : ranked) {
      if (std::find(subset.begin(), subset.end(), cand.second) != subset.end())
        continue;
      std::vector<int> trial = subset;
      trial.push_back(cand.second);
      int k = 0;
      const double e = CrossValidate(x, r, fold_of, folds, trial, &k);
      if (e > add_e) {
        add_e = e;
        add = cand.second;
        add_k = k;
      }
    }
    if (add < 0) break;
    subset.push_back(add);
    best = add_e;
    best_k = add_k;
  }
  out.cv_explained = best;
  if (subset.empty()) return out;
  out.k = best_k;
  // Strongest first: by the single-input share.
  std::vector<std::pair<double, int>> named;
  for (int c : subset) {
    for (const auto& rk : ranked)
      if (rk.second == c) named.push_back(rk);
  }
  std::sort(named.begin(), named.end(),
            [](const auto& a, const auto& b) { return a.first > b.first; });
  for (const auto& nmd : named)
    out.depends_on.push_back(inputs.names[nmd.second]);

  // Held-out gain: the correction from all training poses.
  if (!held_res.empty()) {
    const size_t keep =
        std::find(Ks().begin(), Ks().end(), best_k) - Ks().begin();
    std::vector<double> sse(Ks().size(), 0.0);
    KnnErrors(s.train, train_res, s.held, held_res, subset, &sse);
    out.heldout_rms_after_mm = std::sqrt(sse[keep] / held_res.size());
  }
  return out;
}

}  // namespace kincal
