// URDF export and DH conversion: the forward kinematics of the URDF read back
// (data/urdf.h -> chain) equals the robot file's to 1e-9 mm over random
// poses, for BH-7 (DH with a prismatic joint), the UR10 (DH), perturbed
// "calibrated" versions of both (beta included), MDH, and the Panda (URDF
// in -> calibrate on its real socket data -> URDF out).

#include "calib/urdf_export.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <random>

#include "calib/calibrate.h"
#include "calib/chain.h"
#include "data/error.h"
#include "data/import_mukca.h"
#include "data/urdf.h"
#include "tests/testing/paths.h"

namespace kincal {
namespace {

using ::testing::HasSubstr;

Robot Bundled(const std::string& name) {
  return ReadRobotYaml(testing::SourceDir() + "/data/robots/" + name);
}

// Largest tip-position difference (mm) between two robots over random joint
// values (revolute +-180 deg, prismatic +-200 mm), without extensions.
double MaxTipDifference(const Robot& a, const Robot& b, int poses = 200) {
  const Chain ca = Chain::FromRobot(a), cb = Chain::FromRobot(b);
  EXPECT_EQ(ca.num_joints(), cb.num_joints());
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  double worst = 0.0;
  for (int i = 0; i < poses; ++i) {
    std::vector<double> q(ca.num_joints());
    for (int k = 0; k < ca.num_joints(); ++k) {
      q[k] = ca.rows[k].type == JointType::kPrismatic ? 200.0 * u(rng)
                                                      : M_PI * u(rng);
    }
    const Eigen::Matrix4d ta = BaseFromTipAt(ca, q), tb = BaseFromTipAt(cb, q);
    worst = std::max(
        worst,
        (ta.block<3, 1>(0, 3) - tb.block<3, 1>(0, 3)).cwiseAbs().maxCoeff());
    // Orientation too (unitless), scaled to mm at 1 m lever.
    worst =
        std::max(worst, 1000.0 * (ta.block<3, 3>(0, 0) - tb.block<3, 3>(0, 0))
                                     .cwiseAbs()
                                     .maxCoeff());
  }
  return worst;
}

Robot RoundTrip(const Robot& robot, UrdfExport* exported = nullptr) {
  const UrdfExport e = ExportUrdf(robot);
  if (exported) *exported = e;
  return ParseUrdfChain(e.xml, robot.name + ".urdf");
}

// Every geometry field moved by up to 2 mm / 2 deg, as a calibration would,
// plus Hayati beta on the rows that have parallel axes.
Robot Perturbed(Robot r, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-2.0, 2.0);
  auto move = [&](RobotRow& row) {
    row.theta_deg += u(rng);
    row.d_mm += u(rng);
    row.a_mm += u(rng);
    row.alpha_deg += u(rng);
    row.beta_deg += 0.3 * u(rng);
  };
  for (RobotRow& row : r.joints) move(row);
  move(r.tool);
  return r;
}

void ExpectCheckUrdfAccepts(const std::string& xml, const std::string& tag) {
  if (std::system("command -v check_urdf >/dev/null 2>&1") != 0) {
    GTEST_SKIP() << "check_urdf (liburdfdom-tools) not installed";
  }
  const std::string path = testing::MakeTempDir(tag) + "/robot.urdf";
  std::ofstream(path) << xml;
  EXPECT_EQ(std::system(("check_urdf " + path + " >/dev/null").c_str()), 0)
      << xml;
}

TEST(UrdfExportTest, Bh7DhWithPrismaticJointRoundTripsExactly) {
  const Robot bh7 = Bundled("bh7.yaml");
  ASSERT_EQ(bh7.joints[0].type, JointType::kPrismatic);
  UrdfExport e;
  const Robot back = RoundTrip(bh7, &e);
  EXPECT_LT(MaxTipDifference(bh7, back), 1e-9);
  EXPECT_TRUE(e.not_exported.empty());
  EXPECT_EQ(back.joints[0].type, JointType::kPrismatic);
  EXPECT_THAT(e.xml, HasSubstr("type=\"prismatic\""));
  ExpectCheckUrdfAccepts(e.xml, "bh7_urdf");
}

TEST(UrdfExportTest, Ur10AndPerturbedCalibratedRobotsRoundTripExactly) {
  for (const std::string name : {"ur10.yaml", "bh7.yaml"}) {
    const Robot nominal = Bundled(name);
    EXPECT_LT(MaxTipDifference(nominal, RoundTrip(nominal)), 1e-9) << name;
    for (uint64_t seed = 1; seed <= 5; ++seed) {
      const Robot cal = Perturbed(nominal, seed);
      EXPECT_GT(MaxTipDifference(nominal, cal), 0.1);  // the test can fail
      EXPECT_LT(MaxTipDifference(cal, RoundTrip(cal)), 1e-9)
          << name << " seed " << seed;
    }
  }
  Robot mdh = Perturbed(Bundled("ur10.yaml"), 9);
  mdh.convention = Convention::kMdh;
  EXPECT_LT(MaxTipDifference(mdh, RoundTrip(mdh)), 1e-9);
}

TEST(UrdfExportTest, ExtensionsAreListedNotExported) {
  Robot r = Bundled("bh7.yaml");
  r.extensions.push_back({"backlash", "j3", {{"width", 0.151}}});
  r.extensions.push_back({"drift", "", {{"vx", 0.1}, {"vy", 0}, {"vz", 0}}});
  const UrdfExport e = ExportUrdf(r);
  ASSERT_EQ(e.not_exported.size(), 2u);
  EXPECT_THAT(e.not_exported[0], HasSubstr("backlash j3"));
  EXPECT_THAT(e.xml, HasSubstr("NOT EXPORTED"));
  EXPECT_THAT(e.xml, HasSubstr("width=0.151"));
  // Geometry is still exact (extensions act on readings, not on FK).
  Robot plain = r;
  plain.extensions.clear();
  EXPECT_LT(MaxTipDifference(plain, ParseUrdfChain(e.xml, "x.urdf")), 1e-9);
}

TEST(UrdfExportTest, DhConversionBothWays) {
  for (const std::string name : {"ur10.yaml", "bh7.yaml"}) {
    const Robot cal = Perturbed(Bundled(name), 3);
    const Robot urdf = RoundTrip(cal);
    ASSERT_EQ(urdf.convention, Convention::kUrdf);
    const Robot dh = ConvertToDh(urdf);
    EXPECT_EQ(dh.convention, Convention::kDh);
    EXPECT_EQ(dh.JointNames(), cal.JointNames());
    EXPECT_LT(MaxTipDifference(cal, dh), 1e-9) << name;
  }
  // A URDF whose first joint turns about the base x axis has no standard DH
  // form in this base frame: a clear error, not a wrong robot.
  Robot tilted = Bundled("ur10.yaml");
  tilted.joints[0].alpha_deg = 0;  // irrelevant; tilt via a URDF origin:
  Robot urdf = RoundTrip(tilted);
  urdf.joints[0].rpy_deg = Eigen::Vector3d(0, 90, 0);
  try {
    ConvertToDh(urdf);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("base z axis"));
  }
}

