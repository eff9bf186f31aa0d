#ifndef KINCAL_SYNTH_FLANGE_SCENE_H_
#define KINCAL_SYNTH_FLANGE_SCENE_H_

// Cameras on the robot's flange (rig.yaml mount: flange) looking at a fixed
// board: where the board stands so that many of a set of poses see it, and
// which poses do. Used by the synthetic bundle fixture and by `simulate
// --render --render-mount flange`; each draws its own hidden mounting.

#include <Eigen/Core>
#include <vector>

#include "camcal/rig.h"
#include "data/rigid3.h"
#include "vision/target.h"

namespace kincal {

// Cameras on the flange (rig.yaml mount: flange) looking at a fixed board:
// where the board is and which poses see it.
struct FlangeBoardPlacement {
  Rigid3 base_from_board;
  std::vector<int> seen;  // indices into base_from_tip, in order
  double distance_mm = 0.0;
};

// The board `board` (a target whose tool frame is the board frame, tags on
// its z = 0 plane facing -z) placed for a rig at base_from_tip_i *
// tip_from_rig: its centre at the point that the most reference-camera
// views hold near their centre (within 0.6 of the half field of view) at
// 0.6..1.5 times `distance_mm` (candidates: the points distance_mm along
// each view's axis, at most ~2000 of them), facing those cameras on
// average; `seen` lists the poses that hold it so, view it within 60 deg of
// its normal and whose reference camera sees at least `min_tags` whole
// front-facing tags. Deterministic.
FlangeBoardPlacement PlaceBoardForFlangeRig(
    const std::vector<Eigen::Matrix4d>& base_from_tip, const Rig& rig,
    const Rigid3& tip_from_rig, const Target& board, double distance_mm,
    int min_tags);

// The poses (indices into base_from_tip, in order) that see the board at
// base_from_board as PlaceBoardForFlangeRig's `seen` says.
std::vector<int> PosesSeeingBoard(
    const std::vector<Eigen::Matrix4d>& base_from_tip, const Rig& rig,
    const Rigid3& tip_from_rig, const Target& board,
    const Rigid3& base_from_board, double distance_mm, int min_tags);

}  // namespace kincal

#endif  // KINCAL_SYNTH_FLANGE_SCENE_H_
