// Universal Robots kinematics export: the description's chain rebuilt from
// the exported entries (ur_description's joint origins, Rz(q) per joint,
// tool0 and the TCP offset) reproduces kincal's forward kinematics at random
// joint vectors for calibrated-looking UR10 variants (standard DH with betas,
// MDH, URDF); the nominal UR10 exports to ur_description's own
// default_kinematics.yaml; the reader refuses bad files; robots that the
// format cannot express are refused with the reason.

#include "calib/ur_calibration.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cstdio>
#include <random>

#include "calib/chain.h"
#include "calib/urdf_export.h"
#include "data/error.h"
#include "data/urdf.h"
#include "tests/testing/paths.h"

namespace kincal {
namespace {

using ::testing::HasSubstr;
using ::testing::MatchesRegex;

constexpr double kDeg = M_PI / 180.0;

// ur_description's UR10 file, quoted verbatim: config/ur10/
// default_kinematics.yaml of github.com/ros-industrial/universal_robot
// (commit e30bc2ed83093a1fd1468cf77bb61b1b1725df9d) and of
// github.com/UniversalRobots/Universal_Robots_ROS2_Driver
// (ur_description/config/ur10/default_kinematics.yaml, commit
// 8be35f34f2a39d254e149c1309a221a4ad97aa7b), identical in both.
const char kUr10DefaultKinematics[] = R"(kinematics:
  shoulder:
    x: 0
    y: 0
    z: 0.1273
    roll: 0
    pitch: 0
    yaw: 0
  upper_arm:
    x: 0
    y: 0
    z: 0
    roll: 1.570796327
    pitch: 0
    yaw: 0
  forearm:
    x: -0.612
    y: 0
    z: 0
    roll: 0
    pitch: 0
    yaw: 0
  wrist_1:
    x: -0.5723
    y: 0
    z: 0.163941
    roll: 0
    pitch: 0
    yaw: 0
  wrist_2:
    x: 0
    y: -0.1157
    z: -2.373046667922381e-11
    roll: 1.570796327
    pitch: 0
    yaw: 0
  wrist_3:
    x: 0
    y: 0.0922
    z: -1.891053610911353e-11
    roll: 1.570796326589793
    pitch: 3.141592653589793
    yaw: 3.141592653589793
  hash: calib_17227329492635474227
)";

Robot Ur10() {
  return ReadRobotYaml(testing::SourceDir() + "/data/robots/ur10.yaml");
}

std::vector<double> RandomQ(std::mt19937_64* rng) {
  std::uniform_real_distribution<double> u(-M_PI, M_PI);
  std::vector<double> q(kUrJoints);
  for (double& v : q) v = u(*rng);
  return q;
}

// The robot file's base_from_frame after the last joint (no tool row).
Eigen::Matrix4d BaseFromFlange(const Chain& chain,
                               const std::vector<double>& q) {
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  for (int k = 0; k < chain.num_joints(); ++k) {
    m = m * RowTransform<double>(chain.convention, chain.rows[k],
                                 chain.rows[k].p.data(), q[k]);
  }
  return m;
}

struct FkDifference {
  double position_mm = 0.0;
  double rotation = 0.0;  // max abs difference of rotation matrix entries
};

FkDifference Difference(const Eigen::Matrix4d& a, const Eigen::Matrix4d& b) {
  FkDifference d;
  d.position_mm =
      (a.block<3, 1>(0, 3) - b.block<3, 1>(0, 3)).cwiseAbs().maxCoeff();
  d.rotation =
      (a.block<3, 3>(0, 0) - b.block<3, 3>(0, 0)).cwiseAbs().maxCoeff();
  return d;
}

// The tip through the description (tool0, then the TCP offset as the
// pendant applies it: translation + rotation vector) against kincal's FK,
// over 100 random joint vectors.
FkDifference TipDifference(const Robot& robot, const UrCalibrationExport& e) {
  const Chain chain = Chain::FromRobot(robot);
  Eigen::Matrix4d tcp = Eigen::Matrix4d::Identity();
  const double angle = e.tcp.rotation_vector_rad.norm();
  if (angle > 0) {
    tcp.block<3, 3>(0, 0) =
        Eigen::AngleAxisd(angle, e.tcp.rotation_vector_rad / angle)
            .toRotationMatrix();
  }
  tcp.block<3, 1>(0, 3) = e.tcp.xyz_mm;
  std::mt19937_64 rng(11);
  FkDifference worst;
  for (int i = 0; i < 100; ++i) {
    const std::vector<double> q = RandomQ(&rng);
    const FkDifference d =
        Difference(BaseFromTipAt(chain, q),
                   UrDescriptionFk(e.kinematics, q).base_from_tool0 * tcp);
    worst.position_mm = std::max(worst.position_mm, d.position_mm);
    worst.rotation = std::max(worst.rotation, d.rotation);
  }
  return worst;
}

// A calibrated-looking UR10: every length moved by up to 2 mm, every angle
// by up to 0.5 deg, betas of up to 0.3 deg on the parallel joints 2 and 3
// (Hayati), the tool by up to 2 mm; the last row's a, alpha, beta kept at 0
// when `flange_nominal`.
Robot PerturbedUr10(std::mt19937_64* rng, bool flange_nominal) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Robot r = Ur10();
  for (int k = 0; k < kUrJoints; ++k) {
    RobotRow& row = r.joints[k];
    row.theta_deg += 0.5 * u(*rng);
    row.d_mm += 2.0 * u(*rng);
    if (!(flange_nominal && k == kUrJoints - 1)) {
      row.a_mm += 2.0 * u(*rng);
      row.alpha_deg += 0.5 * u(*rng);
    }
    if (k == 1 || k == 2) row.beta_deg = 0.3 * u(*rng);
  }
  r.tool.a_mm += 2.0 * u(*rng);
  r.tool.d_mm += 2.0 * u(*rng);
  r.tool.alpha_deg += 0.5 * u(*rng);
  r.tool.theta_deg += 10.0 * u(*rng);
  return r;
}

