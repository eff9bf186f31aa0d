#include "diagnose/travel_gaps.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace kincal {
namespace {

using ::testing::HasSubstr;

Observations Readings(const std::vector<double>& a,
                      const std::vector<double>& b) {
  Observations obs;
  obs.joint_names = {"j1", "j2"};
  for (size_t i = 0; i < a.size(); ++i) {
    Observation o;
    o.q = {a[i], b[i]};
    obs.rows.push_back(o);
  }
  return obs;
}

TEST(TravelGapsTest, WarnsWhereTheGapIsALargeShareOfTheTravel) {
  // j1: a 90 deg gap in 150 deg of travel; j2: evenly covered.
  const Observations obs =
      Readings({50, -100, 0, 10, 20, -90}, {0, 1, 2, 3, 4, 5});
  const auto w = TravelGapWarnings(obs, {"j1", "j2"}, {"deg", "deg"});
  ASSERT_EQ(w.size(), 1u);
  EXPECT_EQ(w[0].code, "transmission_gap");
  EXPECT_THAT(w[0].message, HasSubstr("j1: the transmission series is fitted "
                                      "over the travel [-100.0, 50.0] deg"));
  EXPECT_THAT(w[0].message, HasSubstr("between -90.0 and 0.0 (a gap of 90.0 "
                                      "deg, 60 % of the travel)"));
  // A small gap in absolute terms is not worth a warning.
  EXPECT_TRUE(TravelGapWarnings(Readings({0, 0.1, 3, 3.1}, {0, 1, 2, 3}),
                                {"j1"}, {"deg"})
                  .empty());
}

}  // namespace
}  // namespace kincal
