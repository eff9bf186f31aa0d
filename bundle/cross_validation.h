#ifndef KINCAL_BUNDLE_CROSS_VALIDATION_H_
#define KINCAL_BUNDLE_CROSS_VALIDATION_H_

// k-fold cross-validation of the bundle: the bundle is solved k times, fold
// k holding out the frames that BundleOptions::folds / fold select (a seeded
// shuffle of the frames with corners; every such frame is held out exactly
// once), and the held-out corners and tips of all folds are pooled.

#include <functional>
#include <vector>

#include "bundle/bundle.h"
#include "camcal/rig.h"
#include "data/robot.h"
#include "vision/target.h"

namespace kincal {

struct BundleCrossValidation {
  int folds = 0;
  double heldout_reproj_rms_px = 0.0;  // over every held-out corner
  double heldout_tip_rms_mm = 0.0;     // over every held-out tracked tip
  int heldout_tips = 0;
};

// Runs RunBundle `folds` times (folds >= 2; InputError otherwise) with
// `options` but for folds/fold. `progress(k, folds)` is called before fold
// k when set.
BundleCrossValidation CrossValidateBundle(
    const Robot& nominal, const Rig& rig, const Target& target,
    const std::vector<BundleFrame>& frames, const BundleOptions& options,
    int folds, const std::function<void(int, int)>& progress = {});

}  // namespace kincal

#endif  // KINCAL_BUNDLE_CROSS_VALIDATION_H_
