#ifndef KINCAL_DIAGNOSE_PERIODIC_BASIS_H_
#define KINCAL_DIAGNOSE_PERIODIC_BASIS_H_

// The periodic transmission family's basis (calib/chain.h ChainRow::
// periodic_basis): a joint error over the whole revolution, a Fourier series
// of harmonics 1..kPeriodicHarmonics, fitted through the kMaxTransmissionTerms
// functions of it that the readings support best.
//
// Method: the Fourier terms f_t(q_i) at the readings, centred (the constant
// is the geometry's offset) and weighted by a smoothness prior w_h = h^-p
// (harmonic h), A = F_c W / sqrt(n). Its right singular vectors v_k, by
// singular value s_k (the RMS on the readings of the function W v_k, whose
// weighted coefficient norm is 1), give phi_k(q) = f(q) W v_k / s_k: the
// functions orthonormal on the readings, smoothest and best supported first.
// Only those with s_k >= min_support are kept (a function that is small on
// the readings and large elsewhere would carry the noise into the gaps and
// beyond the travel); the rest of the 24 columns are zero. The family's
// candidates take the first 8, 16, 24 (or as many as are supported) and the
// cross-validation of the selection chooses among them: that is the
// smoothness. With the functions orthonormal on the readings the fitted
// error's RMS over them (centred) is |c| (the catalogue's magnitude).

#include <array>
#include <vector>

#include "calib/chain.h"

namespace kincal {

struct PeriodicBasisOptions {
  // Exponent p of the smoothness prior w_h = h^-p: higher harmonics must be
  // better supported to enter. 1: a harmonic's weight falls as its period.
  double smoothness_power = 1.0;
  // Smallest RMS on the readings of a kept function whose weighted
  // coefficient norm is 1 (so its RMS over the whole revolution is at most
  // 1 / sqrt(2)): bounds how far one function can reach beyond the data.
  double min_support = 0.02;
  void Check() const;
};

struct PeriodicBasis {
  std::vector<double> basis;  // kPeriodicTerms x kMaxTransmissionTerms
  int supported = 0;          // non-zero columns (the first ones)
};

// The basis from one joint's readings (rad). Fewer than 3 distinct
// readings: no supported function.
PeriodicBasis MakePeriodicBasis(const std::vector<double>& q_rad,
                                const PeriodicBasisOptions& options = {});

// Number of non-zero columns of a row's periodic basis (0 without one).
int PeriodicSupport(const ChainRow& row);

// Where a joint's readings (rad) support a function of the angle: the
// arcs of the revolution (deg, lo < hi, lo in [-180, 180)) that lie
// farther than `max_gap_deg` from every reading, i.e. the gaps between
// readings wider than it, and the arc outside their travel.
std::vector<std::array<double, 2>> ExtrapolatedArcs(
    const std::vector<double>& q_rad, double max_gap_deg);

}  // namespace kincal

#endif  // KINCAL_DIAGNOSE_PERIODIC_BASIS_H_
