#include "plan/confirm.h"

#include <gtest/gtest.h>

#include <cmath>

#include "data/error.h"
#include "tests/testing/paths.h"

namespace kincal {
namespace {

Robot Bh7() {
  return ReadRobotYaml(testing::SourceDir() + "/data/robots/bh7.yaml");
}

PlanOptions SmallPlan() {
  PlanOptions options;
  options.n = 30;
  options.candidates = 300;
  options.evaluation_poses = 30;
  return options;
}

TEST(ConfirmDesign, SeededAndOneErrorPerPlannedParameter) {
  const Robot robot = Bh7();
  const PlanOptions options = SmallPlan();
  const PlanResult plan = PlanPoses(robot, options);
  ConfirmOptions confirm;
  confirm.repetitions = 4;
  const ConfirmResult a =
      ConfirmDesign(robot, plan, plan.poses, options, confirm);
  ASSERT_EQ(a.rms_error.size(), plan.params.size());
  EXPECT_EQ(a.failed_fits, 0);
  for (double e : a.rms_error) {
    EXPECT_TRUE(std::isfinite(e));
    EXPECT_GE(e, 0);
  }
  EXPECT_GT(a.error_gmean, 0);
  EXPECT_GT(a.tip_rms_mm, 0);
  // The calibrated model predicts the tips far better than the true
  // deviations (0.5 mm, 0.2 deg over a ~400 mm arm) would leave them.
  EXPECT_LT(a.tip_rms_mm, 0.5);
  const ConfirmResult b =
      ConfirmDesign(robot, plan, plan.poses, options, confirm);
  EXPECT_EQ(a.rms_error, b.rms_error);
  confirm.seed = 2;
  const ConfirmResult c =
      ConfirmDesign(robot, plan, plan.poses, options, confirm);
  EXPECT_NE(a.rms_error, c.rms_error);
}

TEST(ConfirmDesign, FixedPointPlansAreBadInput) {
  const Robot robot = Bh7();
  PlanOptions options = SmallPlan();
  options.fixed_point = true;
  const PlanResult plan = PlanPoses(robot, options);
  EXPECT_THROW(
      ConfirmDesign(robot, plan, plan.poses, options, ConfirmOptions()),
      InputError);
}

}  // namespace
}  // namespace kincal
