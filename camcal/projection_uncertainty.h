#ifndef KINCAL_CAMCAL_PROJECTION_UNCERTAINTY_H_
#define KINCAL_CAMCAL_PROJECTION_UNCERTAINTY_H_

// Projection uncertainty of a calibrated camera, as mrcal defines it
// (mrcal.projection_uncertainty, "Projection uncertainty" in mrcal's docs):
//
//   1. Unproject the pixel q with the solved intrinsics to the point p_cam
//      at the given distance (at infinity: the ray's direction only).
//   2. Express that point in the frame of every calibration view's target:
//      p_target_i = (cam_from_rig * rig_from_target_i)^-1 * p_cam. The
//      reference frame is defined by the target poses, so it moves with
//      them: the point is fixed relative to the targets, not the camera.
//   3. q(b) = Project(intrinsics, cam_from_rig * mean_i(rig_from_target_i *
//      p_target_i)) as a function of all parameters b (intrinsics, the
//      camera's extrinsics, every view pose); at infinity only rotations
//      act on directions.
//   4. Var(q) = dq/db Var(b) dq/db^T; reported as the worst-direction sigma
//      sqrt(largest eigenvalue of Var(q)) in px.
//
// Var(b) is the calibration's covariance (inverse of J^T J, scaled by the
// residual variance). dq/db by central differences of q(b).

#include <Eigen/Core>
#include <array>
#include <limits>
#include <vector>

#include "camcal/camera_model.h"
#include "data/rigid3.h"

namespace kincal {

// The solved calibration and the covariance of a perturbation vector delta of
// its parameters. Perturbations: intrinsics additive; a pose's rotation by a
// rotation vector applied on the left (R' = exp([dr]) R), its translation
// additive (t' = t + dt), 6 entries (dr, dt) per pose.
struct CalibrationCovariance {
  std::vector<std::array<double, kNumIntrinsics>> intrinsics;  // per camera
  std::vector<Rigid3> cam_from_rig;                            // per camera
  std::vector<Rigid3> rig_from_target;  // per view used in the solve
  // Index in delta of each intrinsic; -1 when held fixed.
  std::vector<std::array<int, kNumIntrinsics>> intrinsic_index;
  // First index of the 6 entries of cam_from_rig per camera; -1 when fixed
  // (the reference camera).
  std::vector<int> cam_from_rig_index;
  // First index of the 6 entries of each rig_from_target.
  std::vector<int> rig_from_target_index;
  Eigen::MatrixXd covariance;  // Var(delta)
};

// 2x2 covariance (px^2) of the projection of `pixel` of `camera` at
// `distance` from the camera centre (target units; infinity for a point at
// infinity).
Eigen::Matrix2d ProjectionCovariance(const CalibrationCovariance& cal,
                                     int camera, const Eigen::Vector2d& pixel,
                                     double distance);

// sqrt of the largest eigenvalue of a 2x2 covariance.
double WorstDirectionSigma(const Eigen::Matrix2d& covariance);

struct UncertaintyOptions {
  // Distance of the projected points from the camera (target units);
  // default infinity (mrcal's atinfinity).
  double distance = std::numeric_limits<double>::infinity();
  // Grid of cell centres over the imager.
  int cols = 8, rows = 6;
  // The valid intrinsics region: where the sigma stays below this (px).
  double valid_threshold_px = 1.0;
  // Rays from the image centre that trace the region's outline.
  int region_rays = 32;
};

struct ProjectionUncertaintyMap {
  double distance = std::numeric_limits<double>::infinity();
  Eigen::Vector2d centre_pixel{0, 0};  // ((w - 1) / 2, (h - 1) / 2)
  double centre_px = 0;                // worst-direction sigma at the centre
  // Pixels (0, 0), (w-1, 0), (0, h-1), (w-1, h-1) and their sigma.
  std::array<Eigen::Vector2d, 4> corner_pixels;
  std::array<double, 4> corner_px{};
  // cols x rows cells, row-major from the top-left; sigma at each centre.
  int cols = 0, rows = 0;
  std::vector<double> grid_px;
  double valid_threshold_px = 0;
  // Outline (px, closed: last = first) of the star-shaped region around the
  // image centre where sigma < valid_threshold_px, traced along
  // region_rays rays to the image border; empty when the centre itself is
  // above the threshold.
  std::vector<Eigen::Vector2d> valid_region;
};

ProjectionUncertaintyMap MapProjectionUncertainty(
    const CalibrationCovariance& cal, int camera, int width, int height,
    const UncertaintyOptions& options = {});

}  // namespace kincal

#endif  // KINCAL_CAMCAL_PROJECTION_UNCERTAINTY_H_
