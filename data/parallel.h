#ifndef KINCAL_DATA_PARALLEL_H_
#define KINCAL_DATA_PARALLEL_H_

// Work shared among a few threads, for the dense solves on this project's
// small machines (2 cores): the candidate screening of `diagnose model`,
// the rows of a Jacobian, the columns of a projection.

#include <algorithm>
#include <atomic>
#include <exception>
#include <mutex>
#include <thread>
#include <utility>
#include <vector>

namespace kincal {

// Runs `work(i)` for i in [0, n) on up to `threads` threads (the calling
// one among them); each i once, in no particular order. An exception thrown
// by `work` stops the remaining indices and is rethrown here (the first
// one) after every thread has finished.
template <typename F>
void ParallelFor(int n, int threads, const F& work) {
  threads = std::max(1, std::min(threads, n));
  if (threads == 1) {
    for (int i = 0; i < n; ++i) work(i);
    return;
  }
  std::atomic<int> next(0);
  std::mutex error_mutex;
  std::exception_ptr error;
  const auto drain = [&] {
    for (int i = next++; i < n; i = next++) {
      try {
        work(i);
      } catch (...) {
        std::lock_guard<std::mutex> lock(error_mutex);
        if (!error) error = std::current_exception();
        next = n;
      }
    }
  };
  std::vector<std::thread> pool;
  for (int t = 1; t < threads; ++t) pool.emplace_back(drain);
  drain();
  for (std::thread& t : pool) t.join();
  if (error) std::rethrow_exception(error);
}

// The half-open ranges [begin, end) of `n` items cut into at most `parts`
// contiguous pieces of near-equal size (none empty), for ParallelFor over
// blocks of rows or columns.
inline std::vector<std::pair<int, int>> EvenRanges(int n, int parts) {
  parts = std::max(1, std::min(parts, n));
  std::vector<std::pair<int, int>> out;
  for (int p = 0; p < parts && n > 0; ++p)
    out.emplace_back(n * p / parts, n * (p + 1) / parts);
  return out;
}

}  // namespace kincal

#endif  // KINCAL_DATA_PARALLEL_H_
