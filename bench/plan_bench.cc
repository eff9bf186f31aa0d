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

#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>

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

int main() {
  using kincal::ReadRobotYaml;
  const std::string dir = std::string(KINCAL_SOURCE_DIR) + "/data/robots/";
  std::printf(
      "60 planned vs 60 random feasible poses, noise 0.05 mm/axis, "
      "30 simulated calibrations each (planned / random)\n");
  for (bool rig : {false, true}) {
    kincal::Run("BH-7", ReadRobotYaml(dir + "bh7.yaml"), rig);
    kincal::Run("UR10", ReadRobotYaml(dir + "ur10.yaml"), rig);
  }
  return 0;
}
