// Tests of the terminal progress line (data/progress.cc): what it draws on
// stderr, and when it stays silent.

#include "data/progress.h"

#include <gtest/gtest.h>

#include <cstdlib>

namespace kincal {
namespace {

// stderr while `f` runs.
template <typename F>
std::string StderrOf(F f) {
  ::testing::internal::CaptureStderr();
  f();
  return ::testing::internal::GetCapturedStderr();
}

TEST(ProgressTest, ForcedOnDrawsStagesCountsAndClears) {
  ::setenv("KINCAL_PROGRESS", "1", 1);
  const std::string out = StderrOf([] {
    Progress p("kincal test", false);
    EXPECT_TRUE(p.enabled());
    p.Stage("fitting");
    p.Update(3, 4, "frames");
    p.Update(4, 4, "frames");  // the last one is always drawn
  });
  ::unsetenv("KINCAL_PROGRESS");
  EXPECT_NE(out.find("kincal test: fitting ..."), std::string::npos) << out;
  EXPECT_NE(out.find("kincal test: frames 4/4 (100 %)"), std::string::npos)
      << out;
  // Cleared at the end: the output ends with the erase sequence.
  EXPECT_EQ(out.substr(out.size() - 4), "\r\033[K");
}

TEST(ProgressTest, QuietOrForcedOffOrPipedDrawsNothing) {
  ::setenv("KINCAL_PROGRESS", "1", 1);
  std::string out = StderrOf([] {
    Progress p("kincal test", true);  // --json
    EXPECT_FALSE(p.enabled());
    p.Stage("x");
  });
  EXPECT_EQ(out, "");
  ::setenv("KINCAL_PROGRESS", "0", 1);
  out = StderrOf([] {
    Progress p("kincal test", false);
    EXPECT_FALSE(p.enabled());
    p.Update(1, 2);
  });
  EXPECT_EQ(out, "");
  ::unsetenv("KINCAL_PROGRESS");
  // Captured stderr is not a terminal.
  out = StderrOf([] {
    Progress p("kincal test", false);
    EXPECT_FALSE(p.enabled());
    p.Stage("x");
  });
  EXPECT_EQ(out, "");
}

}  // namespace
}  // namespace kincal
