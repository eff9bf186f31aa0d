#include "calib/holdout.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <utility>

namespace kincal {

std::vector<int> ShuffledIndices(std::vector<int> indices,
                                 std::mt19937_64* rng) {
  std::shuffle(indices.begin(), indices.end(), *rng);
  return indices;
}

HoldoutSplit HoldOutFirst(const std::vector<int>& indices, int num_heldout,
                          std::mt19937_64* rng) {
  const std::vector<int> order = ShuffledIndices(indices, rng);
  const int n = static_cast<int>(order.size());
  const int hold = std::max(0, std::min(num_heldout, n));
  HoldoutSplit split;
  for (int k = 0; k < n; ++k)
    (k < hold ? split.heldout : split.train).push_back(order[k]);
  std::sort(split.train.begin(), split.train.end());
  std::sort(split.heldout.begin(), split.heldout.end());
  return split;
}

HoldoutSplit HoldOutFold(const std::vector<int>& indices, int folds, int fold,
                         uint64_t seed) {
  std::mt19937_64 rng(seed);
  const std::vector<int> order = ShuffledIndices(indices, &rng);
  HoldoutSplit split;
  for (size_t k = 0; k < order.size(); ++k) {
    const bool held = folds > 0 && static_cast<int>(k % folds) == fold;
    (held ? split.heldout : split.train).push_back(order[k]);
  }
  std::sort(split.train.begin(), split.train.end());
  std::sort(split.heldout.begin(), split.heldout.end());
  return split;
}

HoldoutSplit SplitHoldout(const std::vector<Measurement>& measurements,
                          double fraction, uint64_t seed) {
  // (0, frame): the measured points of one series' frame; (1, point): the
  // rows at one fixed point.
  std::map<std::pair<int, int>, std::vector<int>> groups;
  for (size_t i = 0; i < measurements.size(); ++i) {
    const Measurement& m = measurements[i];
    const bool measured = m.kind == Measurement::kMeasured;
    groups[{measured ? 0 : 1, measured ? m.frame : m.point}].push_back(
        static_cast<int>(i));
  }
  std::mt19937_64 rng(seed);
  HoldoutSplit split;
  for (const auto& group : groups) {
    const int n = static_cast<int>(group.second.size());
    const int min_train = group.first.first == 0 ? 10 : 3;
    const int hold =
        std::min(static_cast<int>(std::lround(fraction * n)), n - min_train);
    const HoldoutSplit part = HoldOutFirst(group.second, hold, &rng);
    split.train.insert(split.train.end(), part.train.begin(), part.train.end());
    split.heldout.insert(split.heldout.end(), part.heldout.begin(),
                         part.heldout.end());
  }
  std::sort(split.train.begin(), split.train.end());
  std::sort(split.heldout.begin(), split.heldout.end());
  return split;
}

std::vector<Measurement> PickRows(const std::vector<Measurement>& measurements,
                                  const std::vector<int>& indices) {
  std::vector<Measurement> out;
  out.reserve(indices.size());
  for (int i : indices) out.push_back(measurements[i]);
  return out;
}

}  // namespace kincal
