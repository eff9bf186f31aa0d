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
  // Each tag observation (one tag in one camera) is judged on its own, so a
  // badly lit or oblique tag costs that tag, not the frame:
  //  - before the fit, one whose edges have a contrast under min_contrast
  //    gray levels (TagSideQuality::contrast, the weakest side) is left out
  //    ("contrast");
  //  - before the fit, one the detector's edge refinement could not refine
  //    (libapriltag's corners) is left out while refined ones determine the
  //    pose ("unrefined");
  //  - after the fit, the worst is left out while its corner RMS exceeds
  //    max(outlier_px, outlier_ratio * median tag RMS) ("residual"), the
  //    fit redone each time; between outlier_px and hard_outlier_px only
  //    while the remaining tags still determine the pose: two tag
  //    observations or more, in every camera that had one. A tag over
  //    hard_outlier_px goes whatever remains.
  double outlier_px = 0.5;
  double hard_outlier_px = 1.5;
  double outlier_ratio = 5.0;
  double min_contrast = 12.0;
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
  // Why it was left out (empty when used): "contrast" (its edges too faint
  // to measure), "corners" (fewer than 3 corners the detector trusts
  // (TagDetection::usable) or that fit the pose), "unrefined" (the edge
  // refinement failed on it while other tags were refined), "residual"
  // (its corners disagree with the other tags' pose).
  std::string left_out;
  double contrast = 0;       // weakest side's white - black, gray levels
  double obliquity_deg = 0;  // angle between its normal and the view ray
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

// track's quality gate for a tip: a pose was found from at least `min_tags`
// tag observations, fits them within `max_reproj_px` RMS, and with a rig
// of two or more cameras uses tags seen by at least two of them (a frame
// seen by one camera of a stereo rig has a weak depth, tens of mm at 2 m,
// where the rig's other frames have a fraction of a mm). A one-camera rig
// has nothing better: its tips are valid with their depth sigma.
bool PassesTrackGate(const ToolPoseResult& r, size_t num_cameras, int min_tags,
                     double max_reproj_px);

// Initial pose only (triangulation + Kabsch, or PnP); false when no tag of
// the target is seen. Exposed for tests.
bool InitialToolPose(const Rig& rig, const Target& target,
                     const std::vector<std::vector<TagDetection>>& detections,
                     Rigid3* rig_from_tool);

}  // namespace kincal

#endif  // KINCAL_VISION_TOOL_POSE_H_
