#ifndef KINCAL_CALIB_HOLDOUT_H_
#define KINCAL_CALIB_HOLDOUT_H_

// The seeded hold-out every command uses: indices shuffled by
// std::shuffle with a std::mt19937_64, the first ones (or every k-th, for
// folds) held out of the fit to measure prediction error.

#include <cstdint>
#include <random>
#include <vector>

#include "calib/fit.h"

namespace kincal {

// Training and held-out indices, each in ascending order.
struct HoldoutSplit {
  std::vector<int> train, heldout;
};

// `indices` in the order std::shuffle gives them with `rng`: the order a
// seeded hold-out takes its held-out rows from.
std::vector<int> ShuffledIndices(std::vector<int> indices,
                                 std::mt19937_64* rng);

// The first `num_heldout` of ShuffledIndices(indices, rng) held out, the
// rest training (num_heldout is clamped to [0, indices.size()]).
HoldoutSplit HoldOutFirst(const std::vector<int>& indices, int num_heldout,
                          std::mt19937_64* rng);

// Fold `fold` of `folds`: the k-th of ShuffledIndices(indices,
// std::mt19937_64(seed)) is held out when k % folds == fold.
HoldoutSplit HoldOutFold(const std::vector<int>& indices, int folds, int fold,
                         uint64_t seed);

// Measurement indices split into training and held-out, seeded (one
// std::mt19937_64(seed) stream over the groups): the measured points of
// each series' frame (Measurement::frame) form one group, stratifying the
// split by series, each fixed point a group of its own; each group holds out
// round(fraction x its size) but keeps at least 10 (measured) or 3 (fixed
// point) training poses.
HoldoutSplit SplitHoldout(const std::vector<Measurement>& measurements,
                          double fraction, uint64_t seed);

// The measurements at `indices` (e.g. a split's training rows), in order.
std::vector<Measurement> PickRows(const std::vector<Measurement>& measurements,
                                  const std::vector<int>& indices);

}  // namespace kincal

#endif  // KINCAL_CALIB_HOLDOUT_H_
