#include "calib/evaluate.h"

#include <algorithm>

#include "data/error.h"

namespace kincal {

Registration Register(const ModelState& start,
                      const std::vector<Measurement>& ms,
                      const std::vector<char>& excluded) {
  Registration out;
  out.state = start;
  std::vector<Measurement> used;
  for (size_t i = 0; i < ms.size(); ++i)
    if (!excluded[i]) used.push_back(ms[i]);
  InitializeFrameAndPoints(used, &out.state);
  FitOptions options;
  options.free = FrameParams();
  for (const ParamInfo& p : PointParams(out.state)) options.free.push_back(p);
  options.compute_covariance = false;
  Fit(used, options, &out.state);
  std::vector<double> used_errors;
  for (size_t i = 0; i < ms.size(); ++i) {
    out.errors_mm.push_back(Residual(out.state, ms[i]).norm());
    if (!excluded[i]) used_errors.push_back(out.errors_mm.back());
  }
  out.stats = ComputeErrorStats(used_errors);
  return out;
}

EvaluateResult Evaluate(const Robot& robot, const Observations& obs,
                        double outlier_sigmas) {
  EvaluateResult out;
  ModelState start;
  start.chain = Chain::FromRobot(robot);
  // Approach directions and torques use the model's own geometry.
  const std::vector<Measurement> ms =
      MakeMeasurements(start.chain, obs, &start);
  if (ms.empty()) {
    throw InputError(obs.source, 0, 0,
                     "no row has a measured tip (x, y, z) or a fixed_point "
                     "label: nothing to evaluate");
  }
  for (const Measurement& m : ms) out.rows.push_back(m.row);
  const std::vector<char> excluded = FindGrossErrors(start, ms, outlier_sigmas);
  const bool any =
      std::find(excluded.begin(), excluded.end(), 1) != excluded.end();
  // The spec's figures: registered on every row.
  const Registration all = Register(start, ms, std::vector<char>(ms.size(), 0));
  out.stats = all.stats;
  out.errors_mm = all.errors_mm;
  out.state = all.state;
  if (!any) return out;
  out.has_robust = true;
  out.robust = Register(start, ms, excluded);
  out.excluded = excluded;
  const double sigma = RobustAxisSigmaOfKeptMm(out.robust.errors_mm, excluded);
  out.outlier_axis_sigma_mm = sigma;
  for (size_t i = 0; i < ms.size(); ++i) {
    if (!excluded[i]) continue;
    RowOutlier o =
        DescribeOutlier(out.robust.state, ms[i], obs.rows[ms[i].row].pose,
                        out.robust.errors_mm[i], sigma, outlier_sigmas);
    o.excluded = true;
    out.outliers.push_back(o);
  }
  return out;
}

}  // namespace kincal
