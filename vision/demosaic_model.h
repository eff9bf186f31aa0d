#ifndef KINCAL_VISION_DEMOSAIC_MODEL_H_
#define KINCAL_VISION_DEMOSAIC_MODEL_H_

// The edge model of a linearly demosaiced image (a colour camera's driver
// demosaics its Bayer mosaic and converts it to gray): each gray pixel is a
// known weighted sum of its 3x3 neighbours' raw samples, each raw sample is
// the pixel-integrated, blurred scene times its channel's gain. For a
// bilinear demosaic (at a green site red and blue are the means of the two
// neighbours that sampled them; at a red or blue site green is the mean of
// the four neighbours, the other colour of the four diagonals) followed by
// gray = wR R + wG G + wB B, a pixel's kernel depends only on its phase and
// on the shares of the gray the three channels carry (wR gR, wG gG, wB gB,
// normalised: two unknowns, the same for every tag under one light).
//
// So the profile across a tag's side at a pixel with offset o is
//   m(o) = sum_taps w_phase(d) * p(o + n.d)
// with p the pattern model of vision/edge_profile.h (one round optical
// blur, the pixel box) and n the side's outward normal: the demosaic's
// non-round, phase-dependent 3-tap kernels are in the model instead of
// being approximated by a Gaussian per phase.

#include <Eigen/Core>
#include <array>
#include <vector>

#include "vision/edge_profile.h"

namespace kincal {

// A linear demosaic to gray: per Bayer phase ((x % 2) + 2 (y % 2)) the
// weights of the pixel's 3x3 neighbourhood, index (dy + 1) * 3 + (dx + 1).
struct DemosaicKernels {
  std::array<std::array<double, 9>, 4> weights{};
};

// Bilinear demosaic to gray of a Bayer mosaic. The two green photosites of
// each 2x2 cell lie on a diagonal: phases 1 and 2 (RGGB, BGGR) or 0 and 3
// (GRBG, GBRG); the other two carry colours "a" (phase 0, resp. 1) and "b"
// (phase 3, resp. 2). share_a and share_b: the parts of a flat gray
// scene's gray value that the two colours carry (green the rest).
struct BilinearDemosaic {
  bool greens_on_03 = false;
  double share_a = 0.2;
  double share_b = 0.1;
  DemosaicKernels Kernels() const;
};

// A side's profiles (read at pixel centres with their phases, EdgeProfile
// box_px set) and its outward normal.
struct DemosaicSide {
  const std::vector<EdgeProfile>* profiles = nullptr;
  Eigen::Vector2d normal = Eigen::Vector2d::Zero();
};

// FitEdgeProfile (edge_profile.h) with the demosaic's kernels: sample i is
// the kernels[phase_i]-weighted sum of the blurred pattern at the
// neighbouring pixel centres (offsets o_i + n.d). Same result fields.
EdgeProfileFit FitDemosaicedProfile(const EdgeProfile& profile,
                                    const Eigen::Vector2d& normal,
                                    const DemosaicKernels& kernels,
                                    double sigma_px, int iterations = 6,
                                    double max_shift_px = 2.0);

// The blur that fits the sides' profiles best with these kernels (golden
// section on log sigma in [0.2, 3] px, 8 steps; at most `max_profiles`
// profiles, evenly spaced). *cost (if given): the sum of squared residual
// RMS of those profiles at that blur.
double DemosaicedBlur(const std::vector<DemosaicSide>& sides,
                      const DemosaicKernels& kernels, int max_profiles = 16,
                      double* cost = nullptr);

struct BilinearDemosaicFit {
  BilinearDemosaic model;
  double cost = 0;  // sum over the groups of DemosaicedBlur's cost
};

// The bilinear demosaic that fits groups of sides (each group sharing one
// blur, e.g. a tag's four sides) best: both green layouts from equal
// shares, then the shares by coordinate descent (golden section, each in
// [0.01, 0.6]), the groups' blurs refitted between the rounds.
BilinearDemosaicFit FitBilinearDemosaic(
    const std::vector<std::vector<DemosaicSide>>& groups);

}  // namespace kincal

#endif  // KINCAL_VISION_DEMOSAIC_MODEL_H_
