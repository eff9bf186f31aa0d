#ifndef KINCAL_DIAGNOSE_STATISTICS_H_
#define KINCAL_DIAGNOSE_STATISTICS_H_

// Statistics of the model selection (diagnose/model_diagnosis.cc): the F
// distribution, column spans for identifiability, noise estimators, and a
// small thread pool for independent candidate fits.

#include <Eigen/Core>
#include <algorithm>
#include <vector>

#include "calib/fit.h"
#include "calib/model_state.h"
#include "data/parallel.h"

namespace kincal {

// log P(F > f) for F(d1, d2) (in logs so that strong effects still rank).
double LogFUpperTail(double f, double d1, double d2);
// Upper tail of the F(d1, d2) distribution: P(F > f).
double FDistributionUpperTail(double f, double d1, double d2);

// Column-normalised Jacobian columns; zero columns stay zero.
Eigen::MatrixXd Normalized(Eigen::MatrixXd j);
// Orthonormal basis of the column span of `a` (QR; rank-revealing where the
// columns come near dependence), on up to `threads` threads.
Eigen::MatrixXd Basis(const Eigen::MatrixXd& a, int threads = 1);
// Which columns of `cand` (normalised) keep a part outside the span of
// `basis` and of the candidate's earlier accepted columns (sine > 1e-5).
std::vector<bool> IndependentColumns(const Eigen::MatrixXd& basis,
                                     const Eigen::MatrixXd& cand);
// The same in two parts, so that many candidates share one projection: the
// normalised columns minus their part in the span of `basis`, then which of
// those keep a part outside the earlier accepted ones. `threads`: blocks of
// columns projected in parallel.
Eigen::MatrixXd ProjectedOffBasis(const Eigen::MatrixXd& basis,
                                  const Eigen::MatrixXd& cand, int threads = 1);
std::vector<bool> IndependentProjectedColumns(const Eigen::MatrixXd& rest);
// True when every column of `cand` is independent of `basis`.
bool IdentifiableAgainst(const Eigen::MatrixXd& basis,
                         const Eigen::MatrixXd& cand);

// The per-axis noise from rows with identical joint readings; 0 when there
// are too few repeats (fewer than 6 degrees of freedom).
double RepeatedPoseNoise(const std::vector<Measurement>& ms);
// An upper bound on the per-axis noise from the model residuals of pose
// pairs that are nearest neighbours in joint space (docs/DIAGNOSE.md).
double NearestPoseNoise(const ModelState& state,
                        const std::vector<Measurement>& ms);

}  // namespace kincal

#endif  // KINCAL_DIAGNOSE_STATISTICS_H_
