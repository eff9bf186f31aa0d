// kincal export urdf | dh | ur-calibration end to end: JSON fields, the URDF
// read back has the robot file's kinematics, check_urdf accepts it,
// extensions are listed, bad input exits 2 and writes nothing; the UR
// kinematics file imported back has the robot file's kinematics.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <random>

#include "calib/chain.h"
#include "data/atomic_file.h"
#include "data/robot.h"
#include "data/urdf.h"
#include "tests/testing/paths.h"
#include "tests/testing/run.h"

namespace kincal {
namespace {

using testing::Exists;
using ::testing::HasSubstr;
using testing::RunKincal;
using testing::RunShell;

double MaxTipDifference(const Robot& a, const Robot& b) {
  const Chain ca = Chain::FromRobot(a), cb = Chain::FromRobot(b);
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  double worst = 0.0;
  for (int i = 0; i < 100; ++i) {
    std::vector<double> q(ca.num_joints());
    for (int k = 0; k < ca.num_joints(); ++k) {
      q[k] = ca.rows[k].type == JointType::kPrismatic ? 100 * u(rng)
                                                      : M_PI * u(rng);
    }
    worst = std::max(worst, (BaseFromTipAt(ca, q) - BaseFromTipAt(cb, q))
                                .block<3, 1>(0, 3)
                                .cwiseAbs()
                                .maxCoeff());
  }
  return worst;
}

TEST(ExportCliTest, UrdfFromCalibratedYamlWithExtensions) {
  const std::string dir = testing::MakeTempDir("export");
  std::string yaml =
      ReadFile(testing::SourceDir() + "/data/robots/bh7.yaml") +
      "extensions:\n  - {cause: backlash, joint: j3, width: 0.15}\n";
  std::ofstream(dir + "/cal.yaml") << yaml;
  const auto r = RunKincal("export urdf --robot " + dir + "/cal.yaml --out " +
                           dir + "/bh7.urdf --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["out"], dir + "/bh7.urdf");
  ASSERT_EQ(j["not_exported"].size(), 1u);
  EXPECT_THAT(j["not_exported"][0].get<std::string>(), HasSubstr("backlash"));
  const std::string xml = ReadFile(dir + "/bh7.urdf");
  EXPECT_THAT(xml, HasSubstr("NOT EXPORTED"));
  EXPECT_THAT(xml, HasSubstr("export urdf"));  // provenance
  const Robot back = ReadUrdfChain(dir + "/bh7.urdf");
  Robot plain = ReadRobotYaml(dir + "/cal.yaml");
  plain.extensions.clear();
  EXPECT_LT(MaxTipDifference(plain, back), 1e-9);
  if (RunShell("command -v check_urdf").exit_code == 0) {
    const auto c = RunShell("check_urdf " + dir + "/bh7.urdf");
    EXPECT_EQ(c.exit_code, 0) << c.out << c.err;
    EXPECT_THAT(c.out, HasSubstr("Successfully Parsed XML"));
  }
  // And back to DH through the CLI.
  const auto d = RunKincal("export dh --robot " + dir + "/bh7.urdf --out " +
                           dir + "/bh7_dh.yaml --json");
  ASSERT_EQ(d.exit_code, 0) << d.err;
  EXPECT_LT(MaxTipDifference(plain, ReadRobotYaml(dir + "/bh7_dh.yaml")), 1e-9);
}

TEST(ExportCliTest, BadInputExitsTwoAndWritesNothing) {
  const std::string dir = testing::MakeTempDir("export_bad");
  std::ofstream(dir + "/bad.yaml") << "kincal_robot: 1\nname: x\njoints: 3\n";
  auto r = RunKincal("export urdf --robot " + dir + "/bad.yaml --out " + dir +
                     "/x.urdf");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.err, HasSubstr("bad.yaml"));
  EXPECT_FALSE(Exists(dir + "/x.urdf"));
  r = RunKincal("export urdf --robot " + dir + "/missing.yaml --out " + dir +
                "/x.urdf");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_FALSE(Exists(dir + "/x.urdf"));
  // A URDF whose first joint turns about x has no standard DH form.
  std::ofstream(dir + "/x_first.urdf")
      << "<robot name='r'><link name='a'/><link name='b'/>"
         "<joint name='j1' type='continuous'><parent link='a'/>"
         "<child link='b'/><axis xyz='1 0 0'/></joint></robot>";
  r = RunKincal("export dh --robot " + dir + "/x_first.urdf --out " + dir +
                "/x.yaml");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.err, HasSubstr("base z axis"));
  EXPECT_FALSE(Exists(dir + "/x.yaml"));
}

TEST(ExportCliTest, UrCalibrationWritesKinematicsAndImportsBack) {
  const std::string dir = testing::MakeTempDir("export_ur");
  std::ofstream(dir + "/cal.yaml")
      << ReadFile(testing::SourceDir() + "/data/robots/ur10.yaml") +
             "extensions:\n  - {cause: backlash, joint: elbow_joint, width: "
             "0.02}\n";
  const auto r = RunKincal("export ur-calibration --robot " + dir +
                           "/cal.yaml --out " + dir + "/kin.yaml --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["out"], dir + "/kin.yaml");
  ASSERT_EQ(j["not_exported"].size(), 2u);
  EXPECT_THAT(j["not_exported"][0].get<std::string>(), HasSubstr("backlash"));
  EXPECT_THAT(j["not_exported"][1].get<std::string>(), HasSubstr("TCP"));
  EXPECT_NEAR(j["tcp"]["z_mm"].get<double>(), 93.0, 1e-9);
  const std::string text = ReadFile(dir + "/kin.yaml");
  EXPECT_THAT(text, HasSubstr("export ur-calibration"));  // provenance
  EXPECT_THAT(text, HasSubstr("hash: " + j["hash"].get<std::string>()));
  const auto i =
      RunKincal("import ur-calibration --in " + dir +
                "/kin.yaml --name UR10 --out " + dir + "/back.yaml --json");
  ASSERT_EQ(i.exit_code, 0) << i.err;
  // The import ends at tool0 (zero TCP); with the exported TCP put back as
  // the tool row it is the robot file's kinematics.
  Robot back = ReadRobotYaml(dir + "/back.yaml");
  EXPECT_EQ(back.convention, Convention::kUrdf);
  back.tool.xyz_mm = Eigen::Vector3d(0, 0, 93.0);  // wrist_3_link axes
  back.tool.rpy_deg = Eigen::Vector3d::Zero();
  Robot plain = ReadRobotYaml(dir + "/cal.yaml");
  plain.extensions.clear();
  EXPECT_LT(MaxTipDifference(plain, back), 1e-9);
}

TEST(ExportCliTest, UrCalibrationRefusesOtherArms) {
  const std::string dir = testing::MakeTempDir("export_ur_bad");
  const auto r =
      RunKincal("export ur-calibration --robot " + testing::SourceDir() +
                "/data/robots/bh7.yaml --out " + dir + "/k.yaml");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.err, HasSubstr("6 revolute joints"));
  EXPECT_FALSE(Exists(dir + "/k.yaml"));
}

}  // namespace
}  // namespace kincal
