#ifndef KINCAL_BUNDLE_BUNDLE_H_
#define KINCAL_BUNDLE_BUNDLE_H_

// The image bundle: one Ceres problem from tag corners to robot parameters.
//
// For frame f with joint readings q_f, tag corner X (in the tool frame of
// target.yaml) seen by camera c at pixel u, with the cameras on a stand
// (rig.yaml `mount: world`, the target on the flange):
//
//   u = project_c( cam_from_rig_c * rig_from_base * base_from_flange(q_f)
//                  * flange_from_tool * X )
//
// and with the cameras on the flange (`mount: flange`, the target a fixed
// board whose frame is target.yaml's tool frame):
//
//   u = project_c( cam_from_rig_c * rig_from_flange * flange_from_base(q_f)
//                  * base_from_target * X )
//
// One model for both: rig_from_tool = A * M(q_f) * B, with A the rig-side
// frame (rig_from_base | rig_from_flange), M the chain (base_from_flange or
// its inverse) and B the target-side frame (flange_from_tool |
// base_from_target).
//
// base_from_flange is the robot's chain without its tool row (calib/chain.h,
// RowTransform and ModelJointValue, so the joint error models of `diagnose`
// apply); project_c is camcal's ProjectPoint. Unknowns: the identifiable
// geometry of the joint rows, the two frames A and B, optionally extension
// parameters (e.g. j3.backlash) and the cameras (with priors). The tool row
// of the calibrated robot ends at the needle tip (stand: tip_in_flange =
// flange_from_tool * tip_in_tool) or at the rig origin, the reference
// camera's optical centre (flange: flange_from_rig's translation).
//
// Residuals are pixels with a per-corner Huber loss (applied inside the
// frame's residual block, so one frame's FK is computed once for all its
// corners). Identifiability: the pixel Jacobian, columns scaled to unit norm,
// scanned with Gram-Schmidt in priority order (the two frames first, then
// the rows in chain order), as calibrate does on tip residuals
// (calib/identifiability.h).

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "calib/chain.h"
#include "calib/model_state.h"
#include "camcal/rig.h"
#include "data/robot.h"
#include "vision/target.h"

