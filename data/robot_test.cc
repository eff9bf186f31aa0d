#include "data/robot.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "data/error.h"
#include "tests/testing/paths.h"

namespace kincal {
namespace {

using ::testing::HasSubstr;

const char* kSpecExample = R"(kincal_robot: 1                 # format version
name: BH-7
convention: dh                  # standard DH
gravity: [0, 0, -1]
joints:
  - {name: j1, type: prismatic, d: 0,    alpha: 0,   a: 0,   theta: 0}
  - {name: j2, type: revolute,  d: 0,    alpha: 0,   a: 200, theta: 0}
  - {name: j3, type: revolute,  d: 0,    alpha: 0,   a: 200, theta: 0}
  - {name: j4, type: revolute,  d: -170, alpha: -90, a: 0,   theta: -90}
  - {name: j5, type: revolute,  d: 145,  alpha: -90, a: 0,   theta: 0}
tool: {d: 150, alpha: 0, a: 0, theta: 0}
bounds: {length: 5, angle: 5}
)";

std::string ErrorOf(const std::string& text) {
  try {
    ParseRobotYaml(text, "r.yaml");
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(RobotYamlTest, ReadsSpecExample) {
  const Robot r = ParseRobotYaml(kSpecExample, "spec.yaml");
  EXPECT_EQ(r.name, "BH-7");
  ASSERT_EQ(r.joints.size(), 5u);
  EXPECT_EQ(r.joints[0].type, JointType::kPrismatic);
  EXPECT_DOUBLE_EQ(r.joints[3].d_mm, -170);
  EXPECT_DOUBLE_EQ(r.joints[3].alpha_deg, -90);
  EXPECT_DOUBLE_EQ(r.joints[3].theta_deg, -90);
  EXPECT_DOUBLE_EQ(r.tool.d_mm, 150);
  EXPECT_DOUBLE_EQ(r.bound_length_mm, 5);
  EXPECT_FALSE(r.joints[0].HasLimits());
}

TEST(RobotYamlTest, BundledBh7IsTable1) {
  const Robot file =
      ReadRobotYaml(testing::SourceDir() + "/data/robots/bh7.yaml");
  const Robot spec = ParseRobotYaml(kSpecExample, "spec.yaml");
  ASSERT_EQ(file.joints.size(), spec.joints.size());
  for (size_t i = 0; i < spec.joints.size(); ++i) {
    EXPECT_EQ(file.joints[i].name, spec.joints[i].name);
    EXPECT_EQ(file.joints[i].d_mm, spec.joints[i].d_mm);
    EXPECT_EQ(file.joints[i].a_mm, spec.joints[i].a_mm);
    EXPECT_EQ(file.joints[i].alpha_deg, spec.joints[i].alpha_deg);
    EXPECT_EQ(file.joints[i].theta_deg, spec.joints[i].theta_deg);
    EXPECT_TRUE(file.joints[i].HasLimits());
  }
}

TEST(RobotYamlTest, MdhAndUrdfConventions) {
  std::string mdh = kSpecExample;
  mdh.replace(mdh.find("convention: dh"), 14, "convention: mdh");
  EXPECT_EQ(ParseRobotYaml(mdh, "m.yaml").convention, Convention::kMdh);
  const Robot u = ParseRobotYaml(
      "kincal_robot: 1\nconvention: urdf\njoints:\n"
      "  - {name: a, type: revolute, xyz: [0, 0, 333], rpy: [0, 0, 0], "
      "axis: [0, 0, 2]}\ntool: {xyz: [0, 0, 107], rpy: [0, 0, 45]}\n",
      "u.yaml");
  EXPECT_EQ(u.convention, Convention::kUrdf);
  EXPECT_DOUBLE_EQ(u.joints[0].axis.z(), 1.0);
  EXPECT_DOUBLE_EQ(u.tool.rpy_deg.z(), 45.0);
}

TEST(RobotYamlTest, WriteThenReadIsIdentity) {
  Robot r = ParseRobotYaml(kSpecExample, "spec.yaml");
  r.joints[2].a_mm = 194.9624123456789;
  r.joints[1].beta_deg = 0.0123;
  r.extensions.push_back({"backlash", "j3", {{"width", 0.42}}});
  const Robot back = ParseRobotYaml(FormatRobotYaml(r), "back.yaml");
  EXPECT_EQ(back.joints[2].a_mm, r.joints[2].a_mm);
  EXPECT_EQ(back.joints[1].beta_deg, 0.0123);
  ASSERT_EQ(back.extensions.size(), 1u);
  EXPECT_EQ(back.extensions[0].joint, "j3");
  EXPECT_EQ(back.extensions[0].values.at("width"), 0.42);
}

TEST(RobotYamlTest, NominalFitRecordAndCovarianceRoundTrip) {
  const Robot nominal = ParseRobotYaml(kSpecExample, "spec.yaml");
  Robot r = nominal;
  r.joints[2].a_mm = 200.25;
  r.tool.d_mm = 149.5;
  r.SetNominal(nominal);
  r.fitted_on.poses = 40;
  r.fitted_on.joint_range = {{0, 50}, {-90, 90}, {-45, 45}, {-30, 30}, {0, 0}};
  r.fitted_on.joint_gap.assign(5, {NAN, NAN});
  r.fitted_on.joint_gap[1] = {10, 60};
  r.fitted_on.temp_lo_c = 21.5;
  r.fitted_on.temp_hi_c = 27.0;
  r.fitted_on.thermal_input = "temp_c";
  r.fitted_on.has_frame = true;
  r.fitted_on.frame = {1, 2, 3, 1000, -20, 5.5};
  r.fitted_on.series_frames = {{"A", {1, 2, 3, 1000, -20, 5.5}},
                               {"B \"2\"", {-1, 0, 0.5, 10, 20, 30}}};
  r.fitted_on.heldout_rms_mm = 0.031;
  r.fitted_on.systematic_rms_mm = 0.0;
  r.fitted_on.covariance_params = {"j3.a", "tool.d"};
  r.fitted_on.covariance.resize(2, 2);
  r.fitted_on.covariance << 4e-4, -1e-4, -1e-4, 9e-4;
  const Robot back = ParseRobotYaml(FormatRobotYaml(r), "back.yaml");
  ASSERT_TRUE(back.HasNominal());
  EXPECT_EQ(back.Nominal().joints[2].a_mm, 200.0);
  EXPECT_EQ(back.Nominal().tool.d_mm, 150.0);
  EXPECT_EQ(back.joints[2].a_mm, 200.25);
  EXPECT_EQ(back.fitted_on.poses, 40);
  ASSERT_EQ(back.fitted_on.joint_range.size(), 5u);
  EXPECT_EQ(back.fitted_on.joint_range[1][0], -90.0);
  EXPECT_EQ(back.fitted_on.temp_hi_c, 27.0);
  ASSERT_EQ(back.fitted_on.joint_gap.size(), 5u);
  EXPECT_EQ(back.fitted_on.joint_gap[1][1], 60.0);
  EXPECT_FALSE(back.fitted_on.joint_gap[0][0] ==
               back.fitted_on.joint_gap[0][0]);
  EXPECT_EQ(back.fitted_on.thermal_input, "temp_c");
  EXPECT_TRUE(back.fitted_on.has_frame);
  EXPECT_EQ(back.fitted_on.frame[3], 1000.0);
  ASSERT_EQ(back.fitted_on.series_frames.size(), 2u);
  EXPECT_EQ(back.fitted_on.series_frames[1].first, "B \"2\"");
  EXPECT_EQ(back.fitted_on.series_frames[1].second[5], 30.0);
  EXPECT_EQ(back.fitted_on.heldout_rms_mm, 0.031);
  EXPECT_EQ(back.fitted_on.covariance_params[1], "tool.d");
  EXPECT_EQ(back.fitted_on.covariance(0, 1), -1e-4);
  EXPECT_EQ(back.fitted_on.covariance(1, 1), 9e-4);
  // A nominal of a nominal is the same nominal (calibrating a calibrated
  // file keeps the controller's kinematics).
  Robot again = back;
  again.SetNominal(back);
  EXPECT_EQ(again.nominal_joints[2].a_mm, 200.0);
}

// A periodic transmission's covariance names the fitted functions'
// coefficients; the file carries their basis (64 Fourier terms x m).
TEST(RobotYamlTest, PeriodicBasisRoundTripAndErrors) {
  Robot r = ParseRobotYaml(kSpecExample, "r.yaml");
  Extension e;
  e.cause = "transmission";
  e.joint = "j2";
  e.values = {{"a1", 0.01}, {"b1", -0.02}, {"lo", -90.0}, {"hi", 90.0}};
  r.extensions.push_back(e);
  r.fitted_on.poses = 10;
  r.fitted_on.covariance_params = {"j2.transmission1", "j2.transmission2"};
  r.fitted_on.covariance = Eigen::Matrix2d::Identity() * 1e-6;
  Eigen::MatrixXd basis = Eigen::MatrixXd::Zero(kFourierTerms, 2);
  basis(0, 0) = 1.0;
  basis(1, 1) = -2.0;
  basis(5, 1) = 0.25;
  r.fitted_on.periodic_bases = {{"j2", basis}};
  const std::string text = FormatRobotYaml(r);
  const Robot back = ParseRobotYaml(text, "back.yaml");
  ASSERT_EQ(back.fitted_on.periodic_bases.size(), 1u);
  EXPECT_EQ(back.fitted_on.periodic_bases[0].first, "j2");
  EXPECT_EQ(back.fitted_on.periodic_bases[0].second, basis);
  // A basis for a joint without a periodic transmission is refused, placed.
  std::string wrong = text;
  const size_t at = wrong.find("    j2:\n", wrong.find("periodic_basis"));
  ASSERT_NE(at, std::string::npos);
  wrong.replace(at, 8, "    j3:\n");
  try {
    ParseRobotYaml(wrong, "r.yaml");
    FAIL() << "basis of a joint without periodic transmission accepted";
  } catch (const InputError& err) {
    EXPECT_THAT(err.what(), HasSubstr("periodic_basis.j3"));
    EXPECT_THAT(err.what(), HasSubstr("r.yaml:"));
  }
  // Too few rows.
  std::string short_rows = text.substr(0, text.rfind("      - ["));
  try {
    ParseRobotYaml(short_rows, "r.yaml");
    FAIL() << "basis with 63 rows accepted";
  } catch (const InputError& err) {
    EXPECT_THAT(err.what(), HasSubstr("expected 64 rows"));
  }
}

TEST(RobotYamlTest, FitRecordErrorsArePlaced) {
  const std::string base = std::string(kSpecExample) +
                           "covariance:\n  params: [j3.a, tool.d]\n"
                           "  matrix:\n    - [1, 2]\n    - [3, 1]\n";
  try {
    ParseRobotYaml(base, "r.yaml");
    FAIL() << "asymmetric covariance accepted";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("not symmetric"));
  }
  const std::string nominal = std::string(kSpecExample) +
                              "nominal:\n  joints:\n    - {name: jx, d: 0, "
                              "alpha: 0, a: 0, theta: 0}\n  tool: {d: 1}\n";
  try {
    ParseRobotYaml(nominal, "r.yaml");
    FAIL() << "nominal with wrong row count accepted";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("nominal.joints: expected 5 rows"));
  }
}

TEST(RobotYamlTest, TransmissionSeriesRoundTripAndTravelChecked) {
  Robot r = ParseRobotYaml(kSpecExample, "spec.yaml");
  r.extensions.push_back({"transmission",
                          "j3",
                          {{"lo", -120.5},
                           {"hi", 35.25},
                           {"s1", 0.01},
                           {"s17", -0.0042},
                           {"s24", 1e-5}}});
  const Robot back = ParseRobotYaml(FormatRobotYaml(r), "back.yaml");
  ASSERT_EQ(back.extensions.size(), 1u);
  EXPECT_EQ(back.extensions[0].values, r.extensions[0].values);
  // Travel reversed, an unknown term, a missing travel: file:line:column.
  std::string text = FormatRobotYaml(r);
  const std::string good = "hi: 35.25";
  std::string bad = text;
  bad.replace(bad.find(good), good.size(), "hi: -130");
  EXPECT_NE(ErrorOf(bad).find("hi > lo"), std::string::npos) << ErrorOf(bad);
  EXPECT_NE(ErrorOf(bad).find("r.yaml:"), std::string::npos);
  bad = text;
  bad.replace(bad.find("s24"), 3, "s25");
  EXPECT_NE(ErrorOf(bad).find("unknown field 's25'"), std::string::npos)
      << ErrorOf(bad);
  bad = text;
  bad.replace(bad.find("lo: -120.5, "), 12, "");
  EXPECT_NE(ErrorOf(bad).find("missing field 'lo'"), std::string::npos)
      << ErrorOf(bad);
}

TEST(RobotYamlTest, LinkMassAndCentreOfMassRoundTrip) {
  std::string text = kSpecExample;
  const std::string row = "a: 200, theta: 0}";
  text.replace(text.find(row), row.size(),
               "a: 200, theta: 0, mass: 7.5, com: [-100, 0, 12.5]}");
  const Robot r = ParseRobotYaml(text, "m.yaml");
  EXPECT_FALSE(r.joints[0].HasMass());
  ASSERT_TRUE(r.joints[1].HasMass());
  EXPECT_DOUBLE_EQ(r.joints[1].mass_kg, 7.5);
  EXPECT_DOUBLE_EQ(r.joints[1].com_mm.x(), -100.0);
  EXPECT_DOUBLE_EQ(r.joints[1].com_mm.z(), 12.5);
  const Robot back = ParseRobotYaml(FormatRobotYaml(r), "back.yaml");
  EXPECT_DOUBLE_EQ(back.joints[1].mass_kg, 7.5);
  EXPECT_DOUBLE_EQ(back.joints[1].com_mm.x(), -100.0);
  EXPECT_FALSE(back.joints[2].HasMass());
  std::string bad = kSpecExample;
  bad.replace(bad.find(row), row.size(), "a: 200, theta: 0, mass: -1}");
  EXPECT_THAT(ErrorOf(bad), HasSubstr("mass"));
  bad = kSpecExample;
  bad.replace(bad.find(row), row.size(), "a: 200, theta: 0, com: [1, 2, 3]}");
  EXPECT_THAT(ErrorOf(bad), HasSubstr("without mass"));
}

TEST(RobotYamlTest, RejectsBadInputWithPosition) {
  // Each case: text, expected message fragment (with line:column).
  const std::string base = kSpecExample;
  auto replace = [&](const std::string& from, const std::string& to) {
    std::string s = base;
    s.replace(s.find(from), from.size(), to);
    return s;
  };
  EXPECT_THAT(ErrorOf(""), HasSubstr("empty file"));
  EXPECT_THAT(
      ErrorOf("kincal_robot: 2\njoints: []\n"),
      HasSubstr("r.yaml:1:15: kincal_robot: unsupported format version"));
  EXPECT_THAT(ErrorOf(replace("a: 200, theta: 0}", "a: abc, theta: 0}")),
              HasSubstr("r.yaml:7:"));
  EXPECT_THAT(ErrorOf(replace("a: 200, theta: 0}", "a: abc, theta: 0}")),
              HasSubstr("expected a number, got 'abc'"));
  EXPECT_THAT(ErrorOf(replace("a: 200, theta: 0}", "a: nan, theta: 0}")),
              HasSubstr("finite"));
  EXPECT_THAT(ErrorOf(replace("name: j2", "name: j1")),
              HasSubstr("duplicate joint name 'j1'"));
  EXPECT_THAT(ErrorOf(replace("type: prismatic", "type: spherical")),
              HasSubstr("r.yaml:6:"));
  EXPECT_THAT(ErrorOf(replace("convention: dh", "convention: xx")),
              HasSubstr("convention: expected 'dh', 'mdh' or 'urdf'"));
  EXPECT_THAT(ErrorOf(replace("bounds:", "bonds:")),
              HasSubstr("r.yaml:12:1: robot file: unknown key 'bonds'"));
  EXPECT_THAT(ErrorOf(replace("a: 0,   theta: -90}", "a: 0}")),
              HasSubstr("missing required key 'theta'"));
  EXPECT_THAT(ErrorOf(replace("gravity: [0, 0, -1]", "gravity: [0, 0]")),
              HasSubstr("expected 3 numbers, got 2"));
  EXPECT_THAT(ErrorOf("kincal_robot: 1\njoints: [\n"),
              HasSubstr("invalid YAML"));
  EXPECT_THAT(ErrorOf(base + "extensions:\n  - {cause: magic, joint: j3}\n"),
              HasSubstr("unknown cause 'magic'"));
  EXPECT_THAT(
      ErrorOf(base +
              "extensions:\n  - {cause: backlash, joint: j9, width: 1}\n"),
      HasSubstr("no joint named 'j9'"));
}

TEST(RobotYamlTest, MissingFileIsInputError) {
  EXPECT_THROW(ReadRobotYaml("/nonexistent/robot.yaml"), InputError);
}

}  // namespace
}  // namespace kincal
