#include "diagnose/series_checks.h"

#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <limits>

#include "calib/exact_jacobian.h"
#include "diagnose/nonparametric.h"
#include "diagnose/statistics.h"

namespace kincal {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

double RmsOf(const std::vector<Eigen::Vector3d>& r) {
  if (r.empty()) return kNaN;
  double sum = 0.0;
  for (const Eigen::Vector3d& v : r) sum += v.squaredNorm();
  return std::sqrt(sum / r.size());
}

// Robot or instrument on one series' training poses: the smooth test over
// the joint readings alone and over the measured point.
void RobotOrInstrument(const Observations& obs,
                       const std::vector<const Measurement*>& rows,
                       const std::vector<Eigen::Vector3d>& residuals,
                       SeriesCheck* check) {
  SmoothInputs in;
  in.names = obs.joint_names;
  for (const Measurement* m : rows) {
    in.train.push_back(obs.rows[m->row].q);
    in.point_train.push_back(m->p_in_meas);
  }
  if (rows.size() < 20) {
    check->joints_cv_explained = check->point_cv_explained = kNaN;
    check->follows = "undecided";
    return;
  }
  const SmoothCorrection sc = FitSmoothCorrection(in, residuals, {});
  check->joints_cv_explained = sc.cv_explained;
  check->point_cv_explained = sc.point_cv_explained;
  const double joints = sc.cv_explained, point = sc.point_cv_explained;
  if (joints > point + 0.05 && joints >= 0.1) {
    check->follows = "robot";
  } else if (point > joints + 0.05 && point >= 0.1) {
    check->follows = "instrument";
  } else {
    check->follows = "undecided";
  }
}

// Column of a scale about frame k's origin: d(s R tip + t) / ds = R tip =
// the predicted point minus the frame's translation.
Eigen::Vector3d ScaleColumn(const ModelState& state, const Measurement& m,
                            const Eigen::Vector3d& residual) {
  const double* f = state.FrameBlock(m.frame);
  return residual + m.p_in_meas - Eigen::Vector3d(f[3], f[4], f[5]);
}

// The relative scales' test and the shared scale's sine (SeriesChecks).
void TestScales(const std::vector<Measurement>& train, const ModelState& state,
                const std::vector<ParamInfo>& free, double false_alarm,
                int threads, SeriesChecks* out) {
  const int frames = state.NumFrames();
  Eigen::VectorXd r;
  Eigen::MatrixXd jac;
  ResidualsAndJacobian(train, state, free, &r, &jac, threads);
  const int n = static_cast<int>(r.size()), p = static_cast<int>(jac.cols());
  const int q = frames - 1;
  Eigen::MatrixXd scales = Eigen::MatrixXd::Zero(n, q);
  Eigen::VectorXd shared = Eigen::VectorXd::Zero(n);
  for (size_t i = 0; i < train.size(); ++i) {
    const Measurement& m = train[i];
    const Eigen::Vector3d c =
        ScaleColumn(state, m, r.segment<3>(3 * static_cast<int>(i)));
    shared.segment<3>(3 * i) = c;
    if (m.frame > 0) scales.block<3, 1>(3 * i, m.frame - 1) = c;
  }
  // Column-scaled least squares on [J, scales] and on J alone, through the
  // normal equations (the columns are few against the rows).
  Eigen::MatrixXd a(n, p + q + 1);
  a << jac, scales, shared;
  Eigen::VectorXd norms = a.colwise().norm();
  for (int c = 0; c < a.cols(); ++c)
    if (norms(c) > 0) a.col(c) /= norms(c);
  const Eigen::MatrixXd normal = NormalMatrix(a, threads);
  const Eigen::VectorXd gradient = a.transpose() * r;
  const Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> full(
      normal.topLeftCorner(p + q, p + q));
  const Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> base(
      normal.topLeftCorner(p, p));
  const Eigen::VectorXd step = full.solve(-gradient.head(p + q));
  const double rss1 = r.squaredNorm() + gradient.head(p + q).dot(step);
  const double rss0 =
      r.squaredNorm() - gradient.head(p).dot(base.solve(gradient.head(p)));
  const int dof = n - static_cast<int>(full.rank());
  const double s2 = dof > 0 ? rss1 / dof : kNaN;
  out->scale_f = q > 0 && s2 > 0 ? (rss0 - rss1) / q / s2 : 0.0;
  out->scale_p_value =
      q > 0 && dof > 0 ? FDistributionUpperTail(out->scale_f, q, dof) : 1.0;
  out->scale_significant = out->scale_p_value < false_alarm;
  // Covariance of the scaled solution: s2 (A^T A)^+.
  const Eigen::MatrixXd cov = s2 * full.pseudoInverse();
  for (int k = 0; k < q; ++k) {
    const int c = p + k;
    SeriesCheck& check = out->series[k + 1];
    check.scale_ppm = norms(c) > 0 ? 1e6 * step(c) / norms(c) : kNaN;
    check.scale_sigma_ppm =
        norms(c) > 0 ? 1e6 * std::sqrt(std::max(0.0, cov(c, c))) / norms(c)
                     : kNaN;
  }
  // The shared column (unit length after scaling) off the span of J.
  const Eigen::VectorXd toward = normal.col(p + q).head(p);
  const double off = 1.0 - toward.dot(base.solve(toward));
  out->shared_scale_sine =
      norms(p + q) > 0 ? std::sqrt(std::max(0.0, off)) : 0.0;
}

}  // namespace

SeriesChecks CheckSeries(const Observations& obs,
                         const std::vector<Measurement>& train,
                         const std::vector<Measurement>& held,
                         const ModelState& state,
                         const std::vector<ParamInfo>& free, double false_alarm,
                         int threads) {
  SeriesChecks out;
  const int frames = state.NumFrames();
  out.series.resize(frames);
  for (int f = 0; f < frames; ++f) {
    SeriesCheck& check = out.series[f];
    check.name = f < static_cast<int>(state.frame_series.size())
                     ? state.frame_series[f]
                     : std::string();
    std::vector<const Measurement*> rows;
    std::vector<Eigen::Vector3d> train_res, held_res;
    for (const Measurement& m : train) {
      if (m.frame != f || m.kind != Measurement::kMeasured) continue;
      rows.push_back(&m);
      train_res.push_back(Residual(state, m));
    }
    for (const Measurement& m : held) {
      if (m.frame == f && m.kind == Measurement::kMeasured)
        held_res.push_back(Residual(state, m));
    }
    check.train_poses = static_cast<int>(train_res.size());
    check.heldout_poses = static_cast<int>(held_res.size());
    check.train_rms_mm = RmsOf(train_res);
    check.heldout_rms_mm = RmsOf(held_res);
    check.scale_sigma_ppm = f == 0 ? kNaN : 0.0;
    RobotOrInstrument(obs, rows, train_res, &check);
  }
  if (frames > 1) TestScales(train, state, free, false_alarm, threads, &out);
  return out;
}

}  // namespace kincal
