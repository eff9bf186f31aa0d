#ifndef KINCAL_VISION_TARGET_LAYOUT_H_
#define KINCAL_VISION_TARGET_LAYOUT_H_

// Measuring a tool target: the poses of the AprilTags on a holder, from a
// recorded session of the tool (hand-held or on a robot, 10+ views), with no
// prior layout, only the tag family and size.
//
// Steps:
//  1. every tag's pose in the rig at every frame, from its own corners in
//     every camera (vision/tool_pose.h with a one-tag target);
//  2. the reference tag = the tag seen in most frames (ties: lowest id); its
//     frame IS the tool frame (tool_from_tag = identity, held fixed);
//  3. the other tags' start poses in the tool frame, chained through the
//     frames where a tag is seen with an already placed tag (the candidate
//     with the median translation); a tag never seen with a placed tag is
//     refused;
//  4. one Ceres problem over every corner of every tag in every camera of
//     every frame showing two or more placed tags: per frame rig_from_tool,
//     per tag tool_from_tag (reference fixed), rig fixed; a Huber fit, then
//     corners with large residuals out and a plain least-squares fit;
//  5. each tag's covariance (ceres::Covariance) scaled by the residuals'
//     sigma^2, reported as 1-sigma of the translation (tool axes, mm) and of
//     the rotation error vector in the tool frame (deg).

#include <Eigen/Core>
#include <functional>
#include <string>
#include <vector>

#include "camcal/rig.h"
#include "data/session.h"
#include "vision/apriltag_detector.h"
#include "vision/target.h"
#include "vision/tool_pose.h"

namespace kincal {

// One view of the tool: every camera's detections (rig order).
struct LayoutFrame {
  int frame = 0;  // session frame number
  std::vector<std::vector<TagDetection>> detections;
};

struct TargetLayoutOptions {
  std::string family = "tag36h11";
  double tag_size_mm = 0;  // edge of the black square; required (> 0)
  // Views with two or more tags that the bundle needs at least.
  int min_views = 10;
  // Huber scale of the first fit (px).
  double huber_px = 1.0;
  // After the first fit a corner is left out when its residual exceeds
  // max(outlier_px, outlier_ratio * median corner residual).
  double outlier_px = 1.0;
  double outlier_ratio = 5.0;
  int max_iterations = 100;
  // A final corner RMS above this is refused: the tag size (or the rig, or
  // the family) does not fit the images.
  double max_rms_px = 2.0;
  ToolPoseOptions pose;  // the one-tag pose fits of step 1

  void Check() const;  // InputError naming the bad option
};

struct LayoutTag {
  int id = 0;
  int views = 0;  // frames of the bundle in which the tag was seen
  Rigid3 tool_from_tag;
  Eigen::Vector3d sigma_t_mm = Eigen::Vector3d::Zero();
  Eigen::Vector3d sigma_r_deg = Eigen::Vector3d::Zero();
};

struct TargetLayoutResult {
  // family, tags (by id) with tool_from_tag and sigma; no tip
  // (has_tip = false).
  Target target;
  std::vector<LayoutTag> tags;  // as target.tags
  int reference_tag_id = -1;    // its frame is the tool frame
  int views_used = 0;           // frames in the bundle
  std::vector<int> frames_used;
  std::vector<Rigid3> rig_from_tool;  // per frame used
  int corners_used = 0;
  int corners_rejected = 0;
  double rms_px = 0;     // RMS corner residual (per coordinate) of the fit
  double sigma0_px = 0;  // residual sigma with degrees of freedom
};

// Throws InputError (the reason and what to record instead) when the views
// cannot determine the layout: fewer than options.min_views frames with two
// or more tags, a tag never seen together with the others, or a fit whose
// corner RMS exceeds options.max_rms_px (a wrong tag size).
TargetLayoutResult MeasureTargetLayout(const Rig& rig,
                                       const std::vector<LayoutFrame>& frames,
                                       const TargetLayoutOptions& options);

// Every complete frame of a two-camera session, tags detected at full
// frame in both cameras. progress (optional) gets (done, total) per frame.
// InputError naming an image that cannot be read or has the wrong size.
std::vector<LayoutFrame> DetectSessionTags(
    const Session& session, const Rig& rig, const AprilTagOptions& detector,
    const std::function<void(int, int)>& progress = nullptr);

}  // namespace kincal

#endif  // KINCAL_VISION_TARGET_LAYOUT_H_
