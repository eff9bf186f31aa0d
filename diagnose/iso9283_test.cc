#include "diagnose/iso9283.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <random>

#include "calib/chain.h"
#include "data/atomic_file.h"
#include "data/error.h"
#include "tests/testing/iso9283_cycles.h"
#include "tests/testing/paths.h"

namespace kincal {
namespace {

Robot Load(const std::string& name) {
  return ReadRobotYaml(testing::SourceDir() + "/data/robots/" + name);
}

// ---------------------------------------------------------------------------
// The formulas by hand on four attained positions typed in.

TEST(Iso9283Test, HandComputationOfOnePose) {
  // Commanded c = (500, -100, 300). Attained positions: the barycentre
  // (500.2, -100.1, 300.2) plus the deviations (0.03, 0.04, 0),
  // (-0.03, -0.04, 0), (0, 0, 0.01), (0, 0, -0.01), which sum to zero.
  const Eigen::Vector3d c(500.0, -100.0, 300.0);
  const std::vector<Eigen::Vector3d> x = {{500.23, -100.06, 300.20},
                                          {500.17, -100.14, 300.20},
                                          {500.20, -100.10, 300.21},
                                          {500.20, -100.10, 300.19}};
  const Iso9283Pose p = PoseCharacteristics(c, x);
  EXPECT_EQ(p.n, 4);
  // x̄ = (500.23 + 500.17 + 500.20 + 500.20) / 4 = 500.20, ȳ = -100.10,
  // z̄ = 300.20.
  EXPECT_NEAR(p.barycentre_mm.x(), 500.20, 1e-12);
  EXPECT_NEAR(p.barycentre_mm.y(), -100.10, 1e-12);
  EXPECT_NEAR(p.barycentre_mm.z(), 300.20, 1e-12);
  // AP_x = 0.2, AP_y = -0.1, AP_z = 0.2; AP_P = sqrt(0.04 + 0.01 + 0.04) =
  // 0.3.
  EXPECT_NEAR(p.ap_xyz_mm.x(), 0.2, 1e-9);
  EXPECT_NEAR(p.ap_xyz_mm.y(), -0.1, 1e-9);
  EXPECT_NEAR(p.ap_xyz_mm.z(), 0.2, 1e-9);
  EXPECT_NEAR(p.ap_mm, 0.3, 1e-9);
  // l = 0.05, 0.05, 0.01, 0.01; l̄ = 0.12 / 4 = 0.03;
  // S_l = sqrt((0.02^2 + 0.02^2 + 0.02^2 + 0.02^2) / 3) = sqrt(0.0016 / 3)
  //     = 0.0230940108; RP_l = 0.03 + 3 * 0.0230940108 = 0.0992820323.
  EXPECT_NEAR(p.l_mean_mm, 0.03, 1e-9);
  EXPECT_NEAR(p.s_l_mm, std::sqrt(0.0016 / 3.0), 1e-9);
  EXPECT_NEAR(p.s_l_mm, 0.0230940108, 1e-9);
  EXPECT_NEAR(p.rp_mm, 0.0992820323, 1e-9);
}

// ---------------------------------------------------------------------------
// Bad input: exit 2 material (InputError with the line).

std::string Csv(const std::string& body) {
  return "pose,j1,j2,j3,j4,j5,x,y,z,fixed_point\n" + body;
}

Observations Parse(const std::string& text) {
  return ParseObservationsCsv(text, "iso.csv", {"j1", "j2", "j3", "j4", "j5"});
}

TEST(Iso9283Test, RefusesDataWithoutLabels) {
  const Observations obs =
      Parse(Csv("a,10,20,30,40,50,1,2,3,\n"
                "b,20,20,30,40,50,1,2,3,\n"));
  try {
    ComputeIso9283(Load("bh7.yaml"), obs);
    FAIL() << "no labels accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("no row has a fixed_point label"),
              std::string::npos)
        << e.what();
  }
}

TEST(Iso9283Test, RefusesALabelledRowWithoutPointAndAPoseVisitedOnce) {
  const Robot bh7 = Load("bh7.yaml");
  try {
    ComputeIso9283(bh7, Parse(Csv("a,10,20,30,40,50,1,2,3,P1\n"
                                  "b,20,20,30,40,50,,,,P1\n")));
    FAIL() << "a labelled row without x,y,z accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("iso.csv:3"), std::string::npos)
        << e.what();
  }
  try {
    ComputeIso9283(bh7, Parse(Csv("a,10,20,30,40,50,1,2,3,P1\n"
                                  "b,20,20,30,40,50,1,2,3,P2\n"
                                  "c,10,20,30,40,50,1,2,3,P1\n")));
    FAIL() << "n = 1 accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("iso.csv:3"), std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("'P2' is visited once"),
              std::string::npos)
        << e.what();
  }
}

