#include "calib/fit_record.h"

#include <gtest/gtest.h>

#include <cmath>

#include "calib/chain.h"
#include "data/error.h"

namespace kincal {
namespace {

Observations TwoRows() {
  Observations obs;
  obs.joint_names = {"j1", "j2"};
  Observation a, b;
  a.q = {10, -20};
  a.temp_c = 21;
  b.q = {-5, 30};
  b.temp_c = 25;
  obs.rows = {a, b};
  return obs;
}

TEST(FitRecordTest, TravelTemperatureFrameAndCovarianceInInterfaceUnits) {
  const Observations obs = TwoRows();
  FitSummary fit;
  ParamInfo angle;
  angle.name = "j2.theta";
  angle.angle = true;
  ParamInfo length;
  length.name = "j2.a";
  ParamInfo frame;
  frame.name = "frame.x";
  frame.kind = ParamKind::kFrame;
  ParamInfo point;
  point.name = "point.P1.x";
  point.kind = ParamKind::kPoint;
  fit.params = {angle, length, frame, point};
  fit.covariance = Eigen::MatrixXd::Identity(4, 4);
  fit.covariance(0, 0) = 1e-6;                         // rad^2
  fit.covariance(0, 1) = fit.covariance(1, 0) = 2e-4;  // rad mm
  ModelState state;
  state.meas_from_base = {0, 0, M_PI / 2, 100, 200, 300};
  FitRecordInput in;
  in.obs = &obs;
  in.fit = &fit;
  in.state = &state;
  in.heldout_rms_mm = 0.05;
  const FitRecord rec = MakeFitRecord(in);
  EXPECT_EQ(rec.poses, 2);
  ASSERT_EQ(rec.joint_range.size(), 2u);
  EXPECT_EQ(rec.joint_range[0][0], -5.0);
  EXPECT_EQ(rec.joint_range[1][1], 30.0);
  EXPECT_EQ(rec.temp_lo_c, 21.0);
  EXPECT_EQ(rec.temp_hi_c, 25.0);
  EXPECT_EQ(rec.thermal_input, "temp_c");
  ASSERT_TRUE(rec.has_frame);
  EXPECT_NEAR(rec.frame[2], 90.0, 1e-12);
  EXPECT_EQ(rec.frame[5], 300.0);
  // Fixed points are left out; the frame stays; deg and mm.
  ASSERT_EQ(rec.covariance_params,
            (std::vector<std::string>{"j2.theta", "j2.a", "frame.x"}));
  const double deg = 180.0 / M_PI;
  EXPECT_NEAR(rec.covariance(0, 0), 1e-6 * deg * deg, 1e-12);
  EXPECT_NEAR(rec.covariance(0, 1), 2e-4 * deg, 1e-12);
  EXPECT_EQ(rec.covariance(2, 2), 1.0);
  EXPECT_EQ(rec.heldout_rms_mm, 0.05);
}

// Without a FitSummary (the bundle's case): the parameters and their
// covariance given directly give the same record; a covariance of another
// size gives none.
TEST(FitRecordTest, ParamsAndCovarianceWithoutAFitSummary) {
  const Observations obs = TwoRows();
  ParamInfo angle;
  angle.name = "j2.theta";
  angle.angle = true;
  ParamInfo frame;
  frame.name = "frame.x";
  frame.kind = ParamKind::kFrame;
  const std::vector<ParamInfo> params = {angle, frame};
  Eigen::MatrixXd cov(2, 2);
  cov << 4e-6, 1e-3, 1e-3, 0.25;  // rad^2, rad mm, mm^2
  FitRecordInput in;
  in.obs = &obs;
  in.rows = {1};
  in.params = &params;
  in.covariance = &cov;
  const FitRecord rec = MakeFitRecord(in);
  EXPECT_EQ(rec.poses, 1);
  EXPECT_EQ(rec.joint_range[0][0], -5.0);
  EXPECT_EQ(rec.joint_range[0][1], -5.0);
  ASSERT_EQ(rec.covariance_params,
            (std::vector<std::string>{"j2.theta", "frame.x"}));
  const double deg = 180.0 / M_PI;
  EXPECT_NEAR(rec.covariance(0, 0), 4e-6 * deg * deg, 1e-12);
  EXPECT_NEAR(rec.covariance(1, 0), 1e-3 * deg, 1e-12);
  EXPECT_EQ(rec.covariance(1, 1), 0.25);
  const Eigen::MatrixXd wrong = Eigen::MatrixXd::Identity(3, 3);
  in.covariance = &wrong;
  EXPECT_TRUE(MakeFitRecord(in).covariance_params.empty());
}

TEST(FitRecordTest, WideGapsInTheTravelAreRecorded) {
  Observations obs;
  obs.joint_names = {"j1"};
  for (double q : {-100.0, -95.0, -90.0, 0.0, 10.0, 20.0, 50.0}) {
    Observation o;
    o.q = {q};
    obs.rows.push_back(o);
  }
  const TravelGap g = LargestGap(obs, 0);
  EXPECT_EQ(g.from, -90.0);
  EXPECT_EQ(g.to, 0.0);
  EXPECT_TRUE(IsWideGap(g));
  FitRecordInput in;
  in.obs = &obs;
  const FitRecord rec = MakeFitRecord(in);
  ASSERT_EQ(rec.joint_gap.size(), 1u);
  EXPECT_EQ(rec.joint_gap[0][0], -90.0);
  EXPECT_EQ(rec.joint_gap[0][1], 0.0);
  // Steps of 5 deg: no gap worth naming.
  in.rows = {0, 1, 2};
  EXPECT_FALSE(MakeFitRecord(in).joint_gap[0][0] ==
               MakeFitRecord(in).joint_gap[0][0]);
}

TEST(FitRecordTest, RowsSubsetAndRecordedNominal) {
  const Observations obs = TwoRows();
  FitRecordInput in;
  in.obs = &obs;
  in.rows = {1};
  const FitRecord rec = MakeFitRecord(in);
  EXPECT_EQ(rec.poses, 1);
  EXPECT_EQ(rec.joint_range[0][0], -5.0);
  EXPECT_EQ(rec.joint_range[0][1], -5.0);
  EXPECT_TRUE(rec.covariance_params.empty());
  EXPECT_FALSE(rec.has_frame);
  Robot nominal;
  nominal.joints.resize(2);
  nominal.joints[0].name = "j1";
  nominal.joints[1].name = "j2";
  nominal.joints[1].a_mm = 200;
  Robot calibrated = nominal;
  calibrated.joints[1].a_mm = 200.3;
  const Robot out = WithFitRecord(calibrated, nominal, in);
  ASSERT_TRUE(out.HasNominal());
  EXPECT_EQ(out.nominal_joints[1].a_mm, 200.0);
  EXPECT_EQ(out.joints[1].a_mm, 200.3);
  EXPECT_EQ(out.fitted_on.poses, 1);
}

// The file's periodic basis round trip: a chain whose periodic row has a
// fitted basis and coefficients, written as its Fourier coefficients (as
// the robot file stores them) and read back through ApplyPeriodicBases,
// predicts the same pose and names the same coefficients.
TEST(FitRecordTest, PeriodicBasesRoundTripThroughFourierCoefficients) {
  Robot robot;
  robot.name = "two";
  for (const char* name : {"j1", "j2"}) {
    RobotRow row;
    row.name = name;
    row.a_mm = 300.0;
    robot.joints.push_back(row);
  }
  robot.tool.name = "tool";
  robot.tool.d_mm = 100.0;
  Chain fitted = Chain::FromRobot(robot);
  std::vector<double> b(kPeriodicTerms * kMaxTransmissionTerms, 0.0);
  for (int k = 0; k < 3; ++k) {
    for (int t = 0; t < kPeriodicTerms; ++t) {
      b[kPeriodicTerms * k + t] = std::sin(0.7 * (k + 1) * (t + 1)) / (t + 1);
    }
  }
  fitted.rows[1].periodic_basis = b;
  fitted.joint_errors[1][kTransmission0 + 0] = 2e-4;
  fitted.joint_errors[1][kTransmission0 + 2] = -1e-4;
  const auto bases = PeriodicBases(fitted);
  ASSERT_EQ(bases.size(), 1u);
  EXPECT_EQ(bases[0].first, "j2");
  EXPECT_EQ(bases[0].second.cols(), 3);  // trailing zero columns dropped
  FitRecord rec;
  rec.periodic_bases = bases;
  // As read from a file: the Fourier coefficients in one column, c_1 = 1.
  Chain file_form = fitted;
  file_form.rows[1].periodic_basis = FourierBasis(
      PeriodicCoefficients(fitted.rows[1], fitted.joint_errors[1]));
  for (int k = 0; k < kMaxTransmissionTerms; ++k)
    file_form.joint_errors[1][kTransmission0 + k] = k == 0 ? 1.0 : 0.0;
  Chain read = file_form;
  ApplyPeriodicBases(rec, &read);
  EXPECT_NEAR(read.joint_errors[1][kTransmission0 + 0], 2e-4, 1e-15);
  EXPECT_NEAR(read.joint_errors[1][kTransmission0 + 1], 0.0, 1e-15);
  EXPECT_NEAR(read.joint_errors[1][kTransmission0 + 2], -1e-4, 1e-15);
  // A basis that cannot give the row's coefficients is refused.
  FitRecord wrong = rec;
  wrong.periodic_bases[0].second.col(0).setZero();
  Chain again = file_form;
  EXPECT_THROW(ApplyPeriodicBases(wrong, &again), InputError);
  // A basis naming a row that is not periodic is refused.
  wrong = rec;
  wrong.periodic_bases[0].first = "j1";
  again = file_form;
  EXPECT_THROW(ApplyPeriodicBases(wrong, &again), InputError);
}

}  // namespace
}  // namespace kincal
