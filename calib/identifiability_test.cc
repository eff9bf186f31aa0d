// How many of BH-7's 24 DH parameters the data determine, by data type
// (docs/PAPER_METHOD.md, "Identifiability"). The Jacobian is taken at the
// truth of noise-free simulated data, where the model fits exactly: that is
// where structural redundancies are exact (away from it, a redundancy such
// as "rotate the whole arm about the fixed point" is only approximate and a
// rank test is fooled).

#include "calib/identifiability.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "data/robot.h"
#include "synth/simulate.h"
#include "tests/testing/paths.h"

namespace kincal {
namespace {

using ::testing::Contains;
using ::testing::Not;

Robot Bh7() {
  return ReadRobotYaml(testing::SourceDir() + "/data/robots/bh7.yaml");
}

struct Analysis {
  Identifiability id;
  std::vector<std::string> robot_identifiable, robot_unidentifiable;
};

// Identifiability of the 24 geometry parameters (plus frame / points as
// nuisance, first in priority) at the true model of a simulated session.
Analysis AtTruth(const SimulatedSession& s, bool with_distance = false) {
  ModelState truth;
  truth.chain = Chain::FromRobot(s.truth);
  const std::vector<Measurement> ms =
      MakeMeasurements(truth.chain, s.observations, &truth);
  truth.meas_from_base = s.meas_from_base;
  std::vector<Eigen::Vector3d> sum(truth.point_labels.size(),
                                   Eigen::Vector3d::Zero());
  std::vector<int> n(truth.point_labels.size(), 0);
  bool measured = false;
  for (const Measurement& m : ms) {
    if (m.kind == Measurement::kMeasured) {
      measured = true;
      continue;
    }
    sum[m.point] += TipInBase(truth.chain, m.input);
    ++n[m.point];
  }
  for (size_t k = 0; k < sum.size(); ++k) {
    for (int a = 0; a < 3; ++a) truth.points_in_base[k][a] = sum[k][a] / n[k];
  }
  std::vector<PointDistance> distances;
  if (with_distance) {
    PointDistance d;
    d.a = 0;
    d.b = 1;
    d.distance_mm = (sum[0] / n[0] - sum[1] / n[1]).norm();
    d.weight = 10.0;
    distances.push_back(d);
  }
  std::vector<ParamInfo> candidates;
  if (measured) candidates = FrameParams();
  for (const ParamInfo& p : PointParams(truth)) candidates.push_back(p);
  for (const ParamInfo& p : GeometryParams(truth.chain))
    candidates.push_back(p);
  Analysis a;
  a.id = AnalyzeIdentifiability(ms, truth, candidates, {}, distances);
  for (const ParamInfo& p : a.id.identifiable) {
    if (p.kind == ParamKind::kRow) a.robot_identifiable.push_back(p.name);
  }
  for (const ParamInfo& p : a.id.unidentifiable) {
    if (p.kind == ParamKind::kRow) a.robot_unidentifiable.push_back(p.name);
  }
  return a;
}

std::string Names(const std::vector<std::string>& v) {
  std::string s;
  for (const auto& n : v) s += n + " ";
  return s;
}

// Noise-free session whose true robot is the nominal one (no deviations), so
// the Jacobian is taken at the nominal geometry with exactly parallel axes.
SimulatedSession AtNominal(const Robot& robot, int fixed_points) {
  SimulateOptions opt;
  opt.noise_mm = 0.0;
  opt.sigma_length_mm = 0.0;
  opt.sigma_angle_deg = 0.0;
  opt.seed = 21;
  opt.poses = 120;
  if (fixed_points > 0) {
    opt.mode = SimulateOptions::kFixedPoint;
    opt.fixed_points = fixed_points;
    opt.poses_per_point = 40;
    opt.measure_points = false;
  }
  return Simulate(robot, opt);
}

// The parameters that no data of a point can determine on BH-7, and why
// (docs/PAPER_METHOD.md): rotations about the base z axis (j1.theta, and
// j2.theta since j2's axis is that axis), shifts along the parallel z axes
// (j1.d..j4.d) and the base x shift j1.a collapse into the measuring frame
// or the fixed point; j5.a, j5.alpha, tool.a are combinations of j5.theta /
// j5.d; tool.theta and tool.alpha turn the needle about its own tip.
const std::vector<std::string> kBh7Unidentifiable = {
    "j1.theta", "j1.d", "j1.a",     "j2.theta",   "j2.d",   "j3.d",
    "j4.d",     "j5.a", "j5.alpha", "tool.theta", "tool.a", "tool.alpha"};

TEST(IdentifiabilityTest, Bh7SinglePointDeterminesAsMuchAs3dPoints) {
  const Robot bh7 = Bh7();
  const Analysis measured = AtTruth(AtNominal(bh7, 0));
  EXPECT_EQ(measured.robot_identifiable.size(), 12u)
      << Names(measured.robot_identifiable);
  EXPECT_EQ(measured.robot_unidentifiable, kBh7Unidentifiable);
  for (int points : {1, 2, 3}) {
    const Analysis a = AtTruth(AtNominal(bh7, points));
    EXPECT_EQ(a.robot_identifiable, measured.robot_identifiable)
        << points << " fixed points: " << Names(a.robot_identifiable);
    EXPECT_TRUE(a.id.weak.empty()) << Names(a.id.weak);
  }
  // The prismatic j1 reads in mm: it fixes the scale, so a known distance
  // adds nothing on BH-7.
  const Analysis with_distance = AtTruth(AtNominal(bh7, 2), true);
  EXPECT_EQ(with_distance.robot_identifiable, measured.robot_identifiable);
  // The z shifts of the parallel axes collapse into the fixed point's z.
  const Analysis one = AtTruth(AtNominal(bh7, 1));
  bool found = false;
  for (const std::string& rel : one.id.relations) {
    if (rel.rfind("j3.d = -1.000 point.", 0) == 0) found = true;
  }
  EXPECT_TRUE(found) << "no j3.d = -point.z relation";
}

// An all-revolute arm has no length standard in its joints: single-point
// data lose the scale (one parameter) and a known distance restores it.
TEST(IdentifiabilityTest, Ur10SinglePointLosesScaleAKnownDistanceRestoresIt) {
  const Robot ur10 =
      ReadRobotYaml(testing::SourceDir() + "/data/robots/ur10.yaml");
  const Analysis measured = AtTruth(AtNominal(ur10, 0));
  EXPECT_EQ(measured.robot_identifiable.size(), 17u)
      << Names(measured.robot_identifiable);
  for (int points : {1, 2, 3}) {
    const Analysis a = AtTruth(AtNominal(ur10, points));
    EXPECT_EQ(a.robot_identifiable.size(), 16u)
        << points << " fixed points: " << Names(a.robot_identifiable);
    EXPECT_THAT(a.robot_unidentifiable, Contains("wrist_3_joint.d"));
  }
  const Analysis with_distance = AtTruth(AtNominal(ur10, 2), true);
  EXPECT_EQ(with_distance.robot_identifiable, measured.robot_identifiable);
}

// Away from the nominal geometry (the true robot has 0.2 deg twists between
// the nominally parallel axes) the rank test finds more "identifiable"
// parameters, but only through those twists: they are flagged weak.
TEST(IdentifiabilityTest, Bh7GenericGeometryAddsOnlyWeakParameters) {
  SimulateOptions opt;
  opt.mode = SimulateOptions::kFixedPoint;
  opt.fixed_points = 1;
  opt.poses_per_point = 40;
  opt.measure_points = false;
  opt.noise_mm = 0.0;
  opt.seed = 22;
  const Analysis a = AtTruth(Simulate(Bh7(), opt));
  EXPECT_EQ(a.robot_identifiable.size(), 14u) << Names(a.robot_identifiable);
  EXPECT_EQ(a.id.weak.size(), 3u) << Names(a.id.weak);
  EXPECT_THAT(a.id.weak, Contains("j3.d"));
  EXPECT_THAT(a.id.weak, Contains("j2.theta"));
}

// The scan on a caller's Jacobian (the bundle's pixels): a column in the
// span of earlier ones is held with its relation, a frame column takes part
// without the bound test, and a row column too weak for its bound at the
// given noise is held although it is independent.
TEST(IdentifiabilityTest, JacobianColumnsScanInPriorityOrder) {
  Chain chain;  // bounds: 5 mm, 5 deg
  Eigen::MatrixXd jac = Eigen::MatrixXd::Zero(4, 4);
  jac.col(0) << 1, 0, 0, 0;     // a frame pose column
  jac.col(1) << 0, 2, 0, 0;     // a.d: independent, strong
  jac.col(2) << 3, 4, 0, 0;     // a.a = 3 pose + 2 a.d: redundant
  jac.col(3) << 0, 0, 1e-3, 0;  // b.a: independent, sigma 1e3 x noise
  const std::vector<ParamInfo> candidates = {
      {"pose.0", ParamKind::kFrame, 0, 0, false},
      {"a.d", ParamKind::kRow, 0, 1, false},
      {"a.a", ParamKind::kRow, 0, 2, false},
      {"b.a", ParamKind::kRow, 1, 2, false}};
  IdentifiabilityOptions options;
  options.noise_sigma_mm = 0.01;  // b.a: sigma 10 mm > 0.1 x 5 mm
  const Identifiability id =
      AnalyzeJacobianColumns(jac, candidates, chain, options);
  EXPECT_EQ(id.IdentifiableNames(),
            (std::vector<std::string>{"pose.0", "a.d"}));
  EXPECT_EQ(id.UnidentifiableNames(), (std::vector<std::string>{"a.a", "b.a"}));
  ASSERT_EQ(id.relations.size(), 2u);
  EXPECT_EQ(id.relations[0], "a.a = +3.000 pose.0 +2.000 a.d");
  // Without a noise level only the sine test applies: b.a is determined.
  const Identifiability sine_only =
      AnalyzeJacobianColumns(jac, candidates, chain, {});
  EXPECT_THAT(sine_only.IdentifiableNames(), Contains("b.a"));
}

}  // namespace
}  // namespace kincal