// ---------------------------------------------------------------------------
// Simulated tests (tests/testing/iso9283_cycles.h): a true robot (the
// nominal chain with a hidden backlash on one joint) visits P1..P5; the
// model is the nominal robot.

using testing::IsoNominalTip;
using testing::IsoSimulation;
using testing::SimulateIsoCycles;

// The standard's cycle and the forward order P1..P5: in both every pose is
// approached from the same predecessor in every cycle.
const std::vector<std::vector<int>> kUnidirectionalOrders = {
    testing::IsoStandardOrder(), {0, 1, 2, 3, 4}};

Iso9283Options TrueFrame(const IsoSimulation& sim) {
  Iso9283Options o;
  o.meas_from_base = sim.meas_from_base;
  return o;
}

// Unidirectional cycles: the backlash shifts each pose by the same vector in
// every cycle, so RP (distances from the barycentre) is exactly that of the
// noise alone, while AP moves by the shift. With the same noise draws the
// RPs agree to rounding.
void ExpectBacklashLeavesRpAlone(const Robot& robot, IsoSimulation sim,
                                 double backlash_deg) {
  for (const std::vector<int>& order : kUnidirectionalOrders) {
    sim.order = order;
    sim.backlash_deg = 0.0;
    const Observations clean = SimulateIsoCycles(robot, sim);
    sim.backlash_deg = backlash_deg;
    const Observations worn = SimulateIsoCycles(robot, sim);
    const Iso9283Result a = ComputeIso9283(robot, clean, TrueFrame(sim));
    const Iso9283Result b = ComputeIso9283(robot, worn, TrueFrame(sim));
    ASSERT_EQ(a.poses.size(), 5u);
    ASSERT_EQ(b.poses.size(), 5u);
    EXPECT_EQ(a.poses[0].label, "P1");
    for (size_t k = 0; k < 5; ++k) {
      EXPECT_EQ(b.poses[k].n, sim.cycles);
      EXPECT_NEAR(b.poses[k].rp_mm, a.poses[k].rp_mm, 1e-9) << k;
      // Noise alone: l̄ + 3 S_l of a 3-D Gaussian is about 3.6 sigma.
      EXPECT_GT(a.poses[k].rp_mm, 2.5 * sim.noise_mm);
      EXPECT_LT(a.poses[k].rp_mm, 5.0 * sim.noise_mm);
      // AP moves by the backlash shift of this pose: joint reading minus
      // b/2 times the approach sign s (chain.h ModelJointValue).
      const int pose = std::stoi(b.poses[k].label.substr(1)) - 1;
      const size_t at =
          std::find(order.begin(), order.end(), pose) - order.begin();
      const int before = order[(at + order.size() - 1) % order.size()];
      const double s = sim.poses[pose][sim.backlash_joint] >
                               sim.poses[before][sim.backlash_joint]
                           ? 1.0
                           : -1.0;
      const Eigen::Vector3d shift =
          IsoNominalTip(robot, sim.poses[pose], sim.backlash_joint,
                        -0.5 * s * backlash_deg) -
          IsoNominalTip(robot, sim.poses[pose], sim.backlash_joint, 0.0);
      EXPECT_GT(shift.norm(), 0.05);
      EXPECT_NEAR((b.poses[k].ap_xyz_mm - a.poses[k].ap_xyz_mm - shift).norm(),
                  0.0, 1e-9)
          << k;
    }
  }
}