// The nominal UR10 in modified DH (same kinematics as the DH file):
// row k = Rx(alpha_{k-1}) Tx(a_{k-1}) Rz(q_k) Tz(d_k).
Robot Ur10Mdh() {
  const Robot dh = Ur10();
  Robot r = dh;
  r.convention = Convention::kMdh;
  for (int k = 0; k < kUrJoints; ++k) {
    RobotRow& row = r.joints[k];
    row.alpha_deg = k == 0 ? 0.0 : dh.joints[k - 1].alpha_deg;
    row.a_mm = k == 0 ? 0.0 : dh.joints[k - 1].a_mm;
    row.d_mm = dh.joints[k].d_mm;
    row.theta_deg = dh.joints[k].theta_deg;
  }
  r.tool.alpha_deg = dh.joints[5].alpha_deg;
  r.tool.a_mm = dh.joints[5].a_mm;
  r.tool.d_mm = dh.tool.d_mm;
  return r;
}

TEST(UrCalibrationTest, NominalUr10MatchesUrDescriptionDefaults) {
  const UrCalibrationExport e = ExportUrCalibration(Ur10(), "ur10.yaml");
  const UrKinematics ur =
      ParseUrKinematicsYaml(kUr10DefaultKinematics, "default_kinematics.yaml");
  EXPECT_EQ(ur.hash, "calib_17227329492635474227");
  for (int j = 0; j < kUrJoints; ++j) {
    SCOPED_TRACE(kUrEntryNames[j]);
    // Translations agree to the file's rounding of pi/2 (1.570796327):
    // 0.1157 m x 2e-10 = 2.4e-11 m.
    EXPECT_LT((e.kinematics.entries[j].xyz_m - ur.entries[j].xyz_m)
                  .cwiseAbs()
                  .maxCoeff(),
              1e-10);
    // The rotations are equal; their angle triplets may differ (wrist_3:
    // roll -pi/2 here, (pi/2, pi, pi) in UR's file, the same rotation).
    const Eigen::Matrix4d mine = UrEntryTransform(e.kinematics.entries[j]);
    const Eigen::Matrix4d theirs = UrEntryTransform(ur.entries[j]);
    EXPECT_LT((mine.block<3, 3>(0, 0) - theirs.block<3, 3>(0, 0))
                  .cwiseAbs()
                  .maxCoeff(),
              1e-9);
  }
  // The flange: wrist_3_link of UR's own file is the DH frame 6 of
  // data/robots/ur10.yaml (same base frame: the controller's Base); tool0,
  // the controller's zero-TCP frame, is it turned 180 deg about z.
  const Chain chain = Chain::FromRobot(Ur10());
  std::mt19937_64 rng(5);
  double worst_mm = 0.0;
  for (int i = 0; i < 100; ++i) {
    const std::vector<double> q = RandomQ(&rng);
    const UrDescriptionPose p = UrDescriptionFk(ur, q);
    const FkDifference d =
        Difference(BaseFromFlange(chain, q), p.base_from_wrist3);
    worst_mm = std::max(worst_mm, d.position_mm);
    EXPECT_LT(d.rotation, 1e-9);
  }
  EXPECT_LT(worst_mm, 1e-6);
  Eigen::Matrix4d rz_pi = Eigen::Matrix4d::Identity();
  rz_pi.block<2, 2>(0, 0) = -Eigen::Matrix2d::Identity();
  EXPECT_LT((UrWrist3FromTool0() - rz_pi).cwiseAbs().maxCoeff(), 1e-15);
  // The tool row of ur10.yaml (93 mm along the flange z axis) is the TCP
  // z = 93 mm; its frame keeps the DH flange's orientation: rotation vector
  // 180 deg about z from tool0.
  EXPECT_NEAR(e.tcp.xyz_mm.x(), 0.0, 1e-9);
  EXPECT_NEAR(e.tcp.xyz_mm.y(), 0.0, 1e-9);
  EXPECT_NEAR(e.tcp.xyz_mm.z(), 93.0, 1e-9);
  EXPECT_NEAR(e.tcp.rotation_vector_rad.norm(), M_PI, 1e-12);
  EXPECT_NEAR(std::abs(e.tcp.rotation_vector_rad.z()), M_PI, 1e-12);
}

