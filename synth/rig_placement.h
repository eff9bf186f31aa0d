#ifndef KINCAL_SYNTH_RIG_PLACEMENT_H_
#define KINCAL_SYNTH_RIG_PLACEMENT_H_

// Where a simulated stereo rig stands: looking at the centroid of the tips
// along the mean direction the tags face away from (so they face the
// cameras on average), far enough that a chosen share of the tips lies in
// the central 80 % of the first camera's view, and no nearer than the
// target's working distance.

#include <Eigen/Core>
#include <vector>

#include "camcal/camera_model.h"
#include "camcal/rig.h"

namespace kincal {

// rig_from_base for tips at `base_from_tip` with the tool mounted as
// `tip_from_tool`. `in_view` in (0, 1]: the share of tips that must be in
// view (1: all; 0.9: the rest may leave the image, as on a real rig).
// `distance_mm` (may be null) receives the distance from the centroid.
Rigid3 PlaceRigFacingTips(const std::vector<Eigen::Matrix4d>& base_from_tip,
                          const Rig& rig, const Rigid3& tip_from_tool,
                          double in_view, double* distance_mm = nullptr);

// A rig of `num_cameras` (1..3) cameras from a stereo rig (ExampleStereoRig):
// 1 = its first camera alone; 2 = the pair; 3 = the pair and a third
// camera "top", a copy of the first 120 mm above it (rig -y), turned down
// towards the point `aim_mm` in front of the first camera. InputError for
// another count or a rig without two cameras.
Rig RigWithCameras(const Rig& stereo, int num_cameras, double aim_mm);

}  // namespace kincal

#endif  // KINCAL_SYNTH_RIG_PLACEMENT_H_
