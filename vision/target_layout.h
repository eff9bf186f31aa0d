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
//  5. the tags' joint covariance, reported per tag as 1-sigma of the
//     translation (tool axes, mm) and of the rotation error vector in the
//     tool frame (deg); see LayoutCovariance for the noise model.
//
// A needle tip by pivot calibration with the measured layout
// (MeasurePivotTip) carries the layout's covariance into the tip's sigma.

#include <Eigen/Core>
#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include "camcal/rig.h"
#include "data/session.h"
#include "vision/apriltag_detector.h"
#include "vision/bayer.h"
#include "vision/pivot.h"
#include "vision/target.h"
#include "vision/tool_pose.h"

namespace kincal {

// One view of the tool: every camera's detections (rig order).
struct LayoutFrame {
  int frame = 0;  // session frame number
  std::vector<std::vector<TagDetection>> detections;
};

// How the tags' covariance is estimated (H = J^T J of the bundle, the frame
// poses eliminated by their Schur complement):
//  - kCornerNoise: sigma0^2 H^-1, independent corner noise of the residuals'
//    sigma0; too small when a tag's four corners err together (blur, a
//    tag's quad fitted as a whole);
//  - kTagObservations (default): cluster-robust (sandwich)
//    H^-1 (sum_c g_c g_c^T) H^-1 over each tag observation c (one tag in one
//    camera at one frame), g_c = J_c^T (I - J_c H^-1 J_c^T)^-1 r_c (the
//    residuals c would have had left out of the fit, as a jackknife): any
//    error shared by a tag's corners counts fully, whatever its size per
//    observation. Errors shared across frames (a bias of the corner detector
//    that repeats at every view of a tag) are not seen by either; the
//    corner offsets of TargetLayoutResult::corner_offset_sigma_mm add them
//    to both.
enum class LayoutCovariance { kCornerNoise, kTagObservations };

struct TargetLayoutOptions {
  std::string family = "tag36h11";
  double tag_size_mm = 0;  // edge of the black square; required (> 0)
  // Views with two or more tags that the bundle needs at least.
  int min_views = 10;
  // Huber scale of the first fit (px).
  double huber_px = 1.0;
  // After the first fit a tag observation (one tag in one camera at one
  // frame) is left out when one of its corners' residual exceeds
  // max(outlier_px, outlier_ratio * median corner residual).
  double outlier_px = 0.3;
  double outlier_ratio = 4.0;
  int max_iterations = 100;
  // A final corner RMS above this is refused: the tag size (or the rig, or
  // the family) does not fit the images.
  double max_rms_px = 2.0;
  ToolPoseOptions pose;  // the one-tag pose fits of step 1
  LayoutCovariance covariance = LayoutCovariance::kTagObservations;