TEST(UrCalibrationTest, RoundTripOfCalibratedDhVariants) {
  std::mt19937_64 rng(7);
  FkDifference worst_tip, worst_flange;
  for (int trial = 0; trial < 20; ++trial) {
    const bool flange_nominal = trial % 2 == 0;
    const Robot robot = PerturbedUr10(&rng, flange_nominal);
    const UrCalibrationExport e = ExportUrCalibration(robot, "cal.yaml");
    // Through the file text: what the description reads.
    UrCalibrationExport read_back = e;
    read_back.kinematics = ParseUrKinematicsYaml(e.yaml, "cal_ur.yaml");
    EXPECT_EQ(read_back.kinematics.hash, e.kinematics.hash);
    const FkDifference d = TipDifference(robot, read_back);
    worst_tip.position_mm = std::max(worst_tip.position_mm, d.position_mm);
    worst_tip.rotation = std::max(worst_tip.rotation, d.rotation);
    if (flange_nominal) {  // then wrist_3_link is the DH frame 6
      const Chain chain = Chain::FromRobot(robot);
      std::mt19937_64 qrng(trial);
      for (int i = 0; i < 100; ++i) {
        const std::vector<double> q = RandomQ(&qrng);
        const FkDifference f = Difference(
            BaseFromFlange(chain, q),
            UrDescriptionFk(read_back.kinematics, q).base_from_wrist3);
        worst_flange.position_mm =
            std::max(worst_flange.position_mm, f.position_mm);
        worst_flange.rotation = std::max(worst_flange.rotation, f.rotation);
      }
    }
  }
  std::printf(
      "UR round trip (20 calibrated DH UR10s, 100 poses each): tip %.3g mm "
      "(rotation %.3g), flange %.3g mm (rotation %.3g)\n",
      worst_tip.position_mm, worst_tip.rotation, worst_flange.position_mm,
      worst_flange.rotation);
  EXPECT_LT(worst_tip.position_mm, 1e-6);
  EXPECT_LT(worst_tip.rotation, 1e-12);
  EXPECT_LT(worst_flange.position_mm, 1e-6);
  EXPECT_LT(worst_flange.rotation, 1e-12);
}

