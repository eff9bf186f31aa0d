#include "bundle/cross_validation.h"

#include <cmath>
#include <string>

#include "data/error.h"

namespace kincal {
namespace {

double Rms(const std::vector<double>& v) {
  double s = 0;
  for (double x : v) s += x * x;
  return v.empty() ? 0.0 : std::sqrt(s / v.size());
}

}  // namespace

BundleCrossValidation CrossValidateBundle(
    const Robot& nominal, const Rig& rig, const Target& target,
    const std::vector<BundleFrame>& frames, const BundleOptions& options,
    int folds, const std::function<void(int, int)>& progress) {
  if (folds < 2) {
    throw InputError("--folds: expected at least 2, got " +
                     std::to_string(folds));
  }
  std::vector<double> px, mm;
  for (int k = 0; k < folds; ++k) {
    if (progress) progress(k, folds);
    BundleOptions fold_options = options;
    fold_options.folds = folds;
    fold_options.fold = k;
    const BundleResult fold =
        RunBundle(nominal, rig, target, frames, fold_options);
    px.insert(px.end(), fold.heldout_corner_px.begin(),
              fold.heldout_corner_px.end());
    mm.insert(mm.end(), fold.heldout_tip_mm.begin(), fold.heldout_tip_mm.end());
  }
  BundleCrossValidation cv;
  cv.folds = folds;
  cv.heldout_reproj_rms_px = Rms(px);
  cv.heldout_tip_rms_mm = Rms(mm);
  cv.heldout_tips = static_cast<int>(mm.size());
  return cv;
}

}  // namespace kincal
