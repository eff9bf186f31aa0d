#include "data/import_mukca.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "data/error.h"
#include "tests/testing/paths.h"

namespace kincal {
namespace {

using ::testing::HasSubstr;

Observations Empty() {
  Observations obs;
  obs.joint_names = PandaJointNames();
  return obs;
}

TEST(ImportMukcaTest, ParsesJointSetsInRadians) {
  Observations obs = Empty();
  ParseMukcaHole(
      "4.583062544069793631e-01,6.51e-01,-5.77e-01,-2.0685e+00,4.27e-01,"
      "1.9085e+00,7.72e-01\n"
      "0,0,0,-1.5707963267948966,0,1.5707963267948966,0.7853981633974483\n",
      "h.csv", "hole_1", &obs);
  ASSERT_EQ(obs.rows.size(), 2u);
  EXPECT_EQ(obs.rows[0].fixed_point, "hole_1");
  EXPECT_EQ(obs.rows[1].pose, "hole_1_1");
  EXPECT_FALSE(obs.rows[0].has_point);
  EXPECT_NEAR(obs.rows[0].q[0], 0.4583062544069793631 * 180 / M_PI, 1e-12);
  EXPECT_NEAR(obs.rows[1].q[3], -90.0, 1e-12);
  EXPECT_NEAR(obs.rows[1].q[6], 45.0, 1e-12);
  EXPECT_EQ(obs.rows[1].line, 2);
}

TEST(ImportMukcaTest, RejectsBadLines) {
  Observations obs = Empty();
  try {
    ParseMukcaHole("1,2,3,4,5,6,7\n1,2,3,4,5,6\n", "h.csv", "hole_0", &obs);
    FAIL() << "expected a field-count error";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("h.csv:2:"));
    EXPECT_THAT(e.what(), HasSubstr("expected 7 joint angles"));
  }
  try {
    ParseMukcaHole("1,2,3,x,5,6,7\n", "h.csv", "hole_0", &obs);
    FAIL() << "expected a number error";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("h.csv:1:7: expected a joint angle"));
  }
  EXPECT_THROW(ParseMukcaHole("", "h.csv", "hole_0", &obs), InputError);
  EXPECT_THROW(ReadMukcaDir("/nonexistent/kincal_mukca"), InputError);
}

TEST(ImportMukcaTest, ReadsARealRecording) {
  KINCAL_REQUIRE_SHARED_DATA("mukca");
  const Observations obs =
      ReadMukcaDir(testing::SharedDataDir() + "/mukca/data/panda_6/front");
  // hole_0.csv and hole_1.csv have 31 lines each (kpis.yaml lists 31 + 31).
  ASSERT_EQ(obs.rows.size(), 62u);
  EXPECT_EQ(obs.CountWithFixedPoint(), 62);
  EXPECT_EQ(obs.rows.front().fixed_point, "hole_0");
  EXPECT_EQ(obs.rows.back().fixed_point, "hole_1");
  EXPECT_NEAR(obs.rows[0].q[0], 0.4583062544069793631 * 180 / M_PI, 1e-9);
  // Panda limits: joint 4 in [-176, -4] deg, joint 6 in [-1, 215] deg.
  for (const Observation& r : obs.rows) {
    EXPECT_LT(r.q[3], -4.0);
    EXPECT_GT(r.q[5], -1.01);
  }
}

}  // namespace
}  // namespace kincal
