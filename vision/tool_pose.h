#ifndef KINCAL_VISION_TOOL_POSE_H_
#define KINCAL_VISION_TOOL_POSE_H_

// The tool's pose in the rig frame from the tag corners detected in every
// camera: an initial value from triangulated corners (or PnP when no tag is
// seen twice), then a small Ceres fit of rig_from_tool over all corners of
// all views, with rejection of tag observations whose residual is too large.
// The needle tip is rig_from_tool * tip_in_tool.

#include <Eigen/Core>
#include <array>
#include <string>
#include <vector>

#include "camcal/rig.h"
#include "vision/apriltag_detector.h"
#include "vision/target.h"

namespace kincal {

struct ToolPoseOptions {
  // A tag observation (one tag in one camera) is rejected when its corner RMS
  // exceeds max(outlier_px, outlier_ratio * median tag RMS); the worst goes
  // first, then the fit is redone.
  double outlier_px = 1.5;
  double outlier_ratio = 5.0;
  // Per corner, after the robust first fit: a corner whose residual exceeds
  // max(corner_outlier_px, outlier_ratio * median corner residual) goes back
  // to libapriltag's corner (TagDetection::detector_corners) if that fits
  // better, and is left out otherwise (a tag keeps >= 3 corners or is out).
  double corner_outlier_px = 0.3;
  // Huber scale of the first fit (px); the final fit is plain least squares.
  double huber_px = 2.0;
  int min_tag_observations = 1;
  int max_iterations = 50;

  void Check() const;  // InputError naming the bad option
};

// One tag observation that took part in (or was removed from) the fit.
struct TagObservationResult {
  int camera = 0;
  int tag_id = 0;
  double rms_px = 0;  // corner RMS against the final pose
  bool used = false;
  // Corners that took part (the per-corner check may leave some out) and
  // the pixels used for them (refined, or libapriltag's).
  std::array<bool, 4> corner_used = {true, true, true, true};
  std::array<Eigen::Vector2d, 4> corners_px;
};

struct ToolPoseResult {
  bool found = false;
  std::string why_not;  // when !found
  Rigid3 rig_from_tool;
  Eigen::Vector3d tip_in_rig = Eigen::Vector3d::Zero();
  double rms_px = 0;  // sqrt(mean |corner residual|^2) over used corners
  int tags_used = 0;  // tag observations (tag x camera) in the final fit
  std::vector<TagObservationResult> tags;
};

// detections[c] are camera c's detections (same order as rig.cameras).
// Tags not in the target, or detected twice in one camera, are ignored.
ToolPoseResult EstimateToolPose(
    const Rig& rig, const Target& target,
    const std::vector<std::vector<TagDetection>>& detections,
    const ToolPoseOptions& options = ToolPoseOptions());

// Initial pose only (triangulation + Kabsch, or PnP); false when no tag of
// the target is seen. Exposed for tests.
bool InitialToolPose(const Rig& rig, const Target& target,
                     const std::vector<std::vector<TagDetection>>& detections,
                     Rigid3* rig_from_tool);

}  // namespace kincal

#endif  // KINCAL_VISION_TOOL_POSE_H_
