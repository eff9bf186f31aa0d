#ifndef KINCAL_CAMCAL_CALIBRATE_CAMERAS_H_
#define KINCAL_CAMCAL_CALIBRATE_CAMERAS_H_

// Intrinsic and extrinsic calibration of 1..kMaxCameras cameras from 2D-3D
// correspondences of a planar target (chessboard, AprilGrid). Cameras are
// connected through shared views: a camera's pose in the rig starts from
// the views it shares with an already placed camera (breadth first from the
// reference camera, most shared views first), and a camera that no chain of
// shared views connects to the reference is bad input (UnconnectedCameras).
//
// Model: for camera c, view v and target point p_in_target (target units,
// z = 0 plane),
//   pixel = ProjectPoint(intrinsics_c, cam_c_from_rig * rig_from_target_v * p)
// with cam_0_from_rig = identity (the rig frame is the first camera's frame).
// Lengths (target points, rig translations, baseline) are in target units:
// give the square / tag size in mm and they are mm.
//
// Procedure: OpenCV initial values (cv::calibrateCamera per camera, the
// stereo extrinsics averaged over the views both cameras see), then one Ceres
// refinement of all intrinsics, all view poses and the extrinsics together
// with a robust loss; parameter sigma from ceres::Covariance scaled by the
// residual variance; and a cross-validation as mrcal does it: calibrate on
// the even and on the odd views separately, then (a) fit only the target pose
// of each held-out view with the other half's cameras and report the
// reprojection RMS, and (b) report the projection difference of the two
// halves' intrinsics over the imager.

#include <array>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "camcal/camera_model.h"
#include "camcal/projection_uncertainty.h"
#include "camcal/rig.h"

namespace kincal {

// Most cameras one calibration takes.
constexpr int kMaxCameras = 16;

// Target points seen by one camera in one view (index-aligned).
struct TargetObservation {
  std::vector<Eigen::Vector3d> p_in_target;  // target units, z = 0
  std::vector<Eigen::Vector2d> pixels;       // OpenCV pixel centres
  bool empty() const { return pixels.empty(); }
};

// One view (stereo frame pair): what each camera saw. observations.size() ==
// number of cameras; an empty observation means "target not found".
struct CalibrationView {
  std::string label;  // e.g. the image file name, for reports
  std::vector<TargetObservation> observations;
};

struct CalibrationProblem {
  // name, width, height of each camera (1 or 2); other fields are ignored.
  std::vector<CameraIntrinsics> cameras;
  std::vector<CalibrationView> views;
};

struct CalibrationOptions {
  enum class Loss { kTrivial, kHuber, kCauchy };

