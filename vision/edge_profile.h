#ifndef KINCAL_VISION_EDGE_PROFILE_H_
#define KINCAL_VISION_EDGE_PROFILE_H_

// The intensity profile across one side of a tag, fitted with a model of
// the tag's own pattern along that line (vision/apriltag_detector.cc's edge
// refinement). The model is the printed pattern, blurred:
//
//   m(o) = sum_segments level[class] * (Phi((o - e - lo) / sigma)
//                                       - Phi((o - e - hi) / sigma))
//
// o: offset along the side's outward normal (px, 0 = the side as
// currently placed); the segments [lo, hi) are the pattern along that line
// (black square, its data bits, the white border, the outside) with class
// 0 = black, 1 = white, 2 = outside the tag; e: the shift of the pattern
// (the edge correction sought); sigma: a Gaussian blur shared by the side.
// The three levels are solved per profile (linear least squares for a given
// e), so uneven light across and between tags, a shadow, vignetting or a
// dim tag change the levels, not the edge; the neighbouring data bits and
// the white border's outer edge are in the model instead of biasing the
// edge, as they do in an area rule or a gradient centroid under wide blur.
// e is found by Gauss-Newton with the levels projected out.

#include <Eigen/Core>
#include <array>
#include <functional>
#include <vector>

namespace kincal {

// One line's pattern (as EdgeProfile's breaks and classes) with its weight
// in a mixture.
struct PatternLine {
  std::vector<double> breaks;
  std::vector<int> classes;
  double weight = 1;
};

struct EdgeProfile {
  std::vector<double> offsets;  // px along the outward normal
  std::vector<double> values;   // gray levels at those offsets
  // Pattern: classes[i] holds between breaks[i - 1] and breaks[i]
  // (classes.size() == breaks.size() + 1; the first and last extend to
  // -inf and +inf).
  std::vector<double> breaks;
  std::vector<int> classes;  // 0 black, 1 white, 2 outside
  // Per sample, the Bayer phase of the pixel it was read at ((x % 2) +
  // 2 (y % 2)), for a demosaiced image whose four phases have their own
  // blur (FitEdgeProfile's sigma per phase); empty: one blur for all.
  std::vector<int> phases;
  // Width of a pixel's box along the normal, px, when the samples are
  // pixel values (read at pixel centres): the model's step is then also
  // averaged over that box (a pixel integrates the light over its area);
  // 0 for interpolated samples.
  double box_px = 0;
  // The blur along the side mixes the patterns of the neighbouring lines
  // (across a data bit's edge, near the square's corner) into this one:
  // when not empty, the model is the weighted sum (weights summing to 1)
  // of these lines' patterns blurred across, instead of breaks/classes
  // alone. For a Gaussian blur that is exact (the blur separates into
  // along and across).
  std::vector<PatternLine> mixture;
};

// Gaussian blur per Bayer phase (index (x % 2) + 2 (y % 2)), px.
using PhaseSigmas = std::array<double, 4>;

struct EdgeProfileFit {
  bool ok = false;
  double shift_px = 0;                // e
  std::array<double, 3> levels = {};  // black, white, outside
  double rms = 0;                     // residual RMS, gray levels
};

// Fits e (starting at 0, each step clamped to +-0.5 px, at most
// `iterations` steps) for a given sigma. Not ok when the profile is too
// short, the black and white levels are not apart, or e leaves +-max_shift.
EdgeProfileFit FitEdgeProfile(const EdgeProfile& profile, double sigma_px,
                              int iterations = 6, double max_shift_px = 2.0);
// The same with a blur per phase: sample i is blurred by
// sigma_px[profile.phases[i]] (sigma_px[0] for all when phases is empty).
// A demosaic's per-phase kernels are symmetric about their pixel but of
// different widths; one blur for all would make the profile look skewed
// wherever the phases left and right of the edge differ, and shift it.
EdgeProfileFit FitEdgeProfile(const EdgeProfile& profile,
                              const PhaseSigmas& sigma_px, int iterations = 6,
                              double max_shift_px = 2.0);

// A model's sums over a profile's samples at shift e, from which the
// levels L and the Gauss-Newton step on e follow (b: the basis of the
// three classes at a sample, db its derivative in e, v the sample):
// B = sum b b^T (plus a tiny ridge for classes the profile does not
// reach), D = sum db b^T, DD = sum db db^T, bv = sum b v, dv = sum db v,
// vv = sum v^2. Then B L = bv, and with r = v - b.L, j = -db.L:
// SSE = vv - 2 L.bv + L^T B L, sum j j = L^T DD L, sum j r = -L.dv + L^T D L.
struct EdgeProfileSums {
  Eigen::Matrix3d B = Eigen::Matrix3d::Zero(), D = Eigen::Matrix3d::Zero(),
                  DD = Eigen::Matrix3d::Zero();
  Eigen::Vector3d bv = Eigen::Vector3d::Zero(), dv = Eigen::Vector3d::Zero();
  double vv = 0;

