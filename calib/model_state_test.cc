#include "calib/model_state.h"

#include <gtest/gtest.h>

#include <cmath>

#include "data/error.h"
#include "data/robot.h"
#include "tests/testing/paths.h"

namespace kincal {
namespace {

ModelState Bh7State() {
  ModelState s;
  s.chain = Chain::FromRobot(
      ReadRobotYaml(testing::SourceDir() + "/data/robots/bh7.yaml"));
  s.point_labels = {"socket_a", "socket_b"};
  s.points_in_base = {{1, 2, 3}, {4, 5, 6}};
  return s;
}

TEST(ModelStateTest, ParameterListsAndNames) {
  const ModelState s = Bh7State();
  EXPECT_EQ(GeometryParams(s.chain).size(), 24u);  // 6 dh rows x 4
  EXPECT_EQ(FrameParams().size(), 6u);
  const std::vector<ParamInfo> points = PointParams(s);
  ASSERT_EQ(points.size(), 6u);
  EXPECT_EQ(points[3].kind, ParamKind::kPoint);
  EXPECT_EQ(points[3].block, 1);
  EXPECT_EQ(s.PointIndex("socket_b"), 1);
  EXPECT_EQ(s.PointIndex("nope"), -1);
  for (const ParamInfo& p : GeometryParams(s.chain))
    EXPECT_EQ(FindParam(s, p.name).name, p.name);
}

TEST(ModelStateTest, AddressesReachTheState) {
  ModelState s = Bh7State();
  const ParamInfo a = FindParam(s, s.chain.rows[2].name + ".a");
  EXPECT_FALSE(a.angle);
  *ParamAddress(&s, a) += 1.5;
  EXPECT_DOUBLE_EQ(ParamValue(s, a), s.chain.rows[2].p[a.index]);
  const ParamInfo alpha = FindParam(s, s.chain.rows[2].name + ".alpha");
  EXPECT_TRUE(alpha.angle);
  EXPECT_NEAR(alpha.ToInterface(M_PI / 2), 90.0, 1e-12);
  EXPECT_NEAR(alpha.FromInterface(90.0), M_PI / 2, 1e-12);
  const ParamInfo ty = FrameParams()[4];
  *ParamAddress(&s, ty) = 7.0;
  EXPECT_EQ(s.meas_from_base[4], 7.0);
  EXPECT_EQ(ParamValue(s, PointParams(s)[5]), 6.0);
}

// Each family's unit matches what ToInterface gives (docs/CONVENTIONS.md).
TEST(ModelStateTest, InterfaceUnitPerFamily) {
  const ModelState s = Bh7State();
  EXPECT_EQ(FindParam(s, s.chain.rows[2].name + ".a").InterfaceUnit(), "mm");
  EXPECT_EQ(FrameParams()[0].InterfaceUnit(), "deg");
  EXPECT_EQ(PointParams(s)[0].InterfaceUnit(), "mm");
  const auto unit = [&](int index) {
    return JointErrorParam(s.chain, 2, index).InterfaceUnit();
  };
  EXPECT_EQ(unit(kGain), "1");
  EXPECT_EQ(unit(kBacklash), "deg");
  EXPECT_EQ(unit(kCompliance), "deg/mm");
  EXPECT_EQ(unit(kElastostatic), "deg/(N m)");
  EXPECT_EQ(unit(kThermal), "1/K or 1/h");
  EXPECT_EQ(unit(kTransmission0), "deg");
  // j1 is prismatic: its errors are lengths.
  EXPECT_EQ(JointErrorParam(s.chain, 0, kBacklash).InterfaceUnit(), "mm");
  EXPECT_EQ(JointErrorParam(s.chain, 0, kCompliance).InterfaceUnit(), "mm/mm");
  EXPECT_EQ(JointErrorParam(s.chain, 0, kElastostatic).InterfaceUnit(), "mm/N");
  EXPECT_EQ(DriftParams()[0].InterfaceUnit(), "mm/h");
  for (const ParamInfo& p : MountParams())
    EXPECT_EQ(p.InterfaceUnit(), "deg/(N m)");
}

TEST(ModelStateTest, UnknownNameIsInputError) {
  const ModelState s = Bh7State();
  EXPECT_THROW(FindParam(s, "j99.theta"), InputError);
}

}  // namespace
}  // namespace kincal