// Consecutive axes 1e-7 rad from parallel (the UR10's shoulder, elbow and
// wrist-1 axes after a calibration that tilts them a little): the common
// normal would sit ~1e10 mm away and the conversion lose precision, so the
// row takes Hayati's beta. The DH model moves the tip as the URDF does.
TEST(UrdfExportTest, DhConversionOfNearlyParallelAxesUsesBeta) {
  for (const double tilt_deg : {1e-5, 1e-2, 0.0}) {
    Robot cal = Bundled("ur10.yaml");
    cal.joints[1].beta_deg = tilt_deg;
    cal.joints[2].beta_deg = -0.5 * tilt_deg;
    const Robot dh = ConvertToDh(RoundTrip(cal));
    EXPECT_LT(MaxTipDifference(cal, dh), 1e-9) << tilt_deg;
    for (const RobotRow& row : dh.joints) {
      EXPECT_LT(std::abs(row.d_mm), 1e4) << row.name << " " << tilt_deg;
    }
  }
}

// Centres of mass in the base frame at random poses (mm), one per row with
// a mass.
std::vector<Eigen::Vector3d> MassCentresInBase(const Robot& robot,
                                               const std::vector<double>& q) {
  const Chain chain = Chain::FromRobot(robot);
  std::vector<Eigen::Vector3d> out;
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  for (int k = 0; k < chain.num_joints(); ++k) {
    m = m * RowTransform<double>(chain.convention, chain.rows[k],
                                 chain.rows[k].p.data(), q[k]);
    if (robot.joints[k].HasMass()) {
      out.push_back((m * robot.joints[k].com_mm.homogeneous()).head<3>());
    }
  }
  return out;
}

