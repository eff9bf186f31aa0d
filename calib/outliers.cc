#include "calib/outliers.h"

#include <Eigen/SVD>
#include <algorithm>
#include <map>
#include <set>

namespace kincal {

double RobustAxisSigmaMm(const std::vector<double>& norms_mm) {
  if (norms_mm.empty()) return 0.0;
  std::vector<double> v = norms_mm;
  const size_t mid = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + mid, v.end());
  double median = v[mid];
  if (v.size() % 2 == 0) {
    median = 0.5 * (median + *std::max_element(v.begin(), v.begin() + mid));
  }
  // Median of the norm of a 3-D standard normal vector: sqrt(chi2_3 median).
  return median / 1.5382;
}

double RobustAxisSigmaOfKeptMm(const std::vector<double>& errors_mm,
                               const std::vector<char>& excluded) {
  std::vector<double> kept;
  for (size_t i = 0; i < errors_mm.size(); ++i)
    if (!excluded[i]) kept.push_back(errors_mm[i]);
  return RobustAxisSigmaMm(kept);
}

std::vector<char> FlagGross(const std::vector<double>& norms_mm,
                            double axis_sigma_mm, double sigmas) {
  std::vector<char> flags(norms_mm.size(), 0);
  if (!(sigmas > 0) || !(axis_sigma_mm > 0)) return flags;
  for (size_t i = 0; i < norms_mm.size(); ++i) {
    flags[i] = norms_mm[i] > sigmas * axis_sigma_mm;
  }
  return flags;
}

bool CanExclude(const std::vector<Measurement>& ms,
                const std::vector<char>& flags) {
  size_t excluded = 0;
  std::map<int, int> kept_per_point;
  for (size_t i = 0; i < ms.size(); ++i) {
    if (flags[i]) {
      ++excluded;
      if (ms[i].kind == Measurement::kFixedPoint) kept_per_point[ms[i].point];
    } else if (ms[i].kind == Measurement::kFixedPoint) {
      ++kept_per_point[ms[i].point];
    }
  }
  if (4 * excluded > ms.size()) return false;
  for (const auto& [point, kept] : kept_per_point) {
    if (kept < 3) return false;
  }
  return true;
}

namespace {

// Weighted Kabsch (rotation and translation, no scale) of the measured rows
// of one frame (Measurement::frame): their error under it, into `errors`.
void RegisterFrame(const std::vector<Measurement>& ms,
                   const std::vector<Eigen::Vector3d>& tips,
                   const std::vector<double>& w, int frame,
                   std::vector<double>* errors) {
  auto in_frame = [&](size_t i) {
    return ms[i].kind == Measurement::kMeasured && ms[i].frame == frame;
  };
  double sw = 0.0;
  Eigen::Vector3d tip_mean = Eigen::Vector3d::Zero();
  Eigen::Vector3d meas_mean = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < ms.size(); ++i) {
    if (!in_frame(i) || w[i] <= 0) continue;
    sw += w[i];
    tip_mean += w[i] * tips[i];
    meas_mean += w[i] * ms[i].p_in_meas;
  }
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();
  if (sw > 0) {
    tip_mean /= sw;
    meas_mean /= sw;
    Eigen::Matrix3d h = Eigen::Matrix3d::Zero();
    for (size_t i = 0; i < ms.size(); ++i) {
      if (!in_frame(i) || w[i] <= 0) continue;
      h += w[i] * (tips[i] - tip_mean) *
           (ms[i].p_in_meas - meas_mean).transpose();
    }
    Eigen::JacobiSVD<Eigen::Matrix3d> svd(
        h, Eigen::ComputeFullU | Eigen::ComputeFullV);
    Eigen::Matrix3d d = Eigen::Matrix3d::Identity();
    d(2, 2) = (svd.matrixV() * svd.matrixU().transpose()).determinant() < 0
                  ? -1.0
                  : 1.0;
    rotation = svd.matrixV() * d * svd.matrixU().transpose();
    translation = meas_mean - rotation * tip_mean;
  }
  for (size_t i = 0; i < ms.size(); ++i) {
    if (in_frame(i))
      (*errors)[i] =
          (rotation * tips[i] + translation - ms[i].p_in_meas).norm();
  }
}

