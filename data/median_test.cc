#include "data/median.h"

#include <gtest/gtest.h>

namespace kincal {
namespace {

TEST(UpperMedianTest, MiddleElementOrTheUpperOfTheTwo) {
  EXPECT_EQ(UpperMedian({}), 0.0);
  EXPECT_EQ(UpperMedian({4.0}), 4.0);
  EXPECT_EQ(UpperMedian({3.0, 1.0, 2.0}), 2.0);
  EXPECT_EQ(UpperMedian({4.0, 1.0, 3.0, 2.0}), 3.0);
  EXPECT_EQ(UpperMedian({5.0, 5.0, -1.0, 100.0, 0.0}), 5.0);
}

}  // namespace
}  // namespace kincal
