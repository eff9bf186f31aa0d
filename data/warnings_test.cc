#include "data/warnings.h"

#include <gtest/gtest.h>

#include <sstream>

namespace kincal {
namespace {

TEST(WarningsTest, KeepsCodeAndMessageInOrder) {
  Warnings w;
  EXPECT_TRUE(w.empty());
  w.Add("joint_units_radians", "looks like radians");
  w.Add("clock_offset_weak", "agreement 0.55");
  ASSERT_EQ(w.list().size(), 2u);
  EXPECT_EQ(w.list()[0].code, "joint_units_radians");
  EXPECT_EQ(w.list()[1].message, "agreement 0.55");
  EXPECT_TRUE(w.Has("clock_offset_weak"));
  EXPECT_FALSE(w.Has("points_in_metres"));
}

TEST(WarningsTest, EchoesEachWarningAsAdded) {
  std::ostringstream err;
  Warnings w(&err);
  w.Add("a_code", "first");
  EXPECT_EQ(err.str(), "warning [a_code]: first\n");
  Warnings silent;
  silent.Add("b_code", "second");
  w.Append(silent);
  EXPECT_EQ(err.str(), "warning [a_code]: first\nwarning [b_code]: second\n");
  EXPECT_EQ(w.list().size(), 2u);
}

}  // namespace
}  // namespace kincal
