#include "data/import_ipa.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>

#include "data/error.h"
#include "tests/testing/paths.h"

namespace kincal {
namespace {

using ::testing::HasSubstr;

// Two rows in the format of Series_C (std columns, truncated timestamp).
const char* kSeriesC =
    "Timestamp;Goal x;Goal y;Goal z;Goal roll;Goal pitch;Goal yaw;"
    "shoulder_pan_joint;shoulder_lift_joint;elbow_joint;wrist_1_joint;"
    "wrist_2_joint;wrist_3_joint;measurement_temperature;measurement_x;"
    "measurement_std_x;measurement_y;measurement_std_y;measurement_z;"
    "measurement_std_z;measurement_rx;measurement_std_rx;measurement_ry;"
    "measurement_std_ry;measurement_rz;measurement_std_rz\r\n"
    "2,02011E+13;-0,000181978;-0,365141;1,4273;1,57005;1,56969;-0,000186977;"
    "-3,14159;-1,5708;0;-1,5708;0;0;21,68000031;383,97123;0,041565;"
    "-3240,7562;0,022023;201,72621;0,0055848;-90,179563;0,0024569;"
    "-20,112975;0,0065397;-90,157388;0,008348\r\n"
    "2,02011E+13;0,0103459;-0,480444;1,00632;3,10253;1,66683;1,57927;"
    "-4,08444;-2,6946;1,69873;-2,031;0,99275;-0,0673035;21,68000031;"
    "335,14778;0,0054521;-3134,3677;0,0062093;-221,16088;0,0076535;"
    "-84,20352;0,00099888;-22,726835;0,0026542;-88,245609;0,0014716\r\n";

// Series_A style: full timestamps, no std columns, trailing '.' on the last.
const char* kSeriesA =
    "Timestamp;Goal x;Goal y;Goal z;Goal roll;Goal pitch;Goal yaw;"
    "shoulder_pan_joint;shoulder_lift_joint;elbow_joint;wrist_1_joint;"
    "wrist_2_joint;wrist_3_joint;measurement_temperature;measurement_x;"
    "measurement_y;measurement_z;measurement_rx;measurement_ry;measurement_rz\n"
    "20200714163904;0,365141;-0,000212669;1,4273;1,57002;1,57007;1,57073;"
    "-1,5708;-1,5708;0,0;-1,5708;0,0;0,0;23,6800003051758;2361,9831;"
    "-1368,5474;119,39713;-90,409151;-59,885105;-90,887438\n"
    "20200714163924;0,8;0,6;0,9;1,74533;1,5708;1,5708;-2,14055;-2,08493;"
    "-0,837441;-0,218756;0,393594;-0,00187856;23,68;1685,2797;-1665,3456;"
    "-415,81103;-90,282663;-49,675357;-90,793449.\n";

std::string ErrorOf(const std::string& text) {
  try {
    ParseIpaSeries(text, "s.csv");
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(ImportIpaTest, ParsesDecimalCommas) {
  double v = 0;
  EXPECT_TRUE(ParseDecimalComma("-3240,7562", &v));
  EXPECT_DOUBLE_EQ(v, -3240.7562);
  EXPECT_TRUE(ParseDecimalComma("2,02011E+13", &v));
  EXPECT_DOUBLE_EQ(v, 2.02011e13);
  EXPECT_TRUE(ParseDecimalComma("0", &v));
  EXPECT_DOUBLE_EQ(v, 0.0);
  EXPECT_TRUE(ParseDecimalComma("-90,793449.", &v));  // Series_A's last cell
  EXPECT_DOUBLE_EQ(v, -90.793449);
  EXPECT_FALSE(ParseDecimalComma("1,2,3", &v));
  EXPECT_FALSE(ParseDecimalComma("1,2.3", &v));
  EXPECT_FALSE(ParseDecimalComma("", &v));
  EXPECT_FALSE(ParseDecimalComma("nan", &v));
}

TEST(ImportIpaTest, ReadsSeriesCRow) {
  const IpaSeries s = ParseIpaSeries(kSeriesC, "c.csv");
  ASSERT_EQ(s.observations.rows.size(), 2u);
  EXPECT_EQ(s.observations.joint_names, IpaUr10JointNames());
  const Observation& r = s.observations.rows[0];
  EXPECT_EQ(r.pose, "0");
  EXPECT_EQ(r.line, 2);
  EXPECT_NEAR(r.q[0], -3.14159 * 180 / M_PI, 1e-9);  // rad -> deg
  EXPECT_NEAR(r.q[3], -90.0002, 1e-3);
  EXPECT_TRUE(r.has_point);
  EXPECT_DOUBLE_EQ(r.p_in_meas.x(), 383.97123);
  EXPECT_DOUBLE_EQ(r.p_in_meas.y(), -3240.7562);
  EXPECT_DOUBLE_EQ(r.p_in_meas.z(), 201.72621);
  EXPECT_FALSE(r.HasTime());  // truncated timestamps are not times
  EXPECT_FALSE(s.has_time);
  EXPECT_DOUBLE_EQ(s.temperature_c[1], 21.68000031);
  EXPECT_DOUBLE_EQ(s.observations.rows[1].temp_c, 21.68000031);  // temp_c
  EXPECT_DOUBLE_EQ(s.std_mm[0].x(), 0.041565);
  EXPECT_DOUBLE_EQ(s.rotation_deg[1].z(), -88.245609);
  EXPECT_NEAR(s.goal_mm[0].y(), -365.141, 1e-9);  // m -> mm
}

TEST(ImportIpaTest, SeriesAHasTimesAndNoStd) {
  const IpaSeries s = ParseIpaSeries(kSeriesA, "a.csv");
  ASSERT_EQ(s.observations.rows.size(), 2u);
  EXPECT_TRUE(s.has_time);
  EXPECT_DOUBLE_EQ(s.observations.rows[0].t_s, 0.0);
  EXPECT_DOUBLE_EQ(s.observations.rows[1].t_s, 20.0);  // 16:39:04 -> 16:39:24
  EXPECT_TRUE(std::isnan(s.std_mm[0].x()));
  EXPECT_DOUBLE_EQ(s.rotation_deg[1].z(), -90.793449);
}

TEST(ImportIpaTest, MapsToTheRobotsJointNames) {
  const std::vector<std::string> names = {"j1", "j2", "j3", "j4", "j5", "j6"};
  const IpaSeries s = ParseIpaSeries(kSeriesC, "c.csv", names);
  EXPECT_EQ(s.observations.joint_names, names);
  EXPECT_THAT(ErrorOf(""), HasSubstr("header"));
  try {
    ParseIpaSeries(kSeriesC, "c.csv", {"a", "b"});
    FAIL() << "expected an error for 2 joint names";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("6 joint columns"));
  }
}

TEST(ImportIpaTest, RejectsBadInputWithFileLineColumn) {
  std::string missing = kSeriesC;
  missing.replace(missing.find("elbow_joint"), 11, "elbow");
  EXPECT_THAT(ErrorOf(missing),
              HasSubstr("s.csv:1:1: expected a column 'elbow_joint'"));

  std::string bad_cell = kSeriesC;
  bad_cell.replace(bad_cell.find("383,97123"), 9, "383,9x");
  // Field 15 of line 2 (measurement_x).
  EXPECT_THAT(ErrorOf(bad_cell), HasSubstr("s.csv:2:"));
  EXPECT_THAT(ErrorOf(bad_cell), HasSubstr("'383,9x'"));

  std::string short_row = kSeriesC;
  short_row.replace(short_row.find(";0,008348\r\n"), 9, "");
  EXPECT_THAT(ErrorOf(short_row), HasSubstr("s.csv:2:"));
  EXPECT_THAT(ErrorOf(short_row), HasSubstr("expected 26"));

  const std::string header_only =
      std::string(kSeriesC).substr(0, std::string(kSeriesC).find('\n') + 1);
  EXPECT_THAT(ErrorOf(header_only), HasSubstr("at least one data row"));
}

TEST(ImportIpaTest, ReadsTheRealSeries) {
  KINCAL_REQUIRE_SHARED_DATA("ipa-robot-accuracy");
  const std::string dir = testing::SharedDataDir() + "/ipa-robot-accuracy";
  const IpaSeries a = ReadIpaSeries(dir + "/Series_A/measurements_grid.csv");
  const IpaSeries b =
      ReadIpaSeries(dir + "/Series_B/measurements_joint_configurations.csv");
  const IpaSeries c =
      ReadIpaSeries(dir + "/Series_C/measurements_random_poses.csv");
  // SOURCE.txt: A grid 11,911 poses, B 1,495, C 2,773.
  EXPECT_EQ(a.observations.rows.size(), 11911u);
  EXPECT_EQ(b.observations.rows.size(), 1495u);
  EXPECT_EQ(c.observations.rows.size(), 2773u);
  EXPECT_TRUE(a.has_time);
  EXPECT_FALSE(c.has_time);
  // Series A was recorded overnight (16:39 to 05:01 next day).
  EXPECT_GT(a.observations.rows.back().t_s, 10 * 3600.0);
  for (const IpaSeries* s : {&a, &b, &c}) {
    for (const Observation& r : s->observations.rows) {
      ASSERT_EQ(r.q.size(), 6u);
      for (double q : r.q) ASSERT_LE(std::abs(q), 360.0 + 1e-6) << r.line;
      // The tracker stands a few metres from the robot.
      ASSERT_LT(r.p_in_meas.norm(), 5000.0) << r.line;
    }
  }
  for (double t : c.temperature_c) {
    EXPECT_GT(t, 15.0);
    EXPECT_LT(t, 35.0);
  }
}

}  // namespace
}  // namespace kincal