// Without betas the entries are the ones ur_calibration builds from a
// controller's DH (calibration.cpp, buildChain / getSimplified):
// entry 1 = Rz(theta1) Tz(d1), entry k = [Tx(a_k-1) Rx(alpha_k-1)]
// [Rz(theta_k) Tz(d_k)].
TEST(UrCalibrationTest, EntriesAreUrCalibrationsSegments) {
  std::mt19937_64 rng(23);
  for (int trial = 0; trial < 5; ++trial) {
    Robot robot = PerturbedUr10(&rng, false);
    for (RobotRow& row : robot.joints) row.beta_deg = 0.0;
    const UrCalibrationExport e = ExportUrCalibration(robot, "cal.yaml");
    Eigen::Matrix4d passive = Eigen::Matrix4d::Identity();
    for (int k = 0; k < kUrJoints; ++k) {
      const RobotRow& row = robot.joints[k];
      const Eigen::Matrix4d active = internal::RotZ(row.theta_deg * kDeg) *
                                     internal::Trans(0.0, 0.0, row.d_mm);
      EXPECT_LT((UrEntryTransform(e.kinematics.entries[k]) - passive * active)
                    .cwiseAbs()
                    .maxCoeff(),
                1e-9)
          << kUrEntryNames[k];
      passive = internal::Trans(row.a_mm, 0.0, 0.0) *
                internal::RotX(row.alpha_deg * kDeg);
    }
  }
}

TEST(UrCalibrationTest, RoundTripOfMdhAndUrdfVariants) {
  // The MDH form has the nominal kinematics of the DH file.
  const Chain dh = Chain::FromRobot(Ur10());
  const Chain mdh_nominal = Chain::FromRobot(Ur10Mdh());
  std::mt19937_64 rng(13);
  for (int i = 0; i < 10; ++i) {
    const std::vector<double> q = RandomQ(&rng);
    ASSERT_LT(Difference(BaseFromTipAt(dh, q), BaseFromTipAt(mdh_nominal, q))
                  .position_mm,
              1e-9);
  }
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  double worst_mdh = 0.0, worst_urdf = 0.0;
  for (int trial = 0; trial < 10; ++trial) {
    Robot mdh = Ur10Mdh();
    for (RobotRow& row : mdh.joints) {
      row.a_mm += 2.0 * u(rng);
      row.d_mm += 2.0 * u(rng);
      row.alpha_deg += 0.5 * u(rng);
      row.theta_deg += 0.5 * u(rng);
      row.beta_deg = 0.3 * u(rng);
    }
    worst_mdh = std::max(
        worst_mdh,
        TipDifference(mdh, ExportUrCalibration(mdh, "mdh.yaml")).position_mm);

    // URDF: a calibrated DH UR10 through `export urdf`, then every origin
    // and axis moved (axes tilted by up to 1 deg, one joint reversed).
    Robot urdf =
        ParseUrdfChain(ExportUrdf(PerturbedUr10(&rng, false)).xml, "cal.urdf");
    ASSERT_EQ(urdf.convention, Convention::kUrdf);
    for (RobotRow& row : urdf.joints) {
      row.xyz_mm += 2.0 * Eigen::Vector3d(u(rng), u(rng), u(rng));
      row.rpy_deg += 0.5 * Eigen::Vector3d(u(rng), u(rng), u(rng));
      row.axis = (row.axis + 0.017 * Eigen::Vector3d(u(rng), u(rng), u(rng)))
                     .normalized();
    }
    urdf.joints[trial % kUrJoints].axis *= -1.0;
    worst_urdf = std::max(
        worst_urdf,
        TipDifference(urdf, ExportUrCalibration(urdf, "cal.urdf")).position_mm);
  }
  std::printf("UR round trip: MDH %.3g mm, URDF %.3g mm (10 robots each)\n",
              worst_mdh, worst_urdf);
  EXPECT_LT(worst_mdh, 1e-6);
  EXPECT_LT(worst_urdf, 1e-6);
}

