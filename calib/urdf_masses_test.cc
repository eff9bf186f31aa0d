// Link masses read from URDF <inertial> reach the gravity torques of the
// elastostatic model (MakePoseInputs) in the frame the rows assume: a
// two-link arm's torques from a URDF-loaded model equal the ones computed
// by hand.
#include <gtest/gtest.h>

#include <cmath>

#include "calib/chain.h"
#include "data/urdf.h"

namespace kincal {
namespace {

// Shoulder at 0.4 m height turning about y; the upper arm (2 kg, centre
// 0.15 m out) carries an elbow housing on a fixed joint (0.5 kg, turned
// 90 deg about z, its centre 0.02 m along its own -y = +x of the arm, at
// 0.3 m), then the elbow (about y) at 0.35 m; the forearm (1.2 kg, centre
// 0.1 m out) carries a tool on a fixed joint turned 180 deg about z (0.3 kg,
// its centre 0.05 m along its own -x = +x of the forearm, at 0.25 m).
const char* kArm = R"(<robot name="arm2">
  <link name="base"/>
  <link name="upper"><inertial><origin xyz="0.15 0 0"/><mass value="2"/>
    <inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
  <link name="housing"><inertial><origin xyz="0 -0.02 0"/><mass value="0.5"/>
    <inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
  <link name="fore"><inertial><origin xyz="0.1 0 0"/><mass value="1.2"/>
    <inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
  <link name="tool"><inertial><origin xyz="-0.05 0 0"/><mass value="0.3"/>
    <inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
  <joint name="shoulder" type="revolute"><parent link="base"/><child link="upper"/>
    <origin xyz="0 0 0.4"/><axis xyz="0 1 0"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <joint name="housing_mount" type="fixed"><parent link="upper"/><child link="housing"/>
    <origin xyz="0.3 0 0" rpy="0 0 1.5707963267948966"/></joint>
  <joint name="elbow" type="revolute"><parent link="upper"/><child link="fore"/>
    <origin xyz="0.35 0 0"/><axis xyz="0 1 0"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <joint name="tool_mount" type="fixed"><parent link="fore"/><child link="tool"/>
    <origin xyz="0.25 0 0" rpy="0 0 3.141592653589793"/><axis xyz="0 0 0"/></joint>
</robot>)";

TEST(UrdfMassesTest, GravityTorquesOfTwoLinkArmMatchHandComputation) {
  const Robot robot = ParseUrdfChain(kArm, "arm2.urdf", "", "tool");
  ASSERT_EQ(robot.joints.size(), 2u);
  const Chain chain = Chain::FromRobot(robot);
  Observations obs;
  obs.joint_names = robot.JointNames();
  for (const auto& q : std::vector<std::vector<double>>{
           {0, 0}, {30, -45}, {-70, 110}, {95, 20}}) {
    Observation o;
    o.pose = std::to_string(obs.rows.size());
    o.q = q;
    obs.rows.push_back(o);
  }
  const std::vector<PoseInput> in = MakePoseInputs(chain, obs);
  ASSERT_EQ(in.size(), obs.rows.size());
  for (size_t i = 0; i < in.size(); ++i) {
    // Rotation about +y by q moves a point r out along the arm to
    // x = r cos(q); with gravity -z the torque about +y of a weight m g at
    // horizontal distance dx from the axis is m g dx (N m, m).
    const double q1 = obs.rows[i].q[0] * M_PI / 180;
    const double q12 = q1 + obs.rows[i].q[1] * M_PI / 180;
    const double g = 9.80665;
    const double x_upper = 0.15 * std::cos(q1);
    const double x_housing = 0.32 * std::cos(q1);
    const double x_elbow = 0.35 * std::cos(q1);
    const double x_fore = x_elbow + 0.1 * std::cos(q12);
    const double x_tool = x_elbow + 0.30 * std::cos(q12);
    const double tau_shoulder =
        g * (2.0 * x_upper + 0.5 * x_housing + 1.2 * x_fore + 0.3 * x_tool);
    const double tau_elbow =
        g * (1.2 * (x_fore - x_elbow) + 0.3 * (x_tool - x_elbow));
    EXPECT_NEAR(in[i].tau_mass[0], tau_shoulder, 1e-9) << "pose " << i;
    EXPECT_NEAR(in[i].tau_mass[1], tau_elbow, 1e-9) << "pose " << i;
  }
  EXPECT_GT(std::abs(in[0].tau_mass[0]), 5.0);  // not a vacuous zero
}

}  // namespace
}  // namespace kincal