TEST(Iso9283Test, Bh7BacklashUnderTheStandardCycleLeavesRpUnchanged) {
  ExpectBacklashLeavesRpAlone(Load("bh7.yaml"), testing::Bh7IsoSimulation(),
                              0.05);
}

TEST(Iso9283Test, Ur10BacklashUnderTheStandardCycleLeavesRpUnchanged) {
  ExpectBacklashLeavesRpAlone(Load("ur10.yaml"), testing::Ur10IsoSimulation(),
                              0.02);
}

// Approach flipping every cycle: the attained positions alternate between
// two points d = tip(q_k + b/2) - tip(q_k - b/2) apart. Without noise the
// barycentre is their midpoint, every l_i = |d| / 2, S_l = 0, so RP_l =
// |d| / 2: the tip displacement of a b/2 joint error. With noise sigma per
// axis (sigma << |d|), l_i = |d|/2 + the noise along d: l̄ = |d|/2, S_l =
// sigma, RP_l = |d|/2 + 3 sigma.
void ExpectFlippingApproachRaisesRp(const Robot& robot, IsoSimulation sim,
                                    double backlash_deg) {
  sim.order = kUnidirectionalOrders[0];
  sim.via_delta_deg = 5.0;
  sim.backlash_deg = backlash_deg;
  std::vector<double> half_d;
  for (const auto& q : sim.poses) {
    half_d.push_back(
        0.5 * (IsoNominalTip(robot, q, sim.backlash_joint, 0.5 * backlash_deg) -
               IsoNominalTip(robot, q, sim.backlash_joint, -0.5 * backlash_deg))
                  .norm());
  }
  IsoSimulation exact = sim;
  exact.noise_mm = 0.0;
  const Iso9283Result r0 =
      ComputeIso9283(robot, SimulateIsoCycles(robot, exact), TrueFrame(exact));
  const Iso9283Result r = ComputeIso9283(robot, SimulateIsoCycles(robot, sim));
  sim.backlash_deg = 0.0;
  const Iso9283Result clean =
      ComputeIso9283(robot, SimulateIsoCycles(robot, sim));
  ASSERT_EQ(r.poses.size(), 5u);
  for (size_t k = 0; k < 5; ++k) {
    const int pose = std::stoi(r.poses[k].label.substr(1)) - 1;
    EXPECT_GT(half_d[pose], 0.1) << k;
    EXPECT_NEAR(r0.poses[k].rp_mm, half_d[pose], 1e-9) << k;
    EXPECT_NEAR(r0.poses[k].s_l_mm, 0.0, 1e-9) << k;
    EXPECT_NEAR(r.poses[k].rp_mm, half_d[pose] + 3 * sim.noise_mm,
                1.5 * sim.noise_mm)
        << k;
    EXPECT_LT(clean.poses[k].rp_mm, 5.0 * sim.noise_mm) << k;
  }
}

TEST(Iso9283Test, Bh7BacklashWithFlippingApproachRaisesRpByHalfTheShift) {
  ExpectFlippingApproachRaisesRp(Load("bh7.yaml"), testing::Bh7IsoSimulation(),
                                 0.1);
}

TEST(Iso9283Test, Ur10BacklashWithFlippingApproachRaisesRpByHalfTheShift) {
  ExpectFlippingApproachRaisesRp(Load("ur10.yaml"),
                                 testing::Ur10IsoSimulation(), 0.03);
}