// Weighted least-squares registration of fixed tips: meas_from_base for
// the measured rows (one per frame), a position per fixed point; returns
// every row's error.
std::vector<double> RegisterTips(const std::vector<Measurement>& ms,
                                 const std::vector<Eigen::Vector3d>& tips,
                                 const std::vector<double>& w, int num_points) {
  std::vector<double> errors(ms.size(), 0.0);
  std::set<int> frames;
  for (const Measurement& m : ms)
    if (m.kind == Measurement::kMeasured) frames.insert(m.frame);
  for (int frame : frames) RegisterFrame(ms, tips, w, frame, &errors);
  // Fixed points: the weighted mean of their tips.
  std::vector<Eigen::Vector3d> points(num_points, Eigen::Vector3d::Zero());
  std::vector<double> point_w(num_points, 0.0);
  for (size_t i = 0; i < ms.size(); ++i) {
    if (ms[i].kind != Measurement::kFixedPoint || w[i] <= 0) continue;
    points[ms[i].point] += w[i] * tips[i];
    point_w[ms[i].point] += w[i];
  }
  for (int k = 0; k < num_points; ++k)
    if (point_w[k] > 0) points[k] /= point_w[k];
  for (size_t i = 0; i < ms.size(); ++i) {
    if (ms[i].kind == Measurement::kFixedPoint)
      errors[i] = (tips[i] - points[ms[i].point]).norm();
  }
  return errors;
}

}  // namespace

std::vector<char> FindGrossErrors(const ModelState& state,
                                  const std::vector<Measurement>& ms,
                                  double sigmas) {
  std::vector<Eigen::Vector3d> tips;
  tips.reserve(ms.size());
  int num_points = 0;
  for (const Measurement& m : ms) {
    tips.push_back(TipInBase(state.chain, m.input));
    if (m.kind == Measurement::kFixedPoint)
      num_points = std::max(num_points, m.point + 1);
  }
  std::vector<char> excluded(ms.size(), 0);
  std::vector<double> w(ms.size(), 1.0);
  const std::vector<double> plain = RegisterTips(ms, tips, w, num_points);
  const double scale = RobustAxisSigmaMm(plain);
  if (!(sigmas > 0) || !(scale > 0)) return excluded;
  // Cauchy weights, the scale held: iteratively reweighted.
  std::vector<double> errors = plain;
  for (int it = 0; it < 20; ++it) {
    for (size_t i = 0; i < ms.size(); ++i) {
      const double r = errors[i] / scale;
      w[i] = 1.0 / (1.0 + r * r);
    }
    errors = RegisterTips(ms, tips, w, num_points);
  }
  double sigma = RobustAxisSigmaMm(errors);
  for (int round = 0; round < 6; ++round) {
    const std::vector<char> flags = FlagGross(errors, sigma, sigmas);
    if (flags == excluded || !CanExclude(ms, flags)) break;
    excluded = flags;
    for (size_t i = 0; i < ms.size(); ++i) w[i] = excluded[i] ? 0.0 : 1.0;
    errors = RegisterTips(ms, tips, w, num_points);
    sigma = RobustAxisSigmaOfKeptMm(errors, excluded);
  }
  return excluded;
}

RowOutlier DescribeOutlier(const ModelState& state, const Measurement& m,
                           const std::string& pose, double error_mm,
                           double axis_sigma_mm, double sigmas) {
  RowOutlier o;
  o.row = m.row;
  o.pose = pose;
  o.error_mm = error_mm;
  o.sigmas = axis_sigma_mm > 0 ? error_mm / axis_sigma_mm : 0.0;
  if (m.kind != Measurement::kFixedPoint) return o;
  const Eigen::Vector3d tip = TipInBase(state.chain, m.input);
  double best = -1.0;
  for (size_t j = 0; j < state.points_in_base.size(); ++j) {
    if (static_cast<int>(j) == m.point) continue;
    const auto& p = state.points_in_base[j];
    const double d = (tip - Eigen::Vector3d(p[0], p[1], p[2])).norm();
    if (d <= sigmas * axis_sigma_mm && (best < 0 || d < best)) {
      best = d;
      o.near_point = state.point_labels[j];
      o.near_point_mm = d;
    }
  }
  return o;
}

}  // namespace kincal