// URDF -> DH keeps the links' masses where they are: the centre of mass of
// every link, in the base frame, is the same point for both models.
TEST(UrdfExportTest, DhConversionMovesCentresOfMassIntoTheDhFrames) {
  const Robot urdf =
      ReadUrdfChain(testing::SourceDir() + "/data/robots/industrial7.urdf");
  const Robot dh = ConvertToDh(urdf);
  ASSERT_EQ(MassCentresInBase(urdf, std::vector<double>(7, 0.0)).size(), 7u);
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-M_PI, M_PI);
  double worst = 0.0, moved = 0.0;
  for (int trial = 0; trial < 50; ++trial) {
    std::vector<double> q(7);
    for (double& v : q) v = u(rng);
    const auto a = MassCentresInBase(urdf, q), b = MassCentresInBase(dh, q);
    ASSERT_EQ(a.size(), b.size());
    for (size_t k = 0; k < a.size(); ++k) {
      worst = std::max(worst, (a[k] - b[k]).norm());
      moved =
          std::max(moved, (urdf.joints[k].com_mm - dh.joints[k].com_mm).norm());
      EXPECT_DOUBLE_EQ(urdf.joints[k].mass_kg, dh.joints[k].mass_kg);
    }
  }
  EXPECT_LT(worst, 1e-9);
  EXPECT_GT(moved, 1.0);  // the frames differ: copying com would be wrong
}

// URDF in -> calibrate (real MUKCa socket data, known 50 mm distance) ->
// URDF out: the exported file's FK equals the calibrated model's.
TEST(UrdfExportTest, PandaUrdfCalibratedAndExported) {
  KINCAL_REQUIRE_SHARED_DATA("mukca/urdf/panda.urdf");
  KINCAL_REQUIRE_SHARED_DATA("mukca/data/panda_6/front");
  const std::string mukca = testing::SharedDataDir() + "/mukca/";
  const Robot panda = ReadRobot(mukca + "urdf/panda.urdf", "", "ball_link");
  const Observations obs = ReadMukcaDir(mukca + "data/panda_6/front");
  CalibrateOptions opt;
  opt.holdout_fraction = 0.0;
  opt.distances.push_back({"hole_0", "hole_1", 50.0});
  const CalibrateResult cal = Calibrate(panda, obs, opt);
  ASSERT_EQ(cal.calibrated.convention, Convention::kUrdf);
  EXPECT_GT(MaxTipDifference(panda, cal.calibrated), 1e-3);  // it moved
  UrdfExport e;
  const Robot back = RoundTrip(cal.calibrated, &e);
  EXPECT_LT(MaxTipDifference(cal.calibrated, back), 1e-9);
  ExpectCheckUrdfAccepts(e.xml, "panda_urdf");
  // And the Panda in standard DH. The nominal joint 1 turns about the base z
  // axis, so DH holds it exactly; the calibration may tilt joint 1 against
  // the base (the sockets absorb the base frame), and then standard DH, which
  // has no base row, must refuse with a clear message rather than drop it.
  EXPECT_LT(MaxTipDifference(panda, ConvertToDh(panda)), 1e-9);
  try {
    EXPECT_LT(MaxTipDifference(cal.calibrated, ConvertToDh(cal.calibrated)),
              1e-9);
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("base z axis"));
  }
}

}  // namespace
}  // namespace kincal