// The frame registered on the tested poses minimises sum_i |T tip_i -
// p_i|^2 over rigid T, so it can only lower sum_j n_j AP_j^2 against the
// true frame; RP does not depend on the frame.
TEST(Iso9283Test, RegistrationOnThePosesAbsorbsPartOfAp) {
  const Robot bh7 = Load("bh7.yaml");
  IsoSimulation sim = testing::Bh7IsoSimulation();
  sim.order = kUnidirectionalOrders[0];
  sim.backlash_deg = 0.1;
  const Observations obs = SimulateIsoCycles(bh7, sim);
  const Iso9283Result own = ComputeIso9283(bh7, obs);
  const Iso9283Result truth = ComputeIso9283(bh7, obs, TrueFrame(sim));
  EXPECT_TRUE(own.frame_registered_on_poses);
  EXPECT_FALSE(truth.frame_registered_on_poses);
  EXPECT_EQ(own.registration_rows, 5 * sim.cycles);
  double own_sq = 0, truth_sq = 0;
  for (size_t k = 0; k < 5; ++k) {
    own_sq += own.poses[k].ap_mm * own.poses[k].ap_mm;
    truth_sq += truth.poses[k].ap_mm * truth.poses[k].ap_mm;
    EXPECT_NEAR(own.poses[k].rp_mm, truth.poses[k].rp_mm, 1e-9);
    EXPECT_NEAR(own.poses[k].commanded_spread_mm, 0.0, 1e-12);
  }
  EXPECT_LT(own_sq, truth_sq);
  EXPECT_GT(truth.ap_max_mm, 0.1);
  // The registration residual: AP and noise of every row.
  EXPECT_GT(own.registration_rms_mm, 0.0);
  EXPECT_LT(own.registration_rms_mm, std::sqrt(truth_sq / 5) + 0.05);
}

// --frame-from: the frame registered on other poses measured in the same
// set-up (here 40 unlabelled random poses of the same true robot) gives the
// true frame's AP within the error that backlash and noise leave in it.
TEST(Iso9283Test, FrameFromOtherDataRecoversTheAp) {
  const Robot bh7 = Load("bh7.yaml");
  IsoSimulation sim = testing::Bh7IsoSimulation();
  sim.order = kUnidirectionalOrders[0];
  sim.backlash_deg = 0.1;
  const Observations obs = SimulateIsoCycles(bh7, sim);
  IsoSimulation other = sim;
  other.poses.clear();
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int i = 0; i < 40; ++i) {
    other.poses.push_back({75 + 60 * u(rng), 60 * u(rng), 70 + 60 * u(rng),
                           150 + 30 * u(rng), -40 + 40 * u(rng)});
  }
  other.order.clear();
  for (int i = 0; i < 40; ++i) other.order.push_back(i);
  other.cycles = 1;
  other.seed = 12;
  const Observations frame_obs = SimulateIsoCycles(bh7, other);
  const Iso9283Options given = RegisterMeasuringFrame(bh7, frame_obs);
  EXPECT_EQ(given.given_frame_rows, 40);
  EXPECT_GT(given.given_frame_rms_mm, 0.0);
  const Iso9283Result r = ComputeIso9283(bh7, obs, given);
  const Iso9283Result truth = ComputeIso9283(bh7, obs, TrueFrame(sim));
  EXPECT_FALSE(r.frame_registered_on_poses);
  EXPECT_EQ(r.registration_rows, 40);
  for (size_t k = 0; k < 5; ++k) {
    EXPECT_NEAR(r.poses[k].ap_mm, truth.poses[k].ap_mm, 0.1) << k;
  }
}

TEST(Iso9283Test, ToleranceGivesPassFailPerPoseAndOverall) {
  const Robot bh7 = Load("bh7.yaml");
  IsoSimulation sim = testing::Bh7IsoSimulation();
  sim.order = kUnidirectionalOrders[0];
  const Observations obs = SimulateIsoCycles(bh7, sim);
  Iso9283Options o = TrueFrame(sim);
  const Iso9283Result none = ComputeIso9283(bh7, obs, o);
  EXPECT_FALSE(none.tolerance_given);
  EXPECT_TRUE(none.pass);
  o.rp_tolerance_mm = 1.0;
  o.ap_tolerance_mm = 1.0;
  const Iso9283Result loose = ComputeIso9283(bh7, obs, o);
  EXPECT_TRUE(loose.tolerance_given);
  EXPECT_TRUE(loose.pass);
  // RP between the smallest and the largest pose's: some pass, some fail.
  double lo = 1e9, hi = 0;
  for (const auto& p : none.poses) {
    lo = std::min(lo, p.rp_mm);
    hi = std::max(hi, p.rp_mm);
  }
  o.rp_tolerance_mm = 0.5 * (lo + hi);
  const Iso9283Result tight = ComputeIso9283(bh7, obs, o);
  EXPECT_FALSE(tight.pass);
  int passed = 0;
  for (const auto& p : tight.poses) {
    EXPECT_EQ(p.pass, p.rp_mm <= o.rp_tolerance_mm);
    passed += p.pass;
  }
  EXPECT_GT(passed, 0);
  EXPECT_LT(passed, 5);
}

}  // namespace
}  // namespace kincal

