#ifndef KINCAL_CALIB_EXACT_JACOBIAN_H_
#define KINCAL_CALIB_EXACT_JACOBIAN_H_

// Residuals of measured rows and their exact Jacobian with respect to a
// chosen list of parameters, for the candidate refits of `diagnose model`.
//
// The derivatives use the chain's structure instead of differentiating it
// entry by entry: every row is a product of elementary rotations and
// translations (dh: Rz(theta + q) Tz(d) Tx(a) Rx(alpha) Ry(beta); mdh and
// urdf likewise), so d tip / d(rotation angle) = w x (tip - o) and
// d tip / d(translation) = w, with w the operation's axis and o its origin
// in the base frame (the product-of-exponentials derivative, exact). The
// joint-value hooks (gain, backlash, compliance, cyclic, elastostatic), the
// thermal row scaling, the mount tilt and the measuring frame enter by the
// chain rule, their own derivatives taken by forward-mode autodiff of the
// shared hooks (ModelJointValue*, MountTilt, ApplyFrame). The same forward
// pass gives the residual (rotations that do not depend on the pose and the
// measuring frame computed once per call). One pass per pose gives every
// column, against one autodiff pass per 8 parameters through the whole
// chain. `ExactJacobianTest` checks residuals and Jacobian against
// calib/fit.h's Residual and ResidualJacobian for dh, mdh and urdf chains
// with every family set.

#include <Eigen/Core>
#include <vector>

#include "calib/fit.h"
#include "calib/model_state.h"

namespace kincal {

// Residuals r (3 per measurement, model - measured, mm) and, when J is not
// null, dr / d params (internal units), 3 m x params.size(). Measured rows
// only (kMeasured); fixed-point rows give zero rows. `threads`: the poses
// shared among up to that many threads (blocks of at least 256 poses).
void ResidualsAndJacobian(const std::vector<Measurement>& measurements,
                          const ModelState& state,
                          const std::vector<ParamInfo>& params,
                          Eigen::VectorXd* r, Eigen::MatrixXd* J,
                          int threads = 1);

// J^T J, the rows of J cut into blocks on up to `threads` threads (each a
// symmetric rank update, the blocks then summed), symmetric in full.
Eigen::MatrixXd NormalMatrix(const Eigen::MatrixXd& J, int threads = 1);

}  // namespace kincal

#endif  // KINCAL_CALIB_EXACT_JACOBIAN_H_
