#ifndef KINCAL_BUNDLE_ROBOT_RECORD_H_
#define KINCAL_BUNDLE_ROBOT_RECORD_H_

// The record the bundle's calibrated robot file carries (robot.yaml
// `nominal:`, `fitted_on:`, `covariance:`; calib/fit_record.h writes it, as
// for calibrate), so `compensate` can predict each target's sigma and flag
// readings outside the travel the bundle was fitted on.
//
// The bundle's measuring frame is the frame its tips are given in: on a
// stand the rig (the reference camera), `frame` = rig_from_base; with the
// cameras on the flange the fixed target, `frame` = target_from_base (the
// rig origin, where the tool row ends, is measured in it). The covariance
// names that frame (frame.*), the fitted parameters (geometry and
// extensions, e.g. j3.backlash) and the tool row's position, which the
// bundle does not fit directly but sets from a frame: tip_in_flange =
// flange_from_tool * tip_in_tool on a stand, the rig origin
// (flange_from_rig's translation) on the flange.

#include <Eigen/Core>
#include <string>
#include <vector>

#include "bundle/bundle.h"
#include "calib/model_state.h"
#include "data/robot.h"
#include "vision/target.h"

namespace kincal {

struct BundleRobotCovariance {
  // frame.rx .. frame.z, the fitted parameters in BundleResult::params'
  // order, then the tool row's position parameters (GeometryParams' names).
  std::vector<ParamInfo> params;
  Eigen::MatrixXd covariance;  // internal units (rad, mm, ...), params' order
};

// The tool row's parameters that place its origin (the bundle sets them from
// a frame, the others stay nominal): dh theta, d, a; mdh d, a, alpha; urdf
// x, y, z (ChainRow::p indices).
std::vector<int> ToolRowPositionIndices(Convention convention);

// The covariance of the robot file's parameters from the bundle's
// (BundleResult::covariance: params, then the fitted frames A and B):
// C_out = L C L^T with L the derivative of [measuring frame, params, tool
// row position] by [params, A, B]: the identity for the fitted parameters,
// the frame's dependence on A (stand, the identity) or B (flange, B^-1), and
// for the tool row D^+ dtip/d(B | A) with D the derivative of the tool row's
// origin by its position parameters (central differences). Empty params
// when the bundle has no covariance.
BundleRobotCovariance RobotFileCovariance(const BundleResult& result,
                                          const Target& target);

// `result->calibrated` with its record (calib/fit_record.h WithFitRecord):
// `nominal`'s rows; the travel of `fitted` (indices into `frames`: the
// training frames whose corners the final fit used; held-out frames are not
// fitted on, as in calibrate); the measuring frame; the held-out tip RMS
// (NaN without held-out tips); RobotFileCovariance.
void RecordBundleFit(const Robot& nominal,
                     const std::vector<BundleFrame>& frames,
                     const std::vector<int>& fitted, const Target& target,
                     BundleResult* result);

}  // namespace kincal

#endif  // KINCAL_BUNDLE_ROBOT_RECORD_H_
