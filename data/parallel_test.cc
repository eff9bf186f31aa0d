#include "data/parallel.h"

#include <gtest/gtest.h>

#include <atomic>
#include <mutex>
#include <numeric>
#include <set>
#include <stdexcept>
#include <thread>

namespace kincal {
namespace {

TEST(ParallelForTest, RunsEveryIndexOnceOnSeveralThreads) {
  for (int threads : {1, 2, 3, 8}) {
    std::vector<std::atomic<int>> seen(101);
    for (auto& s : seen) s = 0;
    std::mutex m;
    std::set<std::thread::id> ids;
    ParallelFor(101, threads, [&](int i) {
      seen[i]++;
      std::lock_guard<std::mutex> lock(m);
      ids.insert(std::this_thread::get_id());
    });
    for (int i = 0; i < 101; ++i) EXPECT_EQ(seen[i], 1) << i;
    EXPECT_LE(static_cast<int>(ids.size()), threads);
    if (threads == 1) {
      EXPECT_EQ(ids.count(std::this_thread::get_id()), 1u);
    }
  }
  int calls = 0;
  ParallelFor(0, 2, [&](int) { ++calls; });
  EXPECT_EQ(calls, 0);
}

TEST(ParallelForTest, RethrowsTheWorksExceptionAfterEveryThreadEnds) {
  for (int threads : {1, 2}) {
    std::atomic<int> done(0);
    EXPECT_THROW(ParallelFor(50, threads,
                             [&](int i) {
                               if (i == 7) throw std::runtime_error("seven");
                               ++done;
                             }),
                 std::runtime_error);
    EXPECT_LT(done.load(), 50);
  }
}

TEST(ParallelForTest, EvenRangesCoverTheItemsInNearEqualPieces) {
  EXPECT_TRUE(EvenRanges(0, 2).empty());
  const auto one = EvenRanges(1, 4);
  ASSERT_EQ(one.size(), 1u);
  EXPECT_EQ(one[0], std::make_pair(0, 1));
  const auto r = EvenRanges(10, 3);
  ASSERT_EQ(r.size(), 3u);
  EXPECT_EQ(r[0], std::make_pair(0, 3));
  EXPECT_EQ(r[1], std::make_pair(3, 6));
  EXPECT_EQ(r[2], std::make_pair(6, 10));
}

}  // namespace
}  // namespace kincal
