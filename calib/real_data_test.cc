// Real data (../shared/data, skipped when absent): the UR10 laser-tracker
// series of ipa-robot-accuracy and the MUKCa Panda socket recordings.
// Bounds are what was measured (docs/REAL_DATA.md) with a margin, so a
// regression in the calibration shows up here.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <map>
#include <random>
#include <set>

#include "calib/calibrate.h"
#include "calib/evaluate.h"
#include "calib/paper_method.h"
#include "data/import_ipa.h"
#include "data/import_mukca.h"
#include "data/robot.h"
#include "data/urdf.h"
#include "tests/testing/paths.h"

namespace kincal {
namespace {

std::string Ipa(const std::string& file) {
  return testing::SharedDataDir() + "/ipa-robot-accuracy/" + file;
}

Robot Ur10() {
  return ReadRobotYaml(testing::SourceDir() + "/data/robots/ur10.yaml");
}

Observations EveryNth(const Observations& obs, int every) {
  std::vector<int> keep;
  for (int i = 0; i < static_cast<int>(obs.rows.size()); i += every)
    keep.push_back(i);
  return Subset(obs, keep);
}

// data/robots/ur10.yaml against the data set's own commanded positions:
// the "Goal" TCP of every pose of series C (109 mm out of the flange, the
// data set's Trafo_TM_F_init.txt) is where the nominal chain with that tool
// puts it, in the ROS `base` frame, which is the DH base turned 180 deg
// about z (ur_description's base vs base_link).
TEST(RealDataTest, Ur10NominalModelReproducesTheCommandedGoals) {
  KINCAL_REQUIRE_SHARED_DATA("ipa-robot-accuracy");
  const IpaSeries c =
      ReadIpaSeries(Ipa("Series_C/measurements_random_poses.csv"));
  Robot planner = Ur10();
  planner.tool.d_mm = 109.0;  // the commanded TCP, not the measured point
  const Chain chain = Chain::FromRobot(planner);
  double worst = 0.0;
  for (size_t i = 0; i < c.observations.rows.size(); ++i) {
    PoseInput in;
    for (double q : c.observations.rows[i].q) in.q.push_back(q * M_PI / 180);
    in.s.assign(6, 0.0);
    in.tau.assign(6, 0.0);
    const Eigen::Vector3d tip = TipInBase(chain, in);
    const Eigen::Vector3d in_ros_base(-tip.x(), -tip.y(), tip.z());
    worst = std::max(worst, (in_ros_base - c.goal_mm[i]).norm());
  }
  // Goals and joint angles have 6 significant digits (0.1 mm at 1 m), and
  // the controller solved them with its own factory kinematics: agreement
  // to a fraction of a millimetre, with the 109 mm tool; a wrong tool
  // length or joint sign would be off by centimetres.
  EXPECT_LT(worst, 1.0);
}

// Where the tracker's measured point sits on the flange, from the tracker's
// own 6D poses (tracker_from_tmac = IpaRotation, position = measurement_x/
// y/z) and the nominal chain alone, no calibration: solve
// p_i + R_i w = R_frame flange_i + t_frame for w (the flange origin in the
// T-Mac frame) and t_frame, with R_frame from the rotations. The result,
// (-0.18, 0.32, 92.79) mm on series C and (0.04, 0.22, 93.03) mm on B, is
// the 93.0 mm tool row of ur10.yaml; the data set's initial transform says
// 109 mm (that is the commanded TCP, see above).
Eigen::Vector3d MeasuredPointInFlange(const IpaSeries& s, const Robot& robot) {
  // Flange poses of the nominal chain: tool rows at the flange origin and
  // 1 mm along its x and z axes.
  auto chain_with_tool = [&](double d, double a) {
    Robot r = robot;
    r.tool = RobotRow();
    r.tool.name = "tool";
    r.tool.type = JointType::kFixed;
    r.tool.d_mm = d;
    r.tool.a_mm = a;
    return Chain::FromRobot(r);
  };
  const Chain at_origin = chain_with_tool(0, 0),
              along_x = chain_with_tool(0, 1), along_z = chain_with_tool(1, 0);
  const int n = static_cast<int>(s.observations.rows.size());
  std::vector<Eigen::Matrix3d> flange_rot(n), meas_rot(n);
  std::vector<Eigen::Vector3d> flange_pos(n);
  for (int i = 0; i < n; ++i) {
    PoseInput in;
    for (double q : s.observations.rows[i].q) in.q.push_back(q * M_PI / 180);
    in.s.assign(6, 0.0);
    in.tau.assign(6, 0.0);
    flange_pos[i] = TipInBase(at_origin, in);
    const Eigen::Vector3d x = TipInBase(along_x, in) - flange_pos[i];
    const Eigen::Vector3d z = TipInBase(along_z, in) - flange_pos[i];
    flange_rot[i].col(0) = x;
    flange_rot[i].col(1) = z.cross(x);
    flange_rot[i].col(2) = z;
    meas_rot[i] = IpaRotation(s.rotation_deg[i]);
  }
  // R_meas_i = R_frame R_flange_i R_tmac: alternate the two averages.
  auto project = [](const Eigen::Matrix3d& m) {
    const Eigen::JacobiSVD<Eigen::Matrix3d> svd(
        m, Eigen::ComputeFullU | Eigen::ComputeFullV);
    return Eigen::Matrix3d(svd.matrixU() * svd.matrixV().transpose());
  };
  // Start from the frame rotation of the positions (flange vs measured).
  Eigen::Matrix3Xd from(3, n), to(3, n);
  for (int i = 0; i < n; ++i) {
    from.col(i) = flange_pos[i];
    to.col(i) = s.observations.rows[i].p_in_meas;
  }
  Eigen::Matrix3d frame = Eigen::umeyama(from, to, false).block<3, 3>(0, 0);
  Eigen::Matrix3d tmac;
  for (int it = 0; it < 20; ++it) {
    Eigen::Matrix3d sum = Eigen::Matrix3d::Zero();
    for (int i = 0; i < n; ++i) {
      sum += flange_rot[i].transpose() * frame.transpose() * meas_rot[i];
    }
    tmac = project(sum);
    sum.setZero();
    for (int i = 0; i < n; ++i) {
      sum += meas_rot[i] * tmac.transpose() * flange_rot[i].transpose();
    }
    frame = project(sum);
  }
  Eigen::MatrixXd a(3 * n, 6);
  Eigen::VectorXd b(3 * n);
  for (int i = 0; i < n; ++i) {
    a.block<3, 3>(3 * i, 0) = meas_rot[i];
    a.block<3, 3>(3 * i, 3) = -Eigen::Matrix3d::Identity();
    b.segment<3>(3 * i) =
        frame * flange_pos[i] - s.observations.rows[i].p_in_meas;
  }
  const Eigen::VectorXd x = a.colPivHouseholderQr().solve(b);
  return -tmac * x.head<3>();
}

TEST(RealDataTest, Ur10MeasuredPointIsTheTMacOrigin93mmOutOfTheFlange) {
  KINCAL_REQUIRE_SHARED_DATA("ipa-robot-accuracy");
  const Robot robot = Ur10();
  for (const char* file : {"Series_C/measurements_random_poses.csv",
                           "Series_B/measurements_joint_configurations.csv"}) {
    SCOPED_TRACE(file);
    const Eigen::Vector3d p =
        MeasuredPointInFlange(ReadIpaSeries(Ipa(file)), robot);
    EXPECT_NEAR(p.z(), robot.tool.d_mm, 0.3);
    EXPECT_LT(p.head<2>().norm(), 0.5);
  }
}

// Calibrate on series C (20 % held out), then register only the frame on
// series B and on every 10th pose of series A. Measured (Release, seed 1):
// C held-out 0.501 mm, B 0.922 mm, A 0.858 mm with the 23 identifiable DH
// parameters; with gravity compliance of the shoulder and elbow joints
// freed as well: C 0.496, B 0.564, A 0.62 mm. Nominal (93 mm tool) on B:
// 1.085 mm. Plain DH misses the 0.80 mm on B because B's poses lie
// outside C's joint ranges (docs/REAL_DATA.md): shoulder_lift_joint.a,
// shoulder_lift_joint.theta and elbow_joint.theta absorb gravity sag on C.
TEST(RealDataTest, Ur10CalibrateOnSeriesCPredictsSeriesAAndB) {
  KINCAL_REQUIRE_SHARED_DATA("ipa-robot-accuracy");
  const Robot nominal = Ur10();
  const Observations c =
      ReadIpaSeries(Ipa("Series_C/measurements_random_poses.csv")).observations;
  const Observations b =
      ReadIpaSeries(Ipa("Series_B/measurements_joint_configurations.csv"))
          .observations;
  const Observations a = EveryNth(
      ReadIpaSeries(Ipa("Series_A/measurements_grid.csv")).observations, 10);

  const EvaluateResult nominal_b = Evaluate(nominal, b);
  EXPECT_LT(nominal_b.stats.rms_mm, 1.15);  // 2.92 mm with a 109 mm tool

  const CalibrateResult dh = Calibrate(nominal, c, {});
  EXPECT_EQ(dh.heldout.n, 555);
  EXPECT_LT(dh.heldout.rms_mm, 0.52);
  EXPECT_LT(dh.train.rms_mm, 0.50);
  EXPECT_EQ(dh.identifiability.identifiable.size(), 6u + 17u);
  // The nominal tool row is right: calibration moves d6 + tool by < 0.5 mm.
  const double tool_mm =
      dh.calibrated.joints.back().d_mm + dh.calibrated.tool.d_mm;
  EXPECT_NEAR(tool_mm, 92.2 + nominal.tool.d_mm, 0.5);
  EXPECT_LT(Evaluate(dh.calibrated, b).stats.rms_mm, 0.95);
  EXPECT_LT(Evaluate(dh.calibrated, a).stats.rms_mm, 0.90);

  CalibrateOptions with_compliance;
  with_compliance.extra_params = {"shoulder_lift_joint.compliance",
                                  "elbow_joint.compliance"};
  const CalibrateResult comp = Calibrate(nominal, c, with_compliance);
  const double on_b = Evaluate(comp.calibrated, b).stats.rms_mm;
  const double on_a = Evaluate(comp.calibrated, a).stats.rms_mm;
  RecordProperty("heldout_b_mm", std::to_string(on_b));
  EXPECT_LT(comp.heldout.rms_mm, 0.52);
  EXPECT_LT(on_b, 0.60);  // the target: <= 0.80 mm
  EXPECT_LT(on_a, 0.67);
}

std::string Mukca(const std::string& path) {
  return testing::SharedDataDir() + "/mukca/" + path;
}

// RMS distance to the socket centroid per socket (hole_0, hole_1).
std::map<std::string, double> PerSocketRms(const Observations& obs,
                                           const EvaluateResult& r) {
  std::map<std::string, double> sum;
  std::map<std::string, int> n;
  for (size_t i = 0; i < r.rows.size(); ++i) {
    const std::string& label = obs.rows[r.rows[i]].fixed_point;
    sum[label] += r.errors_mm[i] * r.errors_mm[i];
    ++n[label];
  }
  for (auto& kv : sum) kv.second = std::sqrt(kv.second / n[kv.first]);
  return sum;
}

// The seed's single-point method on a real Panda (panda_6, recording
// "front", 62 poses in two sockets 50 mm apart) with the known distance as
// scale. The authors' kpis.yaml for the same recording: per-axis variances
// 5.5e-9, 9.5e-9, 1.31e-8 m^2 (hole 1) and 7.8e-9, 2.31e-8, 1.88e-8 m^2
// (hole 2), i.e. RMS 0.168 and 0.223 mm, distance error -0.0029 mm.
TEST(RealDataTest, MukcaPandaSinglePointWithKnownDistance) {
  KINCAL_REQUIRE_SHARED_DATA("mukca");
  const Robot urdf =
      ReadRobot(Mukca("calibrated_urdf/panda_6/panda.urdf"), "", "ball_link");
  const Observations front = ReadMukcaDir(Mukca("data/panda_6/front"));
  ASSERT_EQ(urdf.JointNames(), PandaJointNames());

  const EvaluateResult before = Evaluate(urdf, front);
  const auto before_socket = PerSocketRms(front, before);

  // The parameters the data determine (least-squares pass, 0.1 s), then
  // eq. (9) on them with a bounded budget (the CLI's default budget of
  // 200000 evaluations takes ~30 s here and ends at the same eps +- 1 um).
  CalibrateOptions lsq_opt;
  lsq_opt.holdout_fraction = 0.0;
  lsq_opt.distances.push_back({"hole_0", "hole_1", 50.0});
  const CalibrateResult lsq = Calibrate(urdf, front, lsq_opt);
  const Chain nominal = Chain::FromRobot(urdf);
  ModelState state;
  state.chain = nominal;
  const std::vector<Measurement> ms = MakeMeasurements(nominal, front, &state);
  PaperOptions po;
  po.bounds_center = &nominal;
  po.max_evaluations = 30000;
  for (const ParamInfo& p : lsq.identifiability.identifiable) {
    if (p.kind == ParamKind::kRow) po.free.push_back(p);
  }
  PointDistance d;
  d.a = state.PointIndex("hole_0");
  d.b = state.PointIndex("hole_1");
  d.distance_mm = 50.0;
  po.distances.push_back(d);
  EXPECT_GT(po.free.size(), 20u);
  FitPaperObjective(ms, po, &state);
  const double eps = PaperEpsilon(state, ms);
  const auto& p0 = state.points_in_base[d.a];
  const auto& p1 = state.points_in_base[d.b];
  const double distance = std::sqrt((p0[0] - p1[0]) * (p0[0] - p1[0]) +
                                    (p0[1] - p1[1]) * (p0[1] - p1[1]) +
                                    (p0[2] - p1[2]) * (p0[2] - p1[2]));
  // The exact penalty holds the known distance.
  EXPECT_LT(std::abs(distance - 50.0), 0.003);
  Robot calibrated = state.chain.ToRobot(urdf);
  // Per-socket scatter at the authors' level (0.17 / 0.22 mm) and not above
  // the model the data came with.
  const EvaluateResult after = Evaluate(calibrated, front);
  const auto socket = PerSocketRms(front, after);
  ASSERT_EQ(socket.size(), 2u);
  EXPECT_LT(socket.at("hole_0"), 0.25);
  EXPECT_LT(socket.at("hole_1"), 0.25);
  EXPECT_LE(eps, before.stats.mean_mm + 1e-3);
  EXPECT_LE(eps, lsq.epsilon.mean_mm + 0.01);
  EXPECT_LT(eps, 0.2);
  EXPECT_GT(before_socket.at("hole_0"), 0.1);  // real seating scatter
}

// Issue 7: from the NOMINAL Panda (urdf/panda.urdf, what the MUKCa authors
// start from) on panda_6 "front" with the 50 mm distance. Identifiability
// decided again at the solution (fit -> identifiability -> fit) reaches the
// authors' level: measured 0.1942 mm training, 31 parameters (2 passes: 32
// free at the start, one held at the solution), where deciding once at the
// nominal point with 5 mm / 5 deg bounds stopped at 0.649 mm. Held-out on the
// other recordings: not above the authors' calibrated model on the same poses
// (+0.01 mm tolerance for the seating scatter).
TEST(RealDataTest, MukcaPandaFromNominalModel) {
  KINCAL_REQUIRE_SHARED_DATA("mukca");
  const Robot nominal = ReadRobot(Mukca("urdf/panda.urdf"), "", "ball_link");
  const Robot authors =
      ReadRobot(Mukca("calibrated_urdf/panda_6/panda.urdf"), "", "ball_link");
  const Observations front = ReadMukcaDir(Mukca("data/panda_6/front"));
  CalibrateOptions opt;
  opt.holdout_fraction = 0.0;
  opt.distances.push_back({"hole_0", "hole_1", 50.0});
  const CalibrateResult r = Calibrate(nominal, front, opt);
  RecordProperty("train_rms_mm", std::to_string(r.train.rms_mm));
  EXPECT_LT(r.train.rms_mm, 0.20);
  EXPECT_GE(r.passes.size(), 2u);
  EXPECT_LT(std::abs(r.distance_errors_mm.at(0)), 0.003);
  for (const char* test : {"left", "right"}) {
    const Observations obs =
        ReadMukcaDir(Mukca(std::string("data/panda_6/") + test));
    const double ours = Evaluate(r.calibrated, obs).stats.rms_mm;
    const double theirs = Evaluate(authors, obs).stats.rms_mm;
    RecordProperty(std::string(test) + "_mm", std::to_string(ours));
    EXPECT_LE(ours, theirs + 0.01) << test;
  }
}

// Start values far from the truth (every joint origin moved 10 mm and 3 deg
// in a seeded random direction, the ball by 10 mm) converge to the same
// optimum as a start at the authors' answer: same training scatter, same
// predictions on another recording.
TEST(RealDataTest, MukcaPandaFarStartConvergesToTheSameOptimum) {
  KINCAL_REQUIRE_SHARED_DATA("mukca");
  const Robot answer =
      ReadRobot(Mukca("calibrated_urdf/panda_6/panda.urdf"), "", "ball_link");
  const Observations front = ReadMukcaDir(Mukca("data/panda_6/front"));
  const Observations left = ReadMukcaDir(Mukca("data/panda_6/left"));
  CalibrateOptions opt;
  opt.holdout_fraction = 0.0;
  opt.distances.push_back({"hole_0", "hole_1", 50.0});
  const CalibrateResult at_answer = Calibrate(answer, front, opt);
  std::mt19937_64 rng(7);
  std::normal_distribution<double> normal;
  auto direction = [&] {
    Eigen::Vector3d v(normal(rng), normal(rng), normal(rng));
    return Eigen::Vector3d(v.normalized());
  };
  for (int trial = 0; trial < 2; ++trial) {
    Robot far = answer;
    for (RobotRow& row : far.joints) {
      row.xyz_mm += 10.0 * direction();
      row.rpy_deg += 3.0 * direction();
    }
    far.tool.xyz_mm += 10.0 * direction();
    const CalibrateResult r = Calibrate(far, front, opt);
    EXPECT_NEAR(r.train.rms_mm, at_answer.train.rms_mm, 0.005) << trial;
    EXPECT_NEAR(Evaluate(r.calibrated, left).stats.rms_mm,
                Evaluate(at_answer.calibrated, left).stats.rms_mm, 0.01)
        << trial;
  }
}

// The socket distance of a model registered on one recording (mm): the
// distance between the fitted socket centres, as `evaluate` reports it.
double SocketDistance(const EvaluateResult& r) {
  const ModelState& s = r.state;
  const auto& a = s.points_in_base.at(s.PointIndex("hole_0"));
  const auto& b = s.points_in_base.at(s.PointIndex("hole_1"));
  return std::sqrt((a[0] - b[0]) * (a[0] - b[0]) +
                   (a[1] - b[1]) * (a[1] - b[1]) +
                   (a[2] - b[2]) * (a[2] - b[2]));
}

// Like for like with the MUKCa authors: trained on the recording their
// panda_3 model was trained on (frontcenter: their 50 mm error there is
// 0.001 mm, >= 0.02 mm on every other one), kincal from the nominal model
// predicts the other five panda_3 recordings as their model does: measured
// RMS within 0.001 mm and 50 mm error within 0.004 mm of theirs
// (scripts/mukca_as_authors.sh). Same objective, same optimum: the
// differences in the train-on-one tables come from which recording is
// trained on, not from the fit.
TEST(RealDataTest, MukcaPandaTrainedWhereTheAuthorsTrainedPredictsAsTheyDo) {
  KINCAL_REQUIRE_SHARED_DATA("mukca");
  const Robot nominal = ReadRobot(Mukca("urdf/panda.urdf"), "", "ball_link");
  const Robot authors =
      ReadRobot(Mukca("calibrated_urdf/panda_3/panda.urdf"), "", "ball_link");
  CalibrateOptions opt;
  opt.holdout_fraction = 0.0;
  opt.distances.push_back({"hole_0", "hole_1", 50.0});
  opt.prior_weight = 0.0;  // the least-squares optimum, without the default
                           // ridge of single-point data
  const CalibrateResult r =
      Calibrate(nominal, ReadMukcaDir(Mukca("data/panda_3/frontcenter")), opt);
  for (const char* test :
       {"backcenter", "backleft", "backright", "frontleft", "frontright"}) {
    const Observations obs =
        ReadMukcaDir(Mukca(std::string("data/panda_3/") + test));
    const EvaluateResult ours = Evaluate(r.calibrated, obs);
    const EvaluateResult theirs = Evaluate(authors, obs);
    EXPECT_NEAR(ours.stats.rms_mm, theirs.stats.rms_mm, 0.005) << test;
    EXPECT_NEAR(SocketDistance(ours), SocketDistance(theirs), 0.01) << test;
  }
}

// The known distance enters as weight * (|a - b| - d) beside the tip
// residuals. Without enough weight the tips pull it: on panda_6 "front" the
// seating data alone prefer the sockets 0.41 mm closer (weight 1), which
// every held-out recording then inherits (median 50 mm error 0.24 mm vs
// 0.09 mm over the 104 train-on-one pairs); the default 10 holds it to
// 0.0005 mm, and 1000 changes nothing measurable (docs/REAL_DATA.md).
TEST(RealDataTest, MukcaKnownDistanceIsHeldByTheDefaultWeight) {
  KINCAL_REQUIRE_SHARED_DATA("mukca");
  const Robot nominal = ReadRobot(Mukca("urdf/panda.urdf"), "", "ball_link");
  const Observations front = ReadMukcaDir(Mukca("data/panda_6/front"));
  CalibrateOptions opt;
  opt.holdout_fraction = 0.0;
  opt.distances.push_back({"hole_0", "hole_1", 50.0});
  const CalibrateResult held = Calibrate(nominal, front, opt);
  EXPECT_LT(std::abs(held.distance_errors_mm.at(0)), 0.003);
  opt.distance_weight = 1.0;
  const CalibrateResult soft = Calibrate(nominal, front, opt);
  EXPECT_GT(std::abs(soft.distance_errors_mm.at(0)), 0.1);
  EXPECT_LT(soft.train.rms_mm, held.train.rms_mm);  // traded for scatter
  opt.distance_weight = 0.0;
  EXPECT_THROW(Calibrate(nominal, front, opt), std::exception);
}

// Gross errors on real single-point data. MUKCa panda_7 `left` (in the
// authors' repository, not in shared/) has 6 rows of hole_1 saved in
// hole_0.csv; here the same defect is made on panda_6 `front`: 5 rows of
// hole_1 relabelled hole_0. Calibrating from the nominal model lists
// exactly those, names hole_1 as where they sit, and fits as the clean
// recording does. The clean recordings of panda_3 and panda_6 list no row.
TEST(RealDataTest, MukcaRowsSavedUnderTheOtherSocketAreFound) {
  KINCAL_REQUIRE_SHARED_DATA("mukca");
  const Robot nominal = ReadRobot(Mukca("urdf/panda.urdf"), "", "ball_link");
  const Observations front = ReadMukcaDir(Mukca("data/panda_6/front"));
  CalibrateOptions opt;
  opt.holdout_fraction = 0.0;
  opt.distances.push_back({"hole_0", "hole_1", 50.0});
  Observations bad = front;
  std::set<std::string> moved;
  for (Observation& o : bad.rows) {
    if (o.fixed_point == "hole_1" && moved.size() < 5) {
      o.fixed_point = "hole_0";
      moved.insert(o.pose);
    }
  }
  const CalibrateResult clean = Calibrate(nominal, front, opt);
  const CalibrateResult r = Calibrate(nominal, bad, opt);
  std::set<std::string> listed;
  for (const RowOutlier& o : r.outliers) {
    listed.insert(o.pose);
    EXPECT_TRUE(o.excluded);
    EXPECT_EQ(o.near_point, "hole_1") << o.pose;
    EXPECT_LT(o.near_point_mm, 1.0) << o.pose;
  }
  EXPECT_EQ(listed, moved);
  RecordProperty("train_rms_mm", std::to_string(r.train.rms_mm));
  EXPECT_NEAR(r.train.rms_mm, clean.train.rms_mm, 0.01);
  opt.outlier_sigmas = 0;
  EXPECT_GT(Calibrate(nominal, bad, opt).train.rms_mm, 5.0);
  opt.outlier_sigmas = kDefaultOutlierSigmas;
  EXPECT_TRUE(clean.outliers.empty());
  for (const char* rec : {"panda_6/left", "panda_6/right", "panda_3/backcenter",
                          "panda_3/frontleft", "panda_3_bis/right-high"}) {
    const CalibrateResult c = Calibrate(
        nominal, ReadMukcaDir(Mukca(std::string("data/") + rec)), opt);
    EXPECT_TRUE(c.outliers.empty()) << rec;
  }
}

// --free compliance on the Panda (panda_4, trained on "front" as the
// authors): the family frees each joint's compliance; joint 7, whose
// torque arm is the ball's ~7 mm offset, is held; the torque inputs follow
// the fitted geometry, so the model predicts "right" at 0.250 mm (authors
// 0.312, geometry only 0.295). Computed from the nominal geometry only
// (ball on the axis) the same fit predicted 1.26 mm.
TEST(RealDataTest, MukcaComplianceFamilyPredictsAnotherRecording) {
  KINCAL_REQUIRE_SHARED_DATA("mukca");
  const Robot nominal = ReadRobot(Mukca("urdf/panda.urdf"), "", "ball_link");
  CalibrateOptions opt;
  opt.holdout_fraction = 0.0;
  opt.distances.push_back({"hole_0", "hole_1", 50.0});
  opt.extra_params = {"compliance"};
  const CalibrateResult r =
      Calibrate(nominal, ReadMukcaDir(Mukca("data/panda_4_clean/front")), opt);
  std::vector<std::string> free;
  for (const ParamInfo& p : r.identifiability.identifiable) {
    if (p.kind == ParamKind::kJointError) free.push_back(p.name);
  }
  EXPECT_THAT(free, ::testing::Contains("panda_joint2.compliance"));
  EXPECT_THAT(free, ::testing::Contains("panda_joint4.compliance"));
  EXPECT_THAT(free,
              ::testing::Not(::testing::Contains("panda_joint7.compliance")));
  const Observations right = ReadMukcaDir(Mukca("data/panda_4_clean/right"));
  const double ours = Evaluate(r.calibrated, right).stats.rms_mm;
  RecordProperty("right_mm", std::to_string(ours));
  EXPECT_LT(ours, 0.27);
}

}  // namespace
}  // namespace kincal
