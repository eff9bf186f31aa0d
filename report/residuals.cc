#include "report/residuals.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numeric>

#include "calib/chain.h"
#include "calib/evaluate.h"

namespace kincal {
namespace {

// Bin index (0..bins-1) of every element by rank (equal-count bins).
std::vector<int> RankBins(const std::vector<double>& x, int bins) {
  std::vector<int> order(x.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(),
                   [&](int a, int b) { return x[a] < x[b]; });
  std::vector<int> bin(x.size(), 0);
  const size_t n = x.size();
  for (size_t r = 0; r < n; ++r) {
    bin[order[r]] = std::min<int>(bins - 1, static_cast<int>(r * bins / n));
  }
  return bin;
}

double Explained(const std::vector<int>& cell, int cells,
                 const std::vector<double>& v) {
  const size_t n = v.size();
  if (n < 2) return 0.0;
  const double mean = std::accumulate(v.begin(), v.end(), 0.0) / n;
  double total = 0.0;
  for (double x : v) total += (x - mean) * (x - mean);
  if (!(total > 0)) return 0.0;
  std::vector<double> sum(cells, 0.0);
  std::vector<int> count(cells, 0);
  for (size_t i = 0; i < n; ++i) {
    sum[cell[i]] += v[i];
    ++count[cell[i]];
  }
  double between = 0.0;
  for (int c = 0; c < cells; ++c) {
    if (count[c] == 0) continue;
    const double m = sum[c] / count[c];
    between += count[c] * (m - mean) * (m - mean);
  }
  return between / total;
}

}  // namespace

ResidualSet ComputeResiduals(const Robot& robot, const Observations& obs,
                             const std::string& label) {
  const EvaluateResult ev = Evaluate(robot, obs);
  ModelState state = ev.state;
  const std::vector<Measurement> ms =
      MakeMeasurements(Chain::FromRobot(robot), obs, &state);
  const Eigen::Vector3d w(state.meas_from_base[0], state.meas_from_base[1],
                          state.meas_from_base[2]);
  const Eigen::Matrix3d meas_from_base_r =
      w.norm() > 0
          ? Eigen::AngleAxisd(w.norm(), w.normalized()).toRotationMatrix()
          : Eigen::Matrix3d::Identity();
  ResidualSet out;
  out.label = label;
  for (const Measurement& m : ms) {
    Eigen::Vector3d e = Residual(state, m);
    if (m.kind == Measurement::kMeasured) e = meas_from_base_r.transpose() * e;
    out.rows.push_back(m.row);
    out.tip_in_base.push_back(TipInBase(state.chain, m.input));
    out.e_in_base.push_back(e);
    out.norm_mm.push_back(e.norm());
  }
  out.stats = ComputeErrorStats(out.norm_mm);
  return out;
}

std::vector<MeasuredCurve> MeasuredSensitivity(
    const Robot& robot, const Observations& obs, double range, int steps,
    const std::vector<std::string>& skip) {
  const EvaluateResult ev = Evaluate(robot, obs);
  ModelState state = ev.state;
  const std::vector<Measurement> ms =
      MakeMeasurements(Chain::FromRobot(robot), obs, &state);
  std::vector<MeasuredCurve> out;
  for (const ParamInfo& p : GeometryParams(state.chain)) {
    if (std::find(skip.begin(), skip.end(), p.name) != skip.end()) continue;
    MeasuredCurve c;
    c.name = p.name;
    c.unit = p.angle ? "deg" : "mm";
    ModelState s = state;
    double* v = ParamAddress(&s, p);
    const double v0 = *v;
    double lo = INFINITY, hi = -INFINITY;
    for (int k = 0; k < steps; ++k) {
      const double off = -range + 2.0 * range * k / (steps - 1);
      *v = v0 + p.FromInterface(off);
      double sum = 0.0;
      for (const Measurement& m : ms) sum += Residual(s, m).squaredNorm();
      const double rms = std::sqrt(sum / std::max<size_t>(1, ms.size()));
      c.offsets.push_back(off);
      c.rms_mm.push_back(rms);
      lo = std::min(lo, rms);
      hi = std::max(hi, rms);
    }
    if (hi - lo > 1e-6) out.push_back(c);
  }
  return out;
}

double ExplainedByBins(const std::vector<double>& x,
                       const std::vector<double>& value, int bins) {
  if (x.size() != value.size() || x.empty()) return 0.0;
  return Explained(RankBins(x, bins), bins, value);
}

double ExplainedByGrid(const std::vector<double>& x,
                       const std::vector<double>& y,
                       const std::vector<double>& value, int bins) {
  if (x.size() != value.size() || y.size() != value.size() || x.empty()) {
    return 0.0;
  }
  const std::vector<int> bx = RankBins(x, bins), by = RankBins(y, bins);
  std::vector<int> cell(x.size());
  for (size_t i = 0; i < x.size(); ++i) cell[i] = bx[i] * bins + by[i];
  return Explained(cell, bins * bins, value);
}

double VectorExplainedByGrid(const std::vector<double>& x,
                             const std::vector<double>& y,
                             const std::vector<Eigen::Vector3d>& e, int bins) {
  const size_t n = e.size();
  if (n < 2 || x.size() != n || y.size() != n) return 0.0;
  const std::vector<int> bx = RankBins(x, bins), by = RankBins(y, bins);
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const auto& v : e) mean += v;
  mean /= static_cast<double>(n);
  double total = 0.0;
  for (const auto& v : e) total += (v - mean).squaredNorm();
  if (!(total > 0)) return 0.0;
  std::vector<Eigen::Vector3d> sum(bins * bins, Eigen::Vector3d::Zero());
  std::vector<int> count(bins * bins, 0);
  for (size_t i = 0; i < n; ++i) {
    sum[bx[i] * bins + by[i]] += e[i];
    ++count[bx[i] * bins + by[i]];
  }
  double between = 0.0;
  for (int c = 0; c < bins * bins; ++c) {
    if (count[c] > 0) {
      between += count[c] * (sum[c] / count[c] - mean).squaredNorm();
    }
  }
  return between / total;
}