  // Distortion coefficients estimated: 0, 4 (k1 k2 p1 p2), 5 (+k3) or 8
  // (rational: +k4 k5 k6). Default 5, OpenCV's default model.
  int num_distortion = 5;
  // Loss on each point's pixel error (x and y together, norm). Default none
  // (plain least squares on the inliers that outlier rejection keeps, as
  // mrcal): chosen by the even/odd cross-validation on OpenCV's stereo set
  // (docs/CAMCAL.md, "Robust by default"). Huber / Cauchy remain options;
  // loss_scale_px is their scale.
  Loss loss = Loss::kTrivial;
  double loss_scale_px = 3.0;
  // Outlier rejection (mrcal's criterion): after each solve, sigma = RMS of
  // the inlier residual coordinates (x and y of every camera's corners);
  // when some corner has |dx| or |dy| above reject_trigger * reject_sigma *
  // sigma, every corner above reject_sigma * sigma is rejected and the
  // problem solved again on the rest, until no corner passes the trigger or
  // after max_rejection_rounds. An observation (camera, view) that loses
  // more than half of its corners is dropped whole (a misdetected board).
  // Default 4 sigma with the trigger at 5 sigma, mrcal's thresholds: with
  // the board warp on, the setting whose even/odd halves agree best on
  // OpenCV's stereo set, as well as mrcal's default (docs/CAMCAL.md,
  // "Robust by default"). 0 = no rejection.
  double reject_sigma = 4.0;
  double reject_trigger = 1.25;
  int max_rejection_rounds = 20;
  // An observation (one camera, one view) needs this many points to be used.
  int min_points_per_view = 6;
  // Each camera needs the target in at least this many views.
  int min_views = 3;
  int max_iterations = 200;
  // Weight of the regulariser of the rational distortion terms k4 k5 k6
  // (0 = none; only the 8-coefficient model has them), sized as mrcal sizes
  // its distortion regularisation: each camera's cost gains 1/2 s^2
  // (k4^2 + k5^2 + k6^2) with s^2 = regularization * (pixel residuals of the
  // camera) / 3, so k4..k6 of magnitude 1 would cost `regularization` times
  // the cost of 1 px errors on every corner. The views cannot separate
  // k4..k6 from k1..k3 (the unregularised solve drifts along that valley
  // for 200 iterations); the penalty holds them near 0 and moves a
  // well-determined solve by far less than its sigma. Default 0.005 (mrcal
  // aims its regularisation at ~0.5 % of the cost); the 5-coefficient
  // default model has no k4..k6 and is unaffected.
  double regularization = 0.005;
  // Weight of mrcal's lens regulariser (cost_functions.h,
  // LensRegularizationError): every distortion coefficient pulled toward 0
  // and the principal point toward the image centre, with mrcal's scales
  // times this weight (1 = mrcal's; 0 = none). The data outside the area
  // the boards covered do not pin the distortion polynomial; the pull
  // keeps it from extrapolating wildly there. Default 1, as
  // mrcal-calibrate-cameras (docs/CAMCAL.md, "Lens regularisation").
  double lens_regularization = 1.0;
  // A final RMS point residual above this (px) is no calibration: the
  // target's size or layout does not match the images (SolveFailure).
  double max_rms_px = 10.0;
  // Compute parameter sigma (ceres::Covariance, DENSE_SVD) and the
  // projection uncertainty map of each camera (projection_uncertainty.h).
  bool compute_covariance = true;
  // Distance, grid and valid-region threshold of the projection
  // uncertainty (default: points at infinity, 8 x 6 cells, 1 px).
  UncertaintyOptions uncertainty;
  // Estimate mrcal's board deflection (camcal/board_warp.h: a paraboloid
  // with two parameters, target units, shared by all views) with the rest.
  // Default on, as mrcal-calibrate-cameras: printed boards are not flat to
  // a fraction of a pixel, and on OpenCV's stereo set the halves agree
  // better with it (docs/CAMCAL.md). The held-out RMS fits flat boards.
  bool board_warp = true;
  // Run the even/odd cross-validation (needs 2 * min_views views per camera).
  bool cross_validate = true;
  // Radius around the image centre of the half-vs-half projection
  // difference's rotation fit and of its "focus" RMS, px; 0 = a third of
  // the smaller image side (160 px at 640x480).
  double half_diff_focus_radius_px = 0;
  // Points with a residual above this many times the camera's RMS are
  // counted as outliers in the summary (they are not removed).
  double outlier_factor = 5.0;

