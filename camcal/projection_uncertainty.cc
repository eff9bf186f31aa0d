#include "camcal/projection_uncertainty.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

#include "data/error.h"

namespace kincal {

namespace {

// The parameters q(b) depends on for one camera, perturbed in place.
struct ProjectionParameters {
  std::array<double, kNumIntrinsics> intrinsics;
  Rigid3 cam_from_rig;
  std::vector<Rigid3> rig_from_target;
};

// q(b) of the header: the target-frame points mapped back through the
// (perturbed) view poses, averaged in the rig frame, projected.
Eigen::Vector2d ProjectThroughTargets(
    const ProjectionParameters& b,
    const std::vector<Eigen::Vector3d>& in_targets, bool at_infinity) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < in_targets.size(); ++i) {
    const Rigid3& pose = b.rig_from_target[i];
    sum += at_infinity ? Eigen::Vector3d(pose.R * in_targets[i])
                       : Eigen::Vector3d(pose * in_targets[i]);
  }
  const Eigen::Vector3d in_rig = sum / static_cast<double>(in_targets.size());
  const Eigen::Vector3d in_cam =
      at_infinity ? Eigen::Vector3d(b.cam_from_rig.R * in_rig)
                  : Eigen::Vector3d(b.cam_from_rig * in_rig);
  Eigen::Vector2d pixel;
  if (!ProjectPoint(b.intrinsics.data(), in_cam.data(), pixel.data())) {
    pixel.setConstant(std::numeric_limits<double>::quiet_NaN());
  }
  return pixel;
}

// Component k (0..5) of a pose perturbation (rotation vector, translation).
void PerturbPose(int k, double step, Rigid3* pose) {
  if (k < 3) {
    Eigen::Vector3d w = Eigen::Vector3d::Zero();
    w[k] = step;
    pose->R = RotationMatrixFromVector(w) * pose->R;
  } else {
    pose->t[k - 3] += step;
  }
}

// Central difference of q(b) along one entry of delta, written into column
// `index` of `jacobian`. `perturb(step)` applies the step to a copy.
template <typename Perturb>
void DifferenceColumn(const ProjectionParameters& b,
                      const std::vector<Eigen::Vector3d>& in_targets,
                      bool at_infinity, int index, double step, Perturb perturb,
                      Eigen::Matrix2Xd* jacobian) {
  ProjectionParameters plus = b, minus = b;
  perturb(step, &plus);
  perturb(-step, &minus);
  jacobian->col(index) =
      (ProjectThroughTargets(plus, in_targets, at_infinity) -
       ProjectThroughTargets(minus, in_targets, at_infinity)) /
      (2 * step);
}

// dq/d(delta) (2 x size of delta) at `pixel` of `camera`.
Eigen::Matrix2Xd ProjectionJacobian(const CalibrationCovariance& cal,
                                    int camera, const Eigen::Vector2d& pixel,
                                    double distance) {
  const bool at_infinity = std::isinf(distance);
  CameraIntrinsics intrinsics =
      CameraIntrinsics::FromArray(cal.intrinsics[camera].data(), 8);
  const Eigen::Vector3d ray = Unproject(intrinsics, pixel);
  const Eigen::Vector3d p_in_cam =
      at_infinity ? ray : Eigen::Vector3d(ray * distance);
  ProjectionParameters b{cal.intrinsics[camera], cal.cam_from_rig[camera],
                         cal.rig_from_target};
  std::vector<Eigen::Vector3d> in_targets;
  for (const Rigid3& rig_from_target : cal.rig_from_target) {
    const Rigid3 target_from_cam =
        (cal.cam_from_rig[camera] * rig_from_target).Inverse();
    in_targets.push_back(at_infinity
                             ? Eigen::Vector3d(target_from_cam.R * p_in_cam)
                             : Eigen::Vector3d(target_from_cam * p_in_cam));
  }
  const Eigen::Index n = cal.covariance.rows();
  Eigen::Matrix2Xd jacobian = Eigen::Matrix2Xd::Zero(2, n);
  for (int i = 0; i < kNumIntrinsics; ++i) {
    const int index = cal.intrinsic_index[camera][i];
    if (index < 0) continue;
    const double step = 1e-6 * std::max(1.0, std::abs(b.intrinsics[i]));
    DifferenceColumn(
        b, in_targets, at_infinity, index, step,
        [i](double h, ProjectionParameters* p) { p->intrinsics[i] += h; },
        &jacobian);
  }
  const double rotation_step = 1e-6;
  auto pose_step = [&](int k, const Rigid3& pose) {
    return k < 3 ? rotation_step : 1e-6 * std::max(1.0, pose.t.norm());
  };
  const int extrinsic = cal.cam_from_rig_index[camera];
  for (int k = 0; k < 6 && extrinsic >= 0; ++k) {
    DifferenceColumn(
        b, in_targets, at_infinity, extrinsic + k, pose_step(k, b.cam_from_rig),
        [k](double h, ProjectionParameters* p) {
          PerturbPose(k, h, &p->cam_from_rig);
        },
        &jacobian);
  }
  for (size_t v = 0; v < b.rig_from_target.size(); ++v) {
    for (int k = 0; k < 6; ++k) {
      DifferenceColumn(
          b, in_targets, at_infinity, cal.rig_from_target_index[v] + k,
          pose_step(k, b.rig_from_target[v]),
          [k, v](double h, ProjectionParameters* p) {
            PerturbPose(k, h, &p->rig_from_target[v]);
          },
          &jacobian);
    }
  }
  return jacobian;
}

