#include "diagnose/series_checks.h"

#include <gtest/gtest.h>

#include <cmath>

#include "data/urdf.h"
#include "diagnose/model_diagnosis.h"
#include "synth/simulate.h"
#include "tests/testing/paths.h"

namespace kincal {
namespace {

Robot Bh7() {
  return ReadRobotYaml(testing::SourceDir() + "/data/robots/bh7.yaml");
}

// 200 poses of BH-7 (seed 5's hidden geometry) per series, each seen from
// its own frame; series B's instrument reads lengths `scale_ppm` too long
// (about its frame's origin).
Observations TwoSeries(double scale_ppm) {
  SimulateOptions so;
  so.poses = 200;
  so.seed = 5;
  so.noise_mm = 0.02;
  const SimulatedSession a = Simulate(Bh7(), so);
  so.seed = 6;
  so.sigma_length_mm = so.sigma_angle_deg = 0.0;
  so.meas_from_base = std::array<double, 6>{0.2, 0.1, -0.4, 1500, -200, 100};
  const SimulatedSession b = Simulate(a.truth, so);
  Observations out = a.observations;
  for (Observation& o : out.rows) o.series = "A";
  const Eigen::Vector3d origin(1500, -200, 100);
  for (Observation o : b.observations.rows) {
    o.series = "B";
    o.pose = "b" + o.pose;
    o.p_in_meas = origin + (1.0 + 1e-6 * scale_ppm) * (o.p_in_meas - origin);
    out.rows.push_back(o);
  }
  return out;
}

// A 400 ppm scale of B's instrument is found, significant and estimated
// within 3 sigma. One scale shared by both series is identifiable on BH-7:
// its prismatic joint's readings carry the unit of length (an all-revolute
// arm such as the UR10 gives a sine of 0, docs/DIAGNOSE.md).
TEST(SeriesChecksTest,
     RelativeScaleFoundSharedScaleIdentifiableWithAPrismaticJoint) {
  const DiagnosisResult r = DiagnoseModel(Bh7(), TwoSeries(400), {});
  ASSERT_EQ(r.series.series.size(), 2u);
  EXPECT_EQ(r.series.series[0].name, "A");
  EXPECT_EQ(r.series.series[1].name, "B");
  EXPECT_TRUE(std::isnan(r.series.series[0].scale_sigma_ppm));
  const SeriesCheck& b = r.series.series[1];
  EXPECT_TRUE(r.series.scale_significant);
  EXPECT_NEAR(b.scale_ppm, 400, 3 * b.scale_sigma_ppm);
  EXPECT_LT(b.scale_sigma_ppm, 100);
  EXPECT_GT(r.series.shared_scale_sine, 0.01);
  EXPECT_GT(b.train_poses, 100);
  EXPECT_GT(b.heldout_poses, 20);
}

// Without a scale error the test stays quiet and the estimate is within
// 3 sigma of zero.
TEST(SeriesChecksTest, NoScaleNoFinding) {
  const DiagnosisResult r = DiagnoseModel(Bh7(), TwoSeries(0), {});
  ASSERT_EQ(r.series.series.size(), 2u);
  const SeriesCheck& b = r.series.series[1];
  EXPECT_FALSE(r.series.scale_significant);
  EXPECT_LT(std::abs(b.scale_ppm), 3 * b.scale_sigma_ppm);
  EXPECT_LT(b.heldout_rms_mm, 2.0 * std::sqrt(3.0) * 0.02);
}

}  // namespace
}  // namespace kincal