namespace kincal {
namespace {

// The demo session of docs/ISO9283.md (data/sessions/iso9283_demo): a BH-7
// whose true geometry differs from the nominal (j2.theta +0.03 deg, j3.a
// +0.4 mm) with a 0.05 deg backlash in j2, measured with 0.02 mm noise:
//   cycles.csv            the standard's cycle, 30 cycles
//   multidirectional.csv  the same poses, each approached alternately from
//                         both sides of j2 (via rows, unlabelled)
//   frame.csv             40 other poses (unlabelled), for --frame-from
// The checked-in files must be what this simulation writes; with
// KINCAL_WRITE_ISO9283_DEMO=DIR set, the test writes them into DIR instead.
std::vector<std::pair<std::string, Observations>> DemoSession(
    const Robot& bh7) {
  IsoSimulation sim = testing::Bh7IsoSimulation();
  sim.backlash_deg = 0.05;
  sim.noise_mm = 0.02;
  sim.geometry_errors = {{1, 0, 0.03 * M_PI / 180.0}, {2, 2, 0.4}};
  IsoSimulation multi = sim;
  multi.via_delta_deg = 5.0;
  multi.seed = 8;
  IsoSimulation other = sim;
  other.poses.clear();
  other.order.clear();
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int i = 0; i < 40; ++i) {
    other.poses.push_back({75 + 60 * u(rng), 60 * u(rng), 70 + 60 * u(rng),
                           150 + 30 * u(rng), -40 + 40 * u(rng)});
    other.order.push_back(i);
  }
  other.cycles = 1;
  other.seed = 10;
  Observations frame = SimulateIsoCycles(bh7, other);
  Observations frame_measured;
  frame_measured.source = frame.source;
  frame_measured.joint_names = frame.joint_names;
  for (Observation o : frame.rows) {
    if (!o.has_point) continue;  // the warm-up pass is not needed here
    o.fixed_point.clear();
    frame_measured.rows.push_back(o);
  }
  return {{"cycles.csv", SimulateIsoCycles(bh7, sim)},
          {"multidirectional.csv", SimulateIsoCycles(bh7, multi)},
          {"frame.csv", frame_measured}};
}

TEST(Iso9283Test, DemoSessionIsTheSimulation) {
  const Robot bh7 = Load("bh7.yaml");
  const std::string dir = testing::SourceDir() + "/data/sessions/iso9283_demo";
  const char* write = std::getenv("KINCAL_WRITE_ISO9283_DEMO");
  for (const auto& [name, obs] : DemoSession(bh7)) {
    if (write != nullptr) {
      WriteFileAtomic(
          std::string(write) + "/" + name,
          FormatObservationsCsv(
              obs, {"simulated ISO 9283 demo (diagnose/iso9283_test.cc "
                    "DemoSession): BH-7, true j2.theta +0.03 deg, j3.a +0.4 "
                    "mm, backlash j2 0.05 deg, noise 0.02 mm per axis"}));
      continue;
    }
    const Observations file =
        ReadObservationsCsv(dir + "/" + name, obs.joint_names);
    ASSERT_EQ(file.rows.size(), obs.rows.size()) << name;
    for (size_t i = 0; i < obs.rows.size(); ++i) {
      EXPECT_EQ(file.rows[i].fixed_point, obs.rows[i].fixed_point);
      EXPECT_EQ(file.rows[i].has_point, obs.rows[i].has_point);
      EXPECT_LT((file.rows[i].p_in_meas - obs.rows[i].p_in_meas).norm(), 1e-9);
    }
  }
}

}  // namespace
}  // namespace kincal