TEST(UrCalibrationTest, ImportedKinematicsHaveTheDescriptionsFk) {
  const UrKinematics ur =
      ParseUrKinematicsYaml(kUr10DefaultKinematics, "default_kinematics.yaml");
  Eigen::Matrix4d tcp = Eigen::Matrix4d::Identity();
  tcp.block<3, 1>(0, 3) = Eigen::Vector3d(1.0, -2.0, 150.0);
  tcp.block<3, 3>(0, 0) =
      Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized())
          .toRotationMatrix();
  const Robot robot = RobotFromUrKinematics(ur, "UR10 factory", tcp);
  EXPECT_EQ(robot.convention, Convention::kUrdf);
  EXPECT_EQ(robot.joints[1].name, "shoulder_lift_joint");
  const Chain chain = Chain::FromRobot(robot);
  std::mt19937_64 rng(17);
  for (int i = 0; i < 20; ++i) {
    const std::vector<double> q = RandomQ(&rng);
    EXPECT_LT(Difference(BaseFromTipAt(chain, q),
                         UrDescriptionFk(ur, q).base_from_tool0 * tcp)
                  .position_mm,
              1e-9);
  }
  // Exported again: the same joint origins and TCP.
  const UrCalibrationExport e = ExportUrCalibration(robot, "imported.yaml");
  for (int j = 0; j < kUrJoints; ++j) {
    EXPECT_TRUE(UrEntryTransform(e.kinematics.entries[j])
                    .isApprox(UrEntryTransform(ur.entries[j]), 1e-11))
        << kUrEntryNames[j];
  }
  EXPECT_TRUE(e.tool0_from_tip.isApprox(tcp, 1e-11));
}

TEST(UrCalibrationTest, FileCarriesProvenanceTcpAndNotExported) {
  Robot robot = Ur10();
  robot.extensions.push_back({"backlash", "elbow_joint", {{"width", 0.02}}});
  robot.extensions.push_back(
      {"drift", "", {{"vx", 0.1}, {"vy", 0.0}, {"vz", 0.0}}});
  const UrCalibrationExport e = ExportUrCalibration(robot, "cal.yaml");
  ASSERT_EQ(e.not_exported.size(), 3u);
  EXPECT_THAT(e.not_exported[0], HasSubstr("backlash elbow_joint"));
  EXPECT_THAT(e.not_exported[1], HasSubstr("drift"));
  EXPECT_THAT(e.not_exported[2], HasSubstr("TCP"));
  EXPECT_THAT(e.not_exported[2], HasSubstr("z 93.0000 mm"));
  EXPECT_THAT(e.yaml, HasSubstr("# written by kincal"));
  EXPECT_THAT(e.yaml, HasSubstr("NOT EXPORTED"));
  EXPECT_THAT(e.yaml, HasSubstr("kinematics_params_file"));
  EXPECT_THAT(e.kinematics.hash, MatchesRegex("calib_[0-9]+"));
  // Deterministic, and a change of one value changes it.
  EXPECT_EQ(ExportUrCalibration(robot, "cal.yaml").kinematics.hash,
            e.kinematics.hash);
  robot.joints[2].a_mm += 0.01;
  EXPECT_NE(ExportUrCalibration(robot, "cal.yaml").kinematics.hash,
            e.kinematics.hash);
}