  // One sample: its basis b, db/de and value v.
  void Add(const Eigen::Vector3d& b, const Eigen::Vector3d& db, double v) {
    B.noalias() += b * b.transpose();
    D.noalias() += db * b.transpose();
    DD.noalias() += db * db.transpose();
    bv += b * v;
    dv += db * v;
    vv += v * v;
  }
  // The tiny ridge, after the last sample.
  void AddRidge() { B += Eigen::Matrix3d::Identity() * 1e-6; }
};

// The shift e by Gauss-Newton from 0 with the levels projected out, for any
// model whose sums at e `sums_at` gives (FitEdgeProfile's, or a demosaic's,
// vision/demosaic_model.h): each step clamped to +-0.5 px, at most
// `iterations` steps, not ok when e leaves +-max_shift_px or the black and
// white levels are less than 5 apart; rms over `samples` samples.
EdgeProfileFit FitShiftFromSums(
    const std::function<EdgeProfileSums(double)>& sums_at, size_t samples,
    int iterations, double max_shift_px);

// The area rule on the profile's samples (linearly interpolated) over
// [centre - w, centre + w]: edge = centre + w - integral (v - inside) /
// (outside - inside) do, with `inside` and `outside` the levels either side
// of the edge (from a fit). Exact for any symmetric blur of an isolated
// step and for pixel integration, which the Gaussian model is not when an
// edge is sharp (sigma < 0.8 px: the sampled profile's shape then depends on
// the edge's phase within a pixel); used there, where the neighbours' edges
// stay outside the window.
double AreaRuleShift(const EdgeProfile& profile, double inside, double outside,
                     double centre, double w);
// The same rule from the area over [centre - w, centre + w] already known.
double AreaRuleShiftFromArea(double area, double inside, double outside,
                             double centre, double w);

// The model's gray levels at `offsets` for the pattern of `profile`, shift
// e, blur sigma and the levels (black, white, outside) of a fit.
std::vector<double> EdgeProfileModel(const EdgeProfile& profile,
                                     const std::vector<double>& offsets,
                                     double shift_px, double sigma_px,
                                     const std::array<double, 3>& levels);

// The integral of that model over [lo, hi] (closed form: with
// G(x) = x Phi(x) + phi(x), the integral of Phi((o - c) / sigma) is
// sigma G((o - c) / sigma)).
double EdgeProfileModelArea(const EdgeProfile& profile, double lo, double hi,
                            double shift_px, double sigma_px,
                            const std::array<double, 3>& levels);

// The model's basis at offset o for shift e and blur sigma: per class
// (black, white, outside) its weight in m(o) (the box-averaged step when
// box_px > 0), and the derivative of that by e. For models built from the
// same pattern (vision/demosaic_model.h).
void EdgeProfileBasis(const EdgeProfile& profile, double offset,
                      double shift_px, double sigma_px, Eigen::Vector3d* basis,
                      Eigen::Vector3d* d_basis_d_shift);

// Standard normal CDF from a table (|error| < 2e-5), for the model's speed.
double FastPhi(double x);

}  // namespace kincal

#endif  // KINCAL_VISION_EDGE_PROFILE_H_
