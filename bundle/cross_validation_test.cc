#include "bundle/cross_validation.h"

#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include "bundle/testing/synthetic.h"
#include "data/error.h"
#include "tests/testing/paths.h"

namespace kincal {
namespace {

SyntheticBundle Session(double noise_px) {
  SyntheticBundleOptions so;
  so.frames = 30;
  so.noise_px = noise_px;
  so.seed = 21;
  return MakeSyntheticBundle(
      ReadRobotYaml(testing::SourceDir() + "/data/robots/bh7.yaml"), so);
}

// Pools exactly what the folds hold out: every frame with corners is held
// out once, and the pooled RMS is that of the folds' held-out corners.
TEST(BundleCrossValidation, PoolsEveryFoldsHeldOutCorners) {
  const SyntheticBundle s = Session(0.1);
  BundleOptions o;
  const int folds = 3;
  std::vector<int> progress_calls;
  const BundleCrossValidation cv = CrossValidateBundle(
      s.nominal, s.rig, s.target, s.frames, o, folds, [&](int k, int n) {
        EXPECT_EQ(n, folds);
        progress_calls.push_back(k);
      });
  EXPECT_EQ(progress_calls, (std::vector<int>{0, 1, 2}));
  EXPECT_EQ(cv.folds, folds);

  std::set<int> held;
  double sum_px = 0;
  size_t corners = 0;
  int tips = 0;
  for (int k = 0; k < folds; ++k) {
    BundleOptions fo = o;
    fo.folds = folds;
    fo.fold = k;
    const BundleResult r = RunBundle(s.nominal, s.rig, s.target, s.frames, fo);
    for (int i : r.heldout) EXPECT_TRUE(held.insert(i).second) << i;
    for (double e : r.heldout_corner_px) sum_px += e * e;
    corners += r.heldout_corner_px.size();
    tips += r.heldout_tips;
  }
  EXPECT_EQ(held.size(), s.frames.size());
  ASSERT_GT(corners, 0u);
  EXPECT_DOUBLE_EQ(cv.heldout_reproj_rms_px, std::sqrt(sum_px / corners));
  EXPECT_EQ(cv.heldout_tips, tips);
  // 0.1 px corner noise: held-out corners of a good model near that.
  EXPECT_GT(cv.heldout_reproj_rms_px, 0.05);
  EXPECT_LT(cv.heldout_reproj_rms_px, 0.5);
}

TEST(BundleCrossValidation, FewerThanTwoFoldsIsBadInput) {
  const SyntheticBundle s = Session(0.0);
  EXPECT_THROW(CrossValidateBundle(s.nominal, s.rig, s.target, s.frames,
                                   BundleOptions(), 1),
               InputError);
}

}  // namespace
}  // namespace kincal