  void Check() const;  // InputError naming the bad option
};

struct LayoutTag {
  int id = 0;
  int views = 0;  // frames of the bundle in which the tag was seen
  Rigid3 tool_from_tag;
  Eigen::Vector3d sigma_t_mm = Eigen::Vector3d::Zero();
  Eigen::Vector3d sigma_r_deg = Eigen::Vector3d::Zero();
};

// The moments behind a corner-offset sigma (CornerOffsetSystematic): over
// every (tag, corner), shared_mm2 sums |m|^2 - var(z) / n (the mean
// residual in the tag's plane, less its noise part) and seen the share of
// the offsets' variance the fit leaves in those means; s^2 = shared_mm2 /
// seen. Sessions of the same tool add up.
struct CornerOffsetMoments {
  double shared_mm2 = 0;
  double seen = 0;
  double SigmaMm() const {
    return seen > 0 && shared_mm2 > 0 ? std::sqrt(shared_mm2 / seen) : 0.0;
  }
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
  // Joint covariance of the tags' pose corrections, 6 per tag in the order
  // of `tags` (rotation error vector in the tool frame, rad; translation,
  // mm); the reference tag's rows and columns are 0.
  Eigen::MatrixXd covariance;
  // The error every view shares (CornerOffsetSystematic): each tag corner
  // as the detector places it, off its printed place by a fixed offset in
  // the tag's plane, the same in every view (a corner bias that depends on
  // the tag's own pattern next to the corner and on the blur, which no
  // number of views averages out). corner_offset_sigma_mm: its 1-sigma per
  // in-plane axis (mm), estimated from the fit's residuals (0 when the
  // residuals show none); tags_from_corner_offsets: how the tags' pose
  // corrections move with the offsets, 6 per tag (as covariance) x 8 per
  // tag (corner k's tag-plane x, y at columns 8 i + 2 k). `covariance`
  // includes sigma^2 G G^T of it.
  double corner_offset_sigma_mm = 0;
  CornerOffsetMoments corner_offset_moments;
  Eigen::MatrixXd tags_from_corner_offsets;
  // Frames of the session that show two or more tags (those carry the
  // layout) and all frames.
  int multi_tag_views = 0;
  int frames = 0;
};

// Throws InputError (the reason and what to record instead) when the views
// cannot determine the layout: fewer than options.min_views frames with two
// or more tags, a tag never seen together with the others, or a fit whose
// corner RMS exceeds options.max_rms_px (a wrong tag size).
TargetLayoutResult MeasureTargetLayout(const Rig& rig,
                                       const std::vector<LayoutFrame>& frames,
                                       const TargetLayoutOptions& options);

// How rig_from_tool, fitted (plain least squares, as EstimateToolPose's
// final fit) to the corners that `pose` used with the layout's target,
// moves with the layout: 6 x 6 * layout.tags.size(), rows (a, dt) of the
// pose's correction (exp([a]x) R, t + dt), columns the tags' corrections as
// in TargetLayoutResult::covariance. Implicit function theorem:
// -(Jp^T Jp)^-1 Jp^T Jl at the fitted pose.
// information (optional): the pose fit's Jp^T Jp (6 x 6, same order), whose
// inverse is the pose's covariance up to the corner variance.
// from_corner_offsets (optional): how the pose moves with the tags' corner
// offsets of TargetLayoutResult::corner_offset_sigma_mm (6 x 8 per tag, its
// columns as tags_from_corner_offsets'), -(Jp^T Jp)^-1 Jp^T Jd.
Eigen::MatrixXd ToolPoseLayoutJacobian(
    const Rig& rig, const TargetLayoutResult& layout,
    const ToolPoseResult& pose,
    Eigen::Matrix<double, 6, 6>* information = nullptr,
    Eigen::MatrixXd* from_corner_offsets = nullptr);

struct PivotTipOptions {
  // Pivot frames with a tool pose needed at least.
  int min_views = 10;
  // Tilt range needed in the second direction (PivotResult::tilt_range_deg).
  double min_tilt_deg = 15.0;
  double min_conditioning = 1e-3;
  // A pivot frame whose tool pose misses the pivot by more than
  // max(outlier_mm, outlier_ratio * the median pose's residual) is left out
  // (worst first, the pivot refitted each time, keeping min_views poses):
  // one bad tag observation in a frame turns its pose by a few hundredths
  // of a degree, which the tip's 100 mm lever makes tenths of a mm.
  double outlier_mm = 0.05;
  double outlier_ratio = 4.0;
  ToolPoseOptions pose;

  void Check() const;  // InputError naming the bad option
};

struct PivotTipResult {
  PivotResult pivot;  // tip_sigma_mm there: the pivot residuals' part only
  int views = 0;      // pivot frames with a tool pose, outliers left out
  std::vector<int> frames_rejected;  // session frame numbers left out
  // 1-sigma of tip_in_tool per tool axis (mm): the pivot residuals' part and
  // the layout's covariance carried through the tool poses of every pivot
  // frame (ToolPoseLayoutJacobian, PivotTipJacobian).
  Eigen::Vector3d tip_sigma_mm = Eigen::Vector3d::Zero();
  Eigen::Vector3d layout_sigma_mm = Eigen::Vector3d::Zero();  // its part
  // The part of the corner offsets shared by every view
  // (TargetLayoutResult::corner_offset_sigma_mm), through the layout and
  // through every pivot frame's pose at once; layout_sigma_mm then holds
  // the layout's other part only.
  Eigen::Vector3d systematic_sigma_mm = Eigen::Vector3d::Zero();
  // The corner offsets' sigma from the layout and the pivot sessions'
  // residuals together (mm per in-plane axis).
  double corner_offset_sigma_mm = 0;
};

// The tip by pivot calibration of the tool tracked with the measured layout
// in `frames` (the tip resting in a divot while the tool tilts). InputError
// with what to record instead: too few frames with the tool, too little
// tilt, rotations that leave the tip undetermined.
PivotTipResult MeasurePivotTip(const Rig& rig, const TargetLayoutResult& layout,
                               const std::vector<LayoutFrame>& frames,
                               const PivotTipOptions& options);

// Every complete frame of a two-camera session, tags detected at full
// frame in both cameras; with a Bayer pattern the images are raw mosaics,
// balanced to gray first (vision/bayer.h). progress (optional) gets (done,
// total) per frame. InputError naming an image that cannot be read or has
// the wrong size.
std::vector<LayoutFrame> DetectSessionTags(
    const Session& session, const Rig& rig, const AprilTagOptions& detector,
    BayerPattern bayer = BayerPattern::kNone,
    const std::function<void(int, int)>& progress = nullptr);

}  // namespace kincal

#endif  // KINCAL_VISION_TARGET_LAYOUT_H_
