#ifndef KINCAL_VISION_POSE_UNCERTAINTY_H_
#define KINCAL_VISION_POSE_UNCERTAINTY_H_

// How well one frame's tool pose pins the needle tip: the covariance of the
// tip from the corner residuals of the pose fit (vision/tool_pose.h). With
// one camera the depth along the line of sight is what the view determines
// worst (the tags' apparent size gives it); a second camera's ray crossing
// the first pins it. `kincal track` reports the depth sigma so that a
// one-camera rig's tips carry their uncertainty.
//
// Method: Gauss-Newton covariance of the 6 pose parameters (rotation vector
// in the tool frame, translation in the rig frame) from the Jacobian of the
// used corners' projections (central differences), C = s^2 (J^T J)^-1, with
// s the per-coordinate pixel sigma; the tip's covariance is
// J_tip C J_tip^T.

#include <Eigen/Core>

#include "camcal/rig.h"
#include "vision/target.h"
#include "vision/tool_pose.h"

namespace kincal {

struct TipUncertainty {
  bool ok = false;  // false: no pose, or too few corners for 6 parameters
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();  // rig frame, mm^2
  // 1-sigma along the reference camera's line of sight to the tip, mm, and
  // the largest 1-sigma over all directions, mm.
  double depth_sigma_mm = 0;
  double max_sigma_mm = 0;
};

// `sigma_px`: 1-sigma of one corner coordinate (px), e.g. the fit's RMS per
// coordinate or a floor for a perfect fit.
TipUncertainty TipUncertaintyOf(const Rig& rig, const Target& target,
                                const ToolPoseResult& pose, double sigma_px);

}  // namespace kincal

#endif  // KINCAL_VISION_POSE_UNCERTAINTY_H_