double SigmaAt(const CalibrationCovariance& cal, int camera,
               const Eigen::Vector2d& pixel, double distance) {
  return WorstDirectionSigma(
      ProjectionCovariance(cal, camera, pixel, distance));
}

// The farthest point from `centre` toward `border` whose sigma stays below
// the threshold: a march in 16 steps, then bisection of the crossing.
Eigen::Vector2d RegionEdge(const CalibrationCovariance& cal, int camera,
                           double distance, double threshold,
                           const Eigen::Vector2d& centre,
                           const Eigen::Vector2d& border) {
  const int steps = 16;
  double inside = 0;
  for (int s = 1; s <= steps; ++s) {
    const double f = static_cast<double>(s) / steps;
    if (!(SigmaAt(cal, camera, centre + f * (border - centre), distance) <
          threshold)) {
      double outside = f;
      for (int k = 0; k < 8; ++k) {
        const double mid = 0.5 * (inside + outside);
        if (SigmaAt(cal, camera, centre + mid * (border - centre), distance) <
            threshold) {
          inside = mid;
        } else {
          outside = mid;
        }
      }
      return centre + inside * (border - centre);
    }
    inside = f;
  }
  return border;
}

std::vector<Eigen::Vector2d> TraceValidRegion(const CalibrationCovariance& cal,
                                              int camera, int width, int height,
                                              const UncertaintyOptions& options,
                                              const Eigen::Vector2d& centre) {
  std::vector<Eigen::Vector2d> outline;
  const double half_w = (width - 1) / 2.0, half_h = (height - 1) / 2.0;
  for (int k = 0; k < options.region_rays; ++k) {
    const double angle = 2 * M_PI * k / options.region_rays;
    const Eigen::Vector2d dir(std::cos(angle), std::sin(angle));
    // Scale that takes the ray from the centre to the image border.
    const double reach = std::min(
        std::abs(dir.x()) > 1e-12 ? half_w / std::abs(dir.x()) : 1e300,
        std::abs(dir.y()) > 1e-12 ? half_h / std::abs(dir.y()) : 1e300);
    outline.push_back(RegionEdge(cal, camera, options.distance,
                                 options.valid_threshold_px, centre,
                                 centre + reach * dir));
  }
  outline.push_back(outline.front());
  return outline;
}

}  // namespace

Eigen::Matrix2d ProjectionCovariance(const CalibrationCovariance& cal,
                                     int camera, const Eigen::Vector2d& pixel,
                                     double distance) {
  KINCAL_CHECK(camera >= 0 && camera < static_cast<int>(cal.intrinsics.size()),
               "camera " << camera << " not in the calibration");
  KINCAL_CHECK(distance > 0, "distance must be > 0, got " << distance);
  const Eigen::Matrix2Xd jacobian =
      ProjectionJacobian(cal, camera, pixel, distance);
  return jacobian * cal.covariance * jacobian.transpose();
}

double WorstDirectionSigma(const Eigen::Matrix2d& covariance) {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(covariance);
  return std::sqrt(std::max(0.0, eig.eigenvalues().maxCoeff()));
}

ProjectionUncertaintyMap MapProjectionUncertainty(
    const CalibrationCovariance& cal, int camera, int width, int height,
    const UncertaintyOptions& options) {
  Require(options.cols > 0 && options.rows > 0 && options.region_rays >= 3,
          "projection uncertainty: grid and rays must be positive");
  Require(options.distance > 0, "projection uncertainty: distance must be > 0");
  ProjectionUncertaintyMap map;
  map.distance = options.distance;
  map.centre_pixel = Eigen::Vector2d((width - 1) / 2.0, (height - 1) / 2.0);
  map.centre_px = SigmaAt(cal, camera, map.centre_pixel, options.distance);
  map.corner_pixels = {Eigen::Vector2d(0, 0), Eigen::Vector2d(width - 1, 0),
                       Eigen::Vector2d(0, height - 1),
                       Eigen::Vector2d(width - 1, height - 1)};
  for (int k = 0; k < 4; ++k) {
    map.corner_px[k] =
        SigmaAt(cal, camera, map.corner_pixels[k], options.distance);
  }
  map.cols = options.cols;
  map.rows = options.rows;
  for (int j = 0; j < options.rows; ++j) {
    for (int i = 0; i < options.cols; ++i) {
      const Eigen::Vector2d pixel((i + 0.5) * width / options.cols - 0.5,
                                  (j + 0.5) * height / options.rows - 0.5);
      map.grid_px.push_back(SigmaAt(cal, camera, pixel, options.distance));
    }
  }
  map.valid_threshold_px = options.valid_threshold_px;
  if (map.centre_px < options.valid_threshold_px) {
    map.valid_region =
        TraceValidRegion(cal, camera, width, height, options, map.centre_pixel);
  }
  return map;
}

}  // namespace kincal
