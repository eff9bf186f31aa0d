#ifndef KINCAL_DATA_MEDIAN_H_
#define KINCAL_DATA_MEDIAN_H_

// The median the robust scales of this project use (corner errors, edge
// residuals, pivot residuals): the upper median, one element of the data.

#include <algorithm>
#include <vector>

namespace kincal {

// Element size / 2 of `v` in sorted order (for an even count the upper of
// the two middle values); 0 for an empty `v`.
inline double UpperMedian(std::vector<double> v) {
  if (v.empty()) return 0.0;
  const auto mid = v.begin() + v.size() / 2;
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

}  // namespace kincal

#endif  // KINCAL_DATA_MEDIAN_H_