namespace kincal {

// One detected tag corner.
struct BundleCorner {
  int camera = 0;
  int tag = 0;     // index into Target::tags
  int corner = 0;  // 0..3, libapriltag order
  Eigen::Vector2d px = Eigen::Vector2d::Zero();
  // The corner's pixel residual is multiplied by this (> 0; 1 = the
  // reference precision): a corner known to err k times more weighs 1/k
  // (ObserveOptions::full_weight_contrast sets it from the tag's contrast).
  // The Huber scale and the outlier rules read weighted residuals; the
  // reported RMS are in pixels.
  double weight = 1.0;
};

// One frame with joint readings and the corners seen in it.
struct BundleFrame {
  int frame = 0;                  // frame number in the session
  std::vector<double> q_reading;  // robot joint order, mm | deg
  double t_s = 0.0;
  std::vector<BundleCorner> corners;
  // The tracker's tool pose of this frame (start values, held-out tips).
  bool tracked = false;
  Rigid3 rig_from_tool;
  double tracked_rms_px = 0.0;
  int tracked_tags = 0;
};

struct BundleOptions {
  double holdout_fraction = 0.2;  // frames held out of the fit
  uint64_t seed = 1;
  // k-fold: when folds >= 2, the frames held out are fold `fold` (0-based)
  // of a seeded partition into `folds` parts (holdout_fraction is ignored).
  int folds = 0;
  int fold = 0;
  // Per-corner Huber scale, px; 0 = automatic: after the first joint fit,
  // kAutoHuberSigmas times the corners' noise (their median error / 1.1774,
  // the median of a 2-D Gaussian error's norm being 1.1774 sigma), at least
  // kMinAutoHuberPx, and the fit redone. A fixed scale of 1 px let
  // corners 40 sigma off pull the robot on renders with 0.03 px corners.
  double huber_px = 0.0;
  // Tag observations whose RMS after the first fit exceeds
  // max(outlier_px, outlier_ratio * median) are dropped, then the fit redone.
  double outlier_px = 1.0;
  double outlier_ratio = 5.0;
  // Single corners whose error after the first fit exceeds
  // max(outlier_sigmas * sigma, kMinOutlierCornerPx) are dropped too, sigma
  // being the corners' noise (median error / 1.1774); 0 = keep every
  // corner of a kept tag. A Huber loss bounds such a corner's pull but does
  // not remove it: a few corners 1-1.5 px off on dim oblique tags, 40 sigma
  // out, moved the robot 0.02-0.03 mm on renders.
  double outlier_sigmas = 10.0;
  // Start values: tracked poses with at least this many tags and at most
  // this RMS take part in the hand-eye start.
  int start_min_tags = 2;
  double start_max_rms_px = 1.0;
  // Gram-Schmidt tolerance (sine of the angle to the span), and the
  // statistical criterion of calibrate: a parameter whose predicted sigma
  // given the earlier ones exceeds max_sigma_fraction of its bound is held.
  double identifiability_tolerance = 1e-6;
  double max_sigma_fraction = 0.1;
  // Extension parameters to fit besides the geometry ("j3.backlash", ...).
  std::vector<std::string> extensions;
  // Cameras: refine intrinsics (fx, fy, cx, cy, the file's distortion) and
  // the other cameras' cam_from_rig, with Gaussian priors at rig.yaml.
  bool refine_cameras = false;
  double prior_focal_px = 2.0;
  double prior_principal_px = 2.0;
  double prior_distortion = 0.005;
  double prior_rotation_deg = 0.02;
  double prior_translation_mm = 0.2;
  int max_iterations = 100;
  int num_threads = 1;
};

struct BundleParam {
  std::string name;
  double value = 0.0;  // interface units (mm, deg, 1)
  double sigma = 0.0;  // 1-sigma, interface units; NaN when unknown
  // Extensions only: how far the parameter moves the tool row's end (the
  // tip, or the rig origin on the flange), RMS over the used frames of the
  // move when it is set to zero, mm; NaN for geometry.
  double effect_mm = std::numeric_limits<double>::quiet_NaN();
};

struct BundleResult {
  Chain chain;  // fitted (tool row set from the tip)
  // chain.ToRobot(nominal) with the fit record and covariance
  // (bundle/robot_record.h RecordBundleFit).
  Robot calibrated;
  Rig rig;  // refined cameras (= input without refine)
  RigMount mount = RigMount::kWorld;  // rig.mount
  // The two frames, [angle-axis rad, t mm]. mount world: rig_from_base and
  // flange_from_tool; mount flange: flange_from_rig and base_from_target
  // (the other two stay zero).
  std::array<double, 6> rig_from_base{};
  std::array<double, 6> flange_from_tool{};
  std::array<double, 6> flange_from_rig{};
  std::array<double, 6> base_from_target{};
  std::vector<BundleParam> params;  // free parameters with sigma
  // Their covariance (Ceres, dense SVD, scaled by sigma0_px^2; params[].sigma
  // is its diagonal), internal units (mm, rad, the families' units): rows
  // and columns 0 .. params.size() - 1 in params' order, then the fitted
  // frames' pose blocks [angle-axis rad, t mm] A = rig_from_base |
  // rig_from_flange (6) and B = flange_from_tool | base_from_target (6);
  // empty when Ceres cannot compute it.
  Eigen::MatrixXd covariance;
  std::vector<std::string> identifiable, unidentifiable;
  std::vector<std::string> relations;  // why each is unidentifiable
  int frames = 0;                      // frames given
  int used_frames = 0;                 // with joints and corners
  int train_frames = 0, heldout_frames = 0;
  int corners = 0;                   // training corners in the final fit
  int dropped_tags = 0;              // tag observations dropped as outliers
  int dropped_corners = 0;           // single corners dropped as outliers
  double start_reproj_rms_px = 0.0;  // after the hand-eye start
  double reproj_rms_px = 0.0;        // training, final
  double heldout_reproj_rms_px = 0.0;
  // Held-out frames: the model's tip vs the tip tracked from the images
  // (rig frame); with mount flange the rig origin instead (target frame).
  double heldout_tip_rms_mm = 0.0;
  int heldout_tips = 0;
  // Per held-out frame errors (pooling folds): corner residuals, px, and
  // |model tip - tracked tip|, mm.
  std::vector<double> heldout_corner_px, heldout_tip_mm;
  double sigma0_px = 0.0;           // noise estimate per pixel coordinate
  double huber_px = 0.0;            // the Huber scale of the final fit
  std::vector<int> train, heldout;  // indices into the frames given
  std::vector<PoseInput> inputs;    // per frame given (s, tau for errors)
  std::string termination;
  int iterations = 0;
  double seconds = 0.0;
};

// Runs the bundle. Throws InputError when the frames cannot determine a
// start (fewer than 3 tracked frames with distinct rotations) or a name in
// options.extensions is unknown.
BundleResult RunBundle(const Robot& nominal, const Rig& rig,
                       const Target& target,
                       const std::vector<BundleFrame>& frames,
                       const BundleOptions& options);

// The model's tool (target) pose in the rig frame for one frame, either
// mount.
Rigid3 ModelRigFromTool(const BundleResult& result, int index);

// The point the calibrated robot's tool row ends at, for one frame, and the
// frame it is given in: mount world, the needle tip in the rig frame from
// rig_from_tool (the tool's pose in the rig); mount flange, the rig origin in
// the target frame. Applied to ModelRigFromTool or to a tracked pose it gives
// the model's and the images' point.
Eigen::Vector3d MeasuredPoint(RigMount mount, const Target& target,
                              const Rigid3& rig_from_tool);

// Whether the frame's corners come from at least two cameras (a tool pose
// from one camera is weak in depth: such tips are not used as measurements).
bool SeenByTwoCameras(const BundleFrame& f);
// The configuration-aware form: on a rig of `num_cameras` >= 2, two cameras;
// on a one-camera rig, any corner (its tips carry their depth sigma).
bool SeenByEnoughCameras(const BundleFrame& f, int num_cameras);

// Closed-form hand-eye start: X = rig_from_base, Y = flange_from_tool with
// rig_from_tool_i = X * base_from_flange_i * Y (linear in the rotations,
// projected onto SO(3), then linear least squares for the translations).
// The cameras on the flange are the same equation with the chain inverted:
// pass flange_from_base_i, get X = rig_from_flange, Y = base_from_target.
// False when the rotations do not determine X and Y.
bool HandEyeStart(const std::vector<Rigid3>& base_from_flange,
                  const std::vector<Rigid3>& rig_from_tool, Rigid3* x,
                  Rigid3* y);

}  // namespace kincal

#endif  // KINCAL_BUNDLE_BUNDLE_H_
