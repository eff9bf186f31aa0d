// Pose planning figures: for BH-7 and UR10, without a rig (laser tracker) and
// with synth's example stereo rig (tags visible in both cameras), 60 planned
// poses against 60 random feasible poses:
//   predicted geometric-mean sigma of the robot parameters (in units of
//   their bounds) and the ratio random / planned;
//   the same from 30 simulated calibrations at each pose set (actual RMS
//   errors against the truth);
//   predicted and actual tip RMS on random feasible evaluation poses.
// A DH length parameter (a, d) moves the tip by a unit vector, so its
// column has norm 1 at every pose: sigma >= noise / sqrt(N) whatever the
// poses (0.00645 mm for N = 60, noise 0.05 mm); printed as "floor".
// `plan_bench --bound`: that floor for every robot parameter (with every
// other parameter known, sigma_i >= noise / sqrt(N max_pose |J_i|^2), the
// maximum over 20,000 uniform feasible poses plus the planned and random
// ones), and the geometric mean of random sigma / floor: an upper bound on
// the gain any N-pose design can reach over the random one (loose where
// parameters are correlated: the floor ignores them).

#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>

#include "calib/fit.h"
#include "plan/confirm.h"
#include "plan/plan.h"
#include "synth/render.h"

namespace kincal {
namespace {

void Run(const std::string& name, const Robot& robot, bool with_rig) {
  const Rig rig = ExampleStereoRig(1280, 1024);
  const Target target = ExampleTarget();
  PlanOptions options;
  options.n = 60;
  if (with_rig) {
    options.rig = &rig;
    options.target = &target;
  }
  const PlanResult plan = PlanPoses(robot, options);
  ConfirmOptions confirm;
  confirm.repetitions = 30;
  const ConfirmResult a =
      ConfirmDesign(robot, plan, plan.poses, options, confirm);
  const ConfirmResult b =
      ConfirmDesign(robot, plan, plan.random_poses, options, confirm);
  int lengths = 0, at_floor = 0;
  const double floor = options.noise_mm / std::sqrt(60.0);
  for (size_t k = 0; k < plan.params.size(); ++k) {
    if (plan.params[k].kind != ParamKind::kRow || plan.params[k].angle) {
      continue;
    }
    ++lengths;
    at_floor += plan.random.sigma[k] < 1.2 * floor;
  }
  std::printf(
      "%-5s %-8s | pred gmean %.5f / %.5f gain %.2f | actual %.5f / %.5f "
      "gain %.2f | tip pred %.4f / %.4f actual %.4f / %.4f mm | "
      "lengths within 1.2x floor (random) %d/%d | travel %.1f / %.1f | "
      "%.1f s\n",
      name.c_str(), with_rig ? "rig" : "no rig", plan.planned_sigma_gmean,
      plan.random_sigma_gmean,
      plan.random_sigma_gmean / plan.planned_sigma_gmean, a.error_gmean,
      b.error_gmean, b.error_gmean / a.error_gmean, plan.planned.tip_rms_mm,
      plan.random.tip_rms_mm, a.tip_rms_mm, b.tip_rms_mm, at_floor, lengths,
      plan.planned.joint_travel, plan.random.joint_travel, plan.seconds);
}

}  // namespace
}  // namespace kincal

namespace kincal {
namespace {

void GainBound(const std::string& name, const Robot& robot) {
  PlanOptions o;
  o.n = 60;
  o.evaluation_poses = 20000;  // the pool the column maxima are taken over
  const PlanResult plan = PlanPoses(robot, o);
  std::vector<std::vector<double>> pool = plan.evaluation_poses;
  pool.insert(pool.end(), plan.random_poses.begin(), plan.random_poses.end());
  pool.insert(pool.end(), plan.poses.begin(), plan.poses.end());
  const Chain chain = Chain::FromRobot(robot);
  Observations obs;
  obs.joint_names = robot.JointNames();
  for (const auto& q : pool) {
    Observation row;
    row.q = q;
    row.has_point = true;
    obs.rows.push_back(row);
  }
  ModelState state;
  state.chain = chain;
  const std::vector<Measurement> ms = MakeMeasurements(chain, obs, &state);
  std::vector<ParamInfo> robot_params;
  std::vector<size_t> index;
  for (size_t i = 0; i < plan.params.size(); ++i) {
    const ParamKind kind = plan.params[i].kind;
    if (kind == ParamKind::kFrame || kind == ParamKind::kPoint) continue;
    robot_params.push_back(plan.params[i]);
    index.push_back(i);
  }
  const Eigen::MatrixXd J = ResidualJacobian(ms, state, robot_params);
  double log_random = 0, log_planned = 0;
  std::printf("%s: %zu feasible poses, %zu robot parameters\n", name.c_str(),
              pool.size(), robot_params.size());
  for (size_t c = 0; c < robot_params.size(); ++c) {
    double max_sq = 0;
    for (size_t i = 0; i < ms.size(); ++i)
      max_sq = std::max(max_sq, J.block(3 * i, c, 3, 1).squaredNorm());
    const double floor =
        robot_params[c].ToInterface(o.noise_mm / std::sqrt(o.n * max_sq));
    const double random = plan.random.sigma[index[c]];
    const double planned = plan.planned.sigma[index[c]];
    std::printf(
        "  %-26s floor %.5f  random %.5f (x%.2f)  planned %.5f (x%.2f)\n",
        robot_params[c].name.c_str(), floor, random, random / floor, planned,
        planned / floor);
    log_random += std::log(random / floor);
    log_planned += std::log(planned / floor);
  }
  const double m = static_cast<double>(robot_params.size());
  std::printf(
      "  geometric mean: random / floor %.3f (the bound on any design's "
      "gain), planned / floor %.3f, planned gain %.3f\n",
      std::exp(log_random / m), std::exp(log_planned / m),
      std::exp((log_random - log_planned) / m));
}

}  // namespace
}  // namespace kincal

int main(int argc, char** argv) {
  using kincal::ReadRobotYaml;
  const std::string dir = std::string(KINCAL_SOURCE_DIR) + "/data/robots/";
  if (argc > 1 && std::string(argv[1]) == "--bound") {
    std::printf(
        "Upper bound on the sigma gain of any 60-pose design over 60 random "
        "feasible poses (noise 0.05 mm/axis, no rig)\n");
    kincal::GainBound("BH-7", ReadRobotYaml(dir + "bh7.yaml"));
    kincal::GainBound("UR10", ReadRobotYaml(dir + "ur10.yaml"));
    return 0;
  }
  std::printf(
      "60 planned vs 60 random feasible poses, noise 0.05 mm/axis, "
      "30 simulated calibrations each (planned / random)\n");
  for (bool rig : {false, true}) {
    kincal::Run("BH-7", ReadRobotYaml(dir + "bh7.yaml"), rig);
    kincal::Run("UR10", ReadRobotYaml(dir + "ur10.yaml"), rig);
  }
  return 0;
}