void MeanVectorGrid(const std::vector<double>& x, const std::vector<double>& y,
                    const std::vector<Eigen::Vector3d>& e, int bins,
                    int min_count, std::vector<double>* cx,
                    std::vector<double>* cy, std::vector<double>* magnitude,
                    double* cell_w, double* cell_h) {
  cx->clear();
  cy->clear();
  magnitude->clear();
  if (x.empty()) return;
  const auto [xlo, xhi] = std::minmax_element(x.begin(), x.end());
  const auto [ylo, yhi] = std::minmax_element(y.begin(), y.end());
  const double x0 = *xlo, y0 = *ylo;
  const double w = std::max(1e-9, (*xhi - x0) / bins);
  const double h = std::max(1e-9, (*yhi - y0) / bins);
  std::vector<Eigen::Vector3d> sum(bins * bins, Eigen::Vector3d::Zero());
  std::vector<int> count(bins * bins, 0);
  for (size_t i = 0; i < e.size(); ++i) {
    const int a = std::min(bins - 1, static_cast<int>((x[i] - x0) / w));
    const int b = std::min(bins - 1, static_cast<int>((y[i] - y0) / h));
    sum[a * bins + b] += e[i];
    ++count[a * bins + b];
  }
  for (int a = 0; a < bins; ++a) {
    for (int b = 0; b < bins; ++b) {
      const int c = a * bins + b;
      if (count[c] < min_count) continue;
      cx->push_back(x0 + (a + 0.5) * w);
      cy->push_back(y0 + (b + 0.5) * h);
      magnitude->push_back((sum[c] / count[c]).norm());
    }
  }
  *cell_w = w;
  *cell_h = h;
}

void BinnedMeans(const std::vector<double>& x, const std::vector<double>& value,
                 int bins, std::vector<double>* cx, std::vector<double>* mean) {
  cx->assign(bins, 0.0);
  mean->assign(bins, 0.0);
  std::vector<int> count(bins, 0);
  const std::vector<int> b = RankBins(x, bins);
  for (size_t i = 0; i < x.size(); ++i) {
    (*cx)[b[i]] += x[i];
    (*mean)[b[i]] += value[i];
    ++count[b[i]];
  }
  for (int k = bins - 1; k >= 0; --k) {
    if (count[k] == 0) {
      cx->erase(cx->begin() + k);
      mean->erase(mean->begin() + k);
      continue;
    }
    (*cx)[k] /= count[k];
    (*mean)[k] /= count[k];
  }
}

}  // namespace kincal
