#include "calib/evaluate.h"

#include "data/error.h"

namespace kincal {

EvaluateResult Evaluate(const Robot& robot, const Observations& obs) {
  EvaluateResult out;
  out.state.chain = Chain::FromRobot(robot);
  // Approach directions and torques use the model's own geometry.
  const std::vector<Measurement> ms =
      MakeMeasurements(out.state.chain, obs, &out.state);
  if (ms.empty()) {
    throw InputError(obs.source, 0, 0,
                     "no row has a measured tip (x, y, z) or a fixed_point "
                     "label: nothing to evaluate");
  }
  InitializeFrameAndPoints(ms, &out.state);
  FitOptions options;
  options.free = FrameParams();
  for (const ParamInfo& p : PointParams(out.state)) options.free.push_back(p);
  options.compute_covariance = false;
  Fit(ms, options, &out.state);
  for (const Measurement& m : ms) {
    out.errors_mm.push_back(Residual(out.state, m).norm());
    out.rows.push_back(m.row);
  }
  out.stats = ComputeErrorStats(out.errors_mm);
  return out;
}

}  // namespace kincal