// A robot file based at ROS base_link (the controller's Base turned 180 deg
// about z: theta1 + 180 deg in DH) exports the same entries with
// --robot-base base_link, and the wrong choice is named by a warning.
TEST(UrCalibrationTest, RobotBasedAtBaseLink) {
  const UrCalibrationExport nominal = ExportUrCalibration(Ur10(), "ur10.yaml");
  Robot at_base_link = Ur10();
  at_base_link.joints[0].theta_deg += 180.0;
  Warnings none;
  const UrCalibrationExport e = ExportUrCalibration(
      at_base_link, "bl.yaml", UrRobotBase::kBaseLink, &none);
  EXPECT_TRUE(none.empty());
  for (int j = 0; j < kUrJoints; ++j) {
    EXPECT_LT((UrEntryTransform(e.kinematics.entries[j]) -
               UrEntryTransform(nominal.kinematics.entries[j]))
                  .cwiseAbs()
                  .maxCoeff(),
              1e-9)
        << kUrEntryNames[j];
  }
  EXPECT_THAT(e.yaml, HasSubstr("--robot-base base_link"));
  Warnings wrong;
  ExportUrCalibration(at_base_link, "bl.yaml", UrRobotBase::kBase, &wrong);
  ASSERT_TRUE(wrong.Has("ur_base_frame"));
  EXPECT_THAT(wrong.list()[0].message, HasSubstr("--robot-base base_link"));
  Warnings right;
  ExportUrCalibration(Ur10(), "ur10.yaml", UrRobotBase::kBase, &right);
  EXPECT_TRUE(right.empty());
  ExportUrCalibration(Ur10(), "ur10.yaml", UrRobotBase::kBaseLink, &right);
  EXPECT_TRUE(right.Has("ur_base_frame"));
}

TEST(UrCalibrationTest, RobotsTheFormatCannotExpressAreRefused) {
  Robot five = Ur10();
  five.joints.pop_back();
  try {
    ExportUrCalibration(five, "five.yaml");
    FAIL() << "no error for 5 joints";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("has 5 joints"));
    EXPECT_THAT(e.what(), HasSubstr("6 revolute joints"));
  }
  Robot prismatic = Ur10();
  prismatic.joints[3].type = JointType::kPrismatic;
  try {
    ExportUrCalibration(prismatic, "p.yaml");
    FAIL() << "no error for a prismatic joint";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("joint 4 ('wrist_1_joint')"));
    EXPECT_THAT(e.what(), HasSubstr("prismatic"));
  }
}

TEST(UrCalibrationTest, ReaderRefusesBadFilesWithPosition) {
  std::string missing = kUr10DefaultKinematics;
  missing = missing.substr(0, missing.find("  wrist_3:"));
  EXPECT_THROW(
      {
        try {
          ParseUrKinematicsYaml(missing, "k.yaml");
        } catch (const InputError& e) {
          EXPECT_THAT(e.what(), HasSubstr("k.yaml"));
          EXPECT_THAT(e.what(), HasSubstr("wrist_3"));
          throw;
        }
      },
      InputError);
  std::string typo = kUr10DefaultKinematics;
  typo.replace(typo.find("    pitch: 0\n"), 13, "    pich: 0\n");
  EXPECT_THROW(ParseUrKinematicsYaml(typo, "k.yaml"), InputError);
  std::string mm = kUr10DefaultKinematics;
  mm.replace(mm.find("-0.612"), 6, "-612.0");
  try {
    ParseUrKinematicsYaml(mm, "k.yaml");
    FAIL() << "no error for millimetres";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("k.yaml:17:8"));
    EXPECT_THAT(e.what(), HasSubstr("metres"));
  }
}

}  // namespace
}  // namespace kincal
