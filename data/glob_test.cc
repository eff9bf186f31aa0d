#include "data/glob.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>

#include "data/error.h"
#include "tests/testing/paths.h"

namespace kincal {
namespace {

TEST(GlobTest, SortedByNameAndEmptyWhenNothingMatches) {
  const std::string dir = testing::MakeTempDir("glob");
  for (const char* name : {"b_010.png", "a_2.png", "b_002.png", "c.txt"}) {
    std::ofstream(dir + "/" + name) << "x";
  }
  EXPECT_EQ(GlobSorted(dir + "/*.png"),
            (std::vector<std::string>{dir + "/a_2.png", dir + "/b_002.png",
                                      dir + "/b_010.png"}));
  EXPECT_TRUE(GlobSorted(dir + "/*.jpg").empty());
  try {
    GlobSortedOrThrow(dir + "/*.jpg", "--left");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), ::testing::HasSubstr("--left '"));
    EXPECT_THAT(e.what(), ::testing::HasSubstr("no file matches"));
  }
}

}  // namespace
}  // namespace kincal