  // Throws InputError when an option is out of range.
  void Check() const;
};

// Reprojection residuals over the imager: a cols x rows grid of equal cells
// (row-major, row 0 at the top); per cell the number of corners, their RMS
// residual and mean residual vector (projected - detected, px; NaN when the
// cell holds no corner). Shows where in the image the camera model is wrong
// (a distortion model too weak at the edges shows as outward/inward vectors
// in the corners) and where the target never was (coverage).
struct ImageResidualGrid {
  int cols = 0, rows = 0;
  double cell_w_px = 0, cell_h_px = 0;
  std::vector<int> count;
  std::vector<double> rms_px, mean_dx_px, mean_dy_px;
};

struct CameraCalibrationSummary {
  CameraIntrinsics intrinsics;
  int num_views = 0;         // views in which the target was used
  int num_points = 0;        // corner observations
  double opencv_rms_px = 0;  // cv::calibrateCamera RMS (initial values)
  double rms_px = 0;         // final RMS of the point residuals (norm)
  double max_px = 0;         // largest point residual
  int outliers = 0;          // residuals > outlier_factor * rms_px
  // Per view (same order as the problem's views); NaN when not seen.
  std::vector<double> view_rms_px;
  // Residuals over the image (8 x 6 cells).
  ImageResidualGrid image_grid;
  // sigma of fx, fy, cx, cy, k1..k6 (kNumIntrinsics, 0 for fixed ones), scaled
  // by the residual variance; empty when the covariance is not available.
  std::vector<double> sigma;
  // Projection uncertainty (mrcal's definition) at the centre, corners and
  // a grid; valid only when `sigma` is not empty.
  ProjectionUncertaintyMap projection_uncertainty;
  // Cross-validation (NaN when not run): held-out reprojection RMS, each
  // half's cameras on the other half's views with only the view pose fitted.
  double holdout_rms_px = std::numeric_limits<double>::quiet_NaN();
  // Projection difference between the even-half and odd-half intrinsics
  // (ProjectionDifference): RMS within the focus radius of the centre, RMS
  // and max over the whole image.
  double half_diff_focus_radius_px = std::numeric_limits<double>::quiet_NaN();
  double half_diff_focus_rms_px = std::numeric_limits<double>::quiet_NaN();
  double half_diff_rms_px = std::numeric_limits<double>::quiet_NaN();
  double half_diff_max_px = std::numeric_limits<double>::quiet_NaN();
  // Outlier rejection: corners rejected one by one, and observations of
  // this camera dropped whole (their remaining corners not counted above).
  int rejected_corners = 0;
  int rejected_views = 0;
};

struct CalibrationSummary {
  Rig rig;  // intrinsics + cam_from_rig, translations in target units
  std::vector<CameraCalibrationSummary> cameras;
  double rms_px = 0;    // RMS point residual over all cameras
  double baseline = 0;  // target units; 0 with one camera
  double baseline_sigma = std::numeric_limits<double>::quiet_NaN();
  // sigma of cam_from_rig of camera 1: rotation (deg, tangent space) and
  // translation (target units); empty when unavailable or one camera.
  std::vector<double> extrinsic_rotation_sigma_deg;
  std::vector<double> extrinsic_translation_sigma;
  double residual_sigma_px = 0;  // sqrt(sum r^2 / (m - n)), per coordinate
  // Ceres outcome.
  std::string termination;  // e.g. "CONVERGENCE"
  bool converged = false;
  int iterations = 0;
  double initial_cost = 0, final_cost = 0;
  // Part of final_cost due to the regularisers (k4..k6 and the lens
  // regulariser), and its share of final_cost (0 when they are off).
  double regularization_cost = 0;
  double regularization_share = 0;
  std::string covariance_note;  // why sigma is missing, if it is
  // Board deflection (warp_x, warp_y, target units) when
  // CalibrationOptions::board_warp; zeros otherwise.
  std::array<double, 2> board_warp{0.0, 0.0};
  // Outlier rejection: rounds of re-solving and the final residual sigma
  // (RMS of the inlier coordinates, px) its thresholds are relative to.
  int rejection_rounds = 0;
  double rejection_sigma_px = std::numeric_limits<double>::quiet_NaN();
  // The views as the final solve used them: the problem's views without
  // the rejected corners and dropped observations.
  std::vector<CalibrationView> inlier_views;
  // Per view: rig_from_target (NaN-free only for used views) and whether used.
  std::vector<Rigid3> rig_from_target;
  std::vector<bool> view_used;
  double seconds = 0;
};

// Calibrates the cameras. Throws InputError when the data cannot determine
// the cameras (no or too few views with the target, no or more than
// kMaxCameras cameras, a camera that shares no view with the others:
// UnconnectedMessage).
CalibrationSummary CalibrateCameras(const CalibrationProblem& problem,
                                    const CalibrationOptions& options = {});

// Indexes of the cameras that no chain of shared views (views in which two
// cameras both see the target with at least min_points_per_view points)
// connects to the reference camera 0; empty when all are connected.
std::vector<int> UnconnectedCameras(const CalibrationProblem& problem,
                                    const CalibrationOptions& options = {});
// The message naming them, with the cause and the fix.
std::string UnconnectedMessage(const CalibrationProblem& problem,
                               const std::vector<int>& unconnected);

// Why the solve in `summary` is no calibration, with the likely cause and
// the fix; empty when it is one. Not converged within max_iterations: too
// many distortion terms for the views (try --distortion 5, or more views);
// RMS above max_rms_px: the wrong --target size or layout. Commands write
// nothing and exit 1 when this is not empty.
std::string SolveFailure(const CalibrationSummary& summary,
                         const CalibrationOptions& options);

// Reprojection RMS of views when only each view's pose is fitted with the
// cameras of `rig` held fixed (used for cross-validation). Returns one value
// per camera (NaN when that camera saw none of the views).
std::vector<double> HeldOutRmsPx(const Rig& rig,
                                 const std::vector<CalibrationView>& views,
                                 const CalibrationOptions& options);

// mrcal-style projection difference between two models of the same camera
// (mrcal.projection_diff with use_uncertainties=False, rays at infinity):
// a grid of pixels over the imager (grid_width columns, rows in proportion,
// as mrcal.sample_imager) is unprojected by both models; the rotation that
// best maps a's rays onto b's rays of the pixels within focus_radius_px of
// the image centre is fitted (Procrustes on the unit vectors); each of a's
// rays, rotated, is projected by b and compared with its pixel.
struct ProjectionDifference {
  double focus_radius_px = 0;  // the radius used
  double focus_rms_px = 0;     // RMS over the pixels within the radius
  double rms_px = 0;           // RMS over the whole grid
  double max_px = 0;           // largest over the whole grid
};
// focus_radius_px <= 0: a third of the smaller image side.
ProjectionDifference ProjectionDifferenceOf(const CameraIntrinsics& a,
                                            const CameraIntrinsics& b,
                                            double focus_radius_px = 0,
                                            int grid_width = 60);

}  // namespace kincal

#endif  // KINCAL_CAMCAL_CALIBRATE_CAMERAS_H_
