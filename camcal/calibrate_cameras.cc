#include "camcal/calibrate_cameras.h"

#include <ceres/ceres.h>
#include <ceres/rotation.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>
#include <sstream>
#include <utility>

#include "camcal/board_warp.h"
#include "camcal/cost_functions.h"
#include "data/error.h"

namespace kincal {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// A pose as one Ceres quaternion block (x, y, z, w) and one translation block.
struct PoseBlock {
  std::array<double, 4> q{0, 0, 0, 1};
  std::array<double, 3> t{0, 0, 0};

  static PoseBlock From(const Rigid3& pose) {
    PoseBlock b;
    const Eigen::Quaterniond q(pose.R);
    b.q = {q.x(), q.y(), q.z(), q.w()};
    b.t = {pose.t.x(), pose.t.y(), pose.t.z()};
    return b;
  }
  Rigid3 ToRigid3() const {
    Rigid3 pose;
    pose.R = Eigen::Quaterniond(q[3], q[0], q[1], q[2])
                 .normalized()
                 .toRotationMatrix();
    pose.t = Eigen::Vector3d(t[0], t[1], t[2]);
    return pose;
  }
};

// Everything the refinement estimates.
struct State {
  std::vector<std::array<double, kNumIntrinsics>> intrinsics;  // per camera
  std::vector<PoseBlock> cam_from_rig;     // per camera; [0] = identity
  std::vector<PoseBlock> rig_from_target;  // per view
  std::vector<bool> view_used;
  std::array<double, 2> board_warp{0.0, 0.0};  // warp_x, warp_y
  BoardExtent board_extent;  // of every target point of the problem
  // Per camera: the image centre ((width - 1) / 2, (height - 1) / 2), px,
  // where the lens regulariser pulls the principal point.
  std::vector<Eigen::Vector2d> image_centre;
};

bool UsableObservation(const TargetObservation& obs,
                       const CalibrationOptions& options) {
  return static_cast<int>(obs.pixels.size()) >= options.min_points_per_view;
}

std::unique_ptr<ceres::LossFunction> MakeLoss(
    const CalibrationOptions& options) {
  switch (options.loss) {
    case CalibrationOptions::Loss::kHuber:
      return std::make_unique<ceres::HuberLoss>(options.loss_scale_px);
    case CalibrationOptions::Loss::kCauchy:
      return std::make_unique<ceres::CauchyLoss>(options.loss_scale_px);
    case CalibrationOptions::Loss::kTrivial:
      break;
  }
  return nullptr;
}

Rigid3 FromRvecTvec(const cv::Vec3d& rvec, const cv::Vec3d& tvec) {
  cv::Matx33d r;
  cv::Rodrigues(rvec, r);
  Rigid3 pose;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) pose.R(i, j) = r(i, j);
    pose.t(i) = tvec[i];
  }
  return pose;
}

cv::Mat DistortionMat(const CameraIntrinsics& cam) {
  if (cam.distortion.empty()) return cv::Mat();
  return cv::Mat(cam.distortion, true);
}

void ValidateProblem(const CalibrationProblem& problem,
                     const CalibrationOptions& options) {
  options.Check();
  const size_t nc = problem.cameras.size();
  Require(nc >= 1 && nc <= kMaxCameras,
          "camera calibration: expected 1 to " + std::to_string(kMaxCameras) +
              " cameras, got " + std::to_string(nc));
  for (const CameraIntrinsics& cam : problem.cameras) {
    Require(cam.width > 0 && cam.height > 0,
            "camera calibration: camera '" + cam.name +
                "' has no image size (" + std::to_string(cam.width) + "x" +
                std::to_string(cam.height) + ")");
  }
  for (const CalibrationView& view : problem.views) {
    KINCAL_CHECK(view.observations.size() == nc,
                 "view " << view.label << " has " << view.observations.size()
                         << " observations for " << nc << " cameras");
    for (const TargetObservation& obs : view.observations) {
      KINCAL_CHECK(obs.pixels.size() == obs.p_in_target.size(),
                   "view " << view.label << ": " << obs.pixels.size()
                           << " pixels for " << obs.p_in_target.size()
                           << " target points");
    }
  }
}

// Start values of every camera's cam_from_rig: breadth first from the
// reference camera, each new camera d from an already placed camera c with
// which it shares the most views, cam_d_from_cam_c averaged over those views
// (quaternion mean, mean translation). Every camera is connected
// (UnconnectedCameras is checked before).
void ConnectCameras(const CalibrationProblem& problem,
                    const std::vector<std::vector<Rigid3>>& cam_from_target,
                    const std::vector<std::vector<bool>>& seen, State* s) {
  const size_t nc = problem.cameras.size();
  const size_t nv = problem.views.size();
  std::vector<bool> placed(nc, false);
  placed[0] = true;
  std::vector<Rigid3> cam_from_rig(nc);
  for (size_t round = 1; round < nc; ++round) {
    int best_c = -1, best_d = -1, best_n = 0;
    for (size_t d = 0; d < nc; ++d) {
      if (placed[d]) continue;
      for (size_t c = 0; c < nc; ++c) {
        if (!placed[c]) continue;
        int n = 0;
        for (size_t v = 0; v < nv; ++v) n += seen[c][v] && seen[d][v];
        if (n > best_n) best_c = c, best_d = d, best_n = n;
      }
    }
    if (best_d < 0) {
      throw InputError(
          "camera calibration: camera '" +
          problem
              .cameras[std::find(placed.begin(), placed.end(), false) -
                       placed.begin()]
              .name +
          "' shares no view of the target with the others");
    }
    Eigen::Vector4d q_sum = Eigen::Vector4d::Zero();
    Eigen::Vector3d t_sum = Eigen::Vector3d::Zero();
    Eigen::Quaterniond q_ref = Eigen::Quaterniond::Identity();
    int n = 0;
    for (size_t v = 0; v < nv; ++v) {
      if (!seen[best_c][v] || !seen[best_d][v]) continue;
      const Rigid3 d_from_c =
          cam_from_target[best_d][v] * cam_from_target[best_c][v].Inverse();
      Eigen::Quaterniond q(d_from_c.R);
      if (n == 0) q_ref = q;
      if (q.coeffs().dot(q_ref.coeffs()) < 0) q.coeffs() *= -1;
      q_sum += q.coeffs();
      t_sum += d_from_c.t;
      ++n;
    }
    Rigid3 d_from_c;
    d_from_c.R = Eigen::Quaterniond(q_sum / n).normalized().toRotationMatrix();
    d_from_c.t = t_sum / n;
    cam_from_rig[best_d] = d_from_c * cam_from_rig[best_c];
    s->cam_from_rig[best_d] = PoseBlock::From(cam_from_rig[best_d]);
    placed[best_d] = true;
  }
}

// OpenCV initial values: cv::calibrateCamera per camera, the extrinsics as
// the mean over the views both cameras see.
State Initialize(const CalibrationProblem& problem,
                 const CalibrationOptions& options,
                 std::vector<double>* opencv_rms) {
  const size_t nc = problem.cameras.size();
  const size_t nv = problem.views.size();
  State s;
  s.intrinsics.resize(nc);
  s.cam_from_rig.resize(nc);
  s.rig_from_target.resize(nv);
  s.view_used.assign(nv, false);
  for (const CameraIntrinsics& cam : problem.cameras) {
    s.image_centre.emplace_back((cam.width - 1) / 2.0, (cam.height - 1) / 2.0);
  }
  opencv_rms->assign(nc, kNaN);
  std::vector<Eigen::Vector3d> all_points;
  for (const CalibrationView& view : problem.views) {
    for (const TargetObservation& obs : view.observations) {
      all_points.insert(all_points.end(), obs.p_in_target.begin(),
                        obs.p_in_target.end());
    }
  }
  s.board_extent = BoardExtent::Of(all_points);
  // cam_from_target[c][v], valid where seen[c][v].
  std::vector<std::vector<Rigid3>> cam_from_target(nc, std::vector<Rigid3>(nv));
  std::vector<std::vector<bool>> seen(nc, std::vector<bool>(nv, false));

  int flags = 0;
  switch (options.num_distortion) {
    case 0:
      flags = cv::CALIB_FIX_K1 | cv::CALIB_FIX_K2 | cv::CALIB_FIX_K3 |
              cv::CALIB_ZERO_TANGENT_DIST;
      break;
    case 4:
      flags = cv::CALIB_FIX_K3;
      break;
    case 8:
      // The rational terms start at 0 (OpenCV's 5-coefficient fit): OpenCV's
      // own rational fit pairs large numerator and denominator terms that
      // cancel, and from there the solve did not converge within 200
      // iterations even regularised (docs/CAMCAL.md).
      break;
    default:
      break;
  }
  for (size_t c = 0; c < nc; ++c) {
    const CameraIntrinsics& cam = problem.cameras[c];
    std::vector<std::vector<cv::Point3f>> object_points;
    std::vector<std::vector<cv::Point2f>> image_points;
    std::vector<size_t> view_index;
    for (size_t v = 0; v < nv; ++v) {
      const TargetObservation& obs = problem.views[v].observations[c];
      if (!UsableObservation(obs, options)) continue;
      object_points.emplace_back();
      image_points.emplace_back();
      for (size_t i = 0; i < obs.pixels.size(); ++i) {
        object_points.back().emplace_back(obs.p_in_target[i].x(),
                                          obs.p_in_target[i].y(),
                                          obs.p_in_target[i].z());
        image_points.back().emplace_back(obs.pixels[i].x(), obs.pixels[i].y());
      }
      view_index.push_back(v);
    }
    if (static_cast<int>(view_index.size()) < options.min_views) {
      throw InputError("camera '" + cam.name + "': the target was found in " +
                       std::to_string(view_index.size()) +
                       " views with at least " +
                       std::to_string(options.min_points_per_view) +
                       " points; calibration needs at least " +
                       std::to_string(options.min_views));
    }
    cv::Mat K, dist;
    std::vector<cv::Mat> rvecs, tvecs;
    (*opencv_rms)[c] = cv::calibrateCamera(
        object_points, image_points, cv::Size(cam.width, cam.height), K, dist,
        rvecs, tvecs, flags,
        cv::TermCriteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 100,
                         1e-12));
    std::array<double, kNumIntrinsics>& a = s.intrinsics[c];
    a.fill(0.0);
    a[kFx] = K.at<double>(0, 0);
    a[kFy] = K.at<double>(1, 1);
    a[kCx] = K.at<double>(0, 2);
    a[kCy] = K.at<double>(1, 2);
    for (int i = 0;
         i < options.num_distortion && i < static_cast<int>(dist.total());
         ++i) {
      a[kK1 + i] = dist.at<double>(i);
    }
    for (size_t k = 0; k < view_index.size(); ++k) {
      cam_from_target[c][view_index[k]] =
          FromRvecTvec(cv::Vec3d(rvecs[k]), cv::Vec3d(tvecs[k]));
      seen[c][view_index[k]] = true;
    }
  }

  ConnectCameras(problem, cam_from_target, seen, &s);
  // Each view's pose from the first camera that saw it.
  for (size_t v = 0; v < nv; ++v) {
    for (size_t c = 0; c < nc && !s.view_used[v]; ++c) {
      if (!seen[c][v]) continue;
      const Rigid3 cam_from_rig =
          c == 0 ? Rigid3() : s.cam_from_rig[c].ToRigid3();
      s.rig_from_target[v] =
          PoseBlock::From(cam_from_rig.Inverse() * cam_from_target[c][v]);
      s.view_used[v] = true;
    }
  }
  return s;
}

// The reprojection cost of one target point seen by camera c, flat or warped.
ceres::CostFunction* PointCost(const Eigen::Vector3d& p_in_target,
                               const Eigen::Vector2d& pixel, size_t c,
                               bool warp, const State& s) {
  if (warp) {
    return c == 0 ? WarpedTargetReprojectionError::Create(p_in_target, pixel,
                                                          s.board_extent)
                  : WarpedRigTargetReprojectionError::Create(p_in_target, pixel,
                                                             s.board_extent);
  }
  return c == 0 ? TargetReprojectionError::Create(p_in_target, pixel)
                : RigTargetReprojectionError::Create(p_in_target, pixel);
}

// PointCost's parameter blocks, in its order.
std::vector<double*> PointBlocks(size_t c, size_t v, bool warp, State* s) {
  std::vector<double*> blocks = {s->intrinsics[c].data()};
  if (c > 0) {
    blocks.push_back(s->cam_from_rig[c].q.data());
    blocks.push_back(s->cam_from_rig[c].t.data());
  }
  blocks.push_back(s->rig_from_target[v].q.data());
  blocks.push_back(s->rig_from_target[v].t.data());
  if (warp) blocks.push_back(s->board_warp.data());
  return blocks;
}

// Adds every usable observation of the used views to `problem`. Camera
// blocks are held constant unless `refine_cameras`; the board warp is
// estimated only when refining the cameras with options.board_warp.
int BuildProblem(const std::vector<CalibrationView>& views,
                 const CalibrationOptions& options, bool refine_cameras,
                 State* s, ceres::Problem* problem) {
  const size_t nc = s->intrinsics.size();
  const bool warp = options.board_warp && refine_cameras;
  int num_points = 0;
  for (size_t v = 0; v < views.size(); ++v) {
    if (!s->view_used[v]) continue;
    PoseBlock& pose = s->rig_from_target[v];
    for (size_t c = 0; c < nc; ++c) {
      const TargetObservation& obs = views[v].observations[c];
      if (!UsableObservation(obs, options)) continue;
      for (size_t i = 0; i < obs.pixels.size(); ++i) {
        problem->AddResidualBlock(
            PointCost(obs.p_in_target[i], obs.pixels[i], c, warp, *s),
            MakeLoss(options).release(), PointBlocks(c, v, warp, s));
        ++num_points;
      }
    }
    if (problem->HasParameterBlock(pose.q.data())) {
      problem->SetManifold(pose.q.data(), new ceres::EigenQuaternionManifold);
    }
  }
  for (size_t c = 0; c < nc; ++c) {
    double* intr = s->intrinsics[c].data();
    if (!problem->HasParameterBlock(intr)) continue;
    if (!refine_cameras) {
      problem->SetParameterBlockConstant(intr);
    } else {
      // Coefficients beyond the model are fixed at 0.
      std::vector<int> fixed;
      for (int i = kK1 + options.num_distortion; i < kNumIntrinsics; ++i) {
        fixed.push_back(i);
      }
      if (!fixed.empty()) {
        problem->SetManifold(intr,
                             new ceres::SubsetManifold(kNumIntrinsics, fixed));
      }
    }
    if (c > 0 && problem->HasParameterBlock(s->cam_from_rig[c].q.data())) {
      problem->SetManifold(s->cam_from_rig[c].q.data(),
                           new ceres::EigenQuaternionManifold);
      if (!refine_cameras) {
        problem->SetParameterBlockConstant(s->cam_from_rig[c].q.data());
        problem->SetParameterBlockConstant(s->cam_from_rig[c].t.data());
      }
    }
  }
  return num_points;
}

// Pixel residual coordinates (2 per corner) of camera c in the used views.
int NumPixelResiduals(const std::vector<CalibrationView>& views,
                      const CalibrationOptions& options, const State& s,
                      size_t c) {
  int num = 0;
  for (size_t v = 0; v < views.size(); ++v) {
    const TargetObservation& obs = views[v].observations[c];
    if (s.view_used[v] && UsableObservation(obs, options)) {
      num += 2 * static_cast<int>(obs.pixels.size());
    }
  }
  return num;
}

// The scales of one camera's regularisers (0 = that regulariser is off).
struct RegularizationScales {
  double rational = 0;    // k4..k6 (RationalDistortionRegularizationError)
  double distortion = 0;  // every coefficient (LensRegularizationError)
  double centre = 0;      // principal point, per px (LensRegularizationError)
};

// mrcal's sizing of its lens regularisation (measured from
// mrcal.optimizer_callback: identical scales): the distortion terms and the
// principal-point terms each cost 0.25 % of the cost of 0.1 px errors on
// every pixel residual when the coefficients are 0.2 and the principal
// point is 50 px off centre:
//   distortion_scale^2 = w * N * 0.0025 * 0.1^2 / (n_distortion * 0.2^2)
//   centre_scale^2     = w * N * 0.0025 * 0.1^2 / (2 * 50^2)
// with N the camera's pixel residuals and w = options.lens_regularization.
constexpr double kLensRegularizationShare = 0.0025;
constexpr double kNormalPixelErrorPx = 0.1;
constexpr double kNormalDistortion = 0.2;
constexpr double kNormalCentreOffsetPx = 50.0;

// Adds every camera's regularisers to `problem`: the rational-term one
// (options.regularization, 8-coefficient model) and mrcal's lens
// regulariser (options.lens_regularization); returns their scales per
// camera (all 0 for a camera that saw nothing).
std::vector<RegularizationScales> AddRegularizers(
    const std::vector<CalibrationView>& views,
    const CalibrationOptions& options, State* s, ceres::Problem* problem) {
  using Rational = RationalDistortionRegularizationError;
  const size_t nc = s->intrinsics.size();
  std::vector<RegularizationScales> scales(nc);
  const bool rational = options.regularization > 0 &&
                        kK1 + options.num_distortion > Rational::kK4;
  const bool lens = options.lens_regularization > 0;
  for (size_t c = 0; c < nc; ++c) {
    double* intrinsics = s->intrinsics[c].data();
    if (!problem->HasParameterBlock(intrinsics)) continue;
    const double num = NumPixelResiduals(views, options, *s, c);
    if (rational) {
      scales[c].rational =
          std::sqrt(options.regularization * num / Rational::kNumRational);
      problem->AddResidualBlock(Rational::Create(scales[c].rational), nullptr,
                                intrinsics);
    }
    if (!lens) continue;
    const double pixel_cost = options.lens_regularization * num *
                              kLensRegularizationShare * kNormalPixelErrorPx *
                              kNormalPixelErrorPx;
    if (options.num_distortion > 0) {
      scales[c].distortion =
          std::sqrt(pixel_cost / (options.num_distortion * kNormalDistortion *
                                  kNormalDistortion));
    }
    scales[c].centre = std::sqrt(
        pixel_cost / (2 * kNormalCentreOffsetPx * kNormalCentreOffsetPx));
    problem->AddResidualBlock(
        LensRegularizationError::Create(scales[c].distortion, scales[c].centre,
                                        s->image_centre[c].x(),
                                        s->image_centre[c].y()),
        nullptr, intrinsics);
  }
  return scales;
}

// The regularisers' part of the final cost.
double RegularizationCost(const State& s,
                          const std::vector<RegularizationScales>& scales) {
  double cost = 0;
  for (size_t c = 0; c < scales.size(); ++c) {
    const std::array<double, kNumIntrinsics>& intr = s.intrinsics[c];
    for (int i = kK1; i < kNumIntrinsics; ++i) {
      const double r = scales[c].distortion * intr[i];
      cost += 0.5 * r * r;
    }
    for (int i = RationalDistortionRegularizationError::kK4; i < kNumIntrinsics;
         ++i) {
      const double r = scales[c].rational * intr[i];
      cost += 0.5 * r * r;
    }
    const double dx = scales[c].centre * (intr[kCx] - s.image_centre[c].x());
    const double dy = scales[c].centre * (intr[kCy] - s.image_centre[c].y());
    cost += 0.5 * (dx * dx + dy * dy);
  }
  return cost;
}

ceres::Solver::Options SolverOptions(const CalibrationOptions& options) {
  ceres::Solver::Options solver;
  solver.linear_solver_type = ceres::DENSE_SCHUR;
  solver.max_num_iterations = options.max_iterations;
  solver.function_tolerance = 1e-12;
  solver.gradient_tolerance = 1e-12;
  solver.parameter_tolerance = 1e-12;
  solver.num_threads = 1;  // deterministic, and the machine is shared
  solver.logging_type = ceres::SILENT;
  return solver;
}

// Point residuals (pixel error norms) per camera and view.
struct Residuals {
  std::vector<std::vector<std::vector<double>>> norms;  // [c][v][point]
  // projected - detected, [c][v][point]; NaN behind the camera.
  std::vector<std::vector<std::vector<Eigen::Vector2d>>> errors;
  // Detected pixel and residual vector (projected - detected) of every
  // point with a finite residual: [c] -> (pixel, residual).
  std::vector<std::vector<std::pair<Eigen::Vector2d, Eigen::Vector2d>>> vectors;
};

Residuals ComputeResiduals(const std::vector<CalibrationView>& views,
                           const CalibrationOptions& options, const State& s) {
  const size_t nc = s.intrinsics.size();
  Residuals r;
  r.norms.assign(nc, std::vector<std::vector<double>>(views.size()));
  r.errors.assign(nc, std::vector<std::vector<Eigen::Vector2d>>(views.size()));
  r.vectors.resize(nc);
  for (size_t v = 0; v < views.size(); ++v) {
    if (!s.view_used[v]) continue;
    const Rigid3 rig_from_target = s.rig_from_target[v].ToRigid3();
    for (size_t c = 0; c < nc; ++c) {
      const TargetObservation& obs = views[v].observations[c];
      if (!UsableObservation(obs, options)) continue;
      const Rigid3 cam_from_target =
          s.cam_from_rig[c].ToRigid3() * rig_from_target;
      for (size_t i = 0; i < obs.pixels.size(); ++i) {
        const Eigen::Vector3d p_in_cam =
            cam_from_target * WarpedPoint(obs.p_in_target[i], s.board_extent,
                                          s.board_warp.data());
        Eigen::Vector2d px;
        Eigen::Vector2d error(kNaN, kNaN);
        if (ProjectPoint(s.intrinsics[c].data(), p_in_cam.data(), px.data())) {
          error = px - obs.pixels[i];
          r.vectors[c].emplace_back(obs.pixels[i], error);
        }
        r.norms[c][v].push_back(error.norm());
        r.errors[c][v].push_back(error);
      }
    }
  }
  return r;
}

ImageResidualGrid GridOverImage(
    const std::vector<std::pair<Eigen::Vector2d, Eigen::Vector2d>>& vectors,
    int width, int height, int cols, int rows) {
  ImageResidualGrid g;
  g.cols = cols;
  g.rows = rows;
  g.cell_w_px = static_cast<double>(width) / cols;
  g.cell_h_px = static_cast<double>(height) / rows;
  const size_t n = static_cast<size_t>(cols) * rows;
  g.count.assign(n, 0);
  std::vector<double> ss(n, 0.0), sx(n, 0.0), sy(n, 0.0);
  for (const auto& [pixel, e] : vectors) {
    const int i =
        std::clamp(static_cast<int>(pixel.x() / g.cell_w_px), 0, cols - 1);
    const int j =
        std::clamp(static_cast<int>(pixel.y() / g.cell_h_px), 0, rows - 1);
    const size_t k = static_cast<size_t>(j) * cols + i;
    ++g.count[k];
    ss[k] += e.squaredNorm();
    sx[k] += e.x();
    sy[k] += e.y();
  }
  for (size_t k = 0; k < n; ++k) {
    const double m = g.count[k];
    g.rms_px.push_back(m > 0 ? std::sqrt(ss[k] / m) : kNaN);
    g.mean_dx_px.push_back(m > 0 ? sx[k] / m : kNaN);
    g.mean_dy_px.push_back(m > 0 ? sy[k] / m : kNaN);
  }
  return g;
}

double Rms(const std::vector<double>& values) {
  if (values.empty()) return kNaN;
  double ss = 0;
  for (double x : values) ss += x * x;
  return std::sqrt(ss / values.size());
}

// Fits only the view poses of `views` with the cameras of `rig` fixed;
// returns per camera the sum of squared point errors and the count.
void HeldOutSums(const Rig& rig, const std::vector<CalibrationView>& views,
                 const CalibrationOptions& options, std::vector<double>* ss,
                 std::vector<int>* count) {
  const size_t nc = rig.cameras.size();
  ss->assign(nc, 0.0);
  count->assign(nc, 0);
  for (const CalibrationView& view : views) {
    // Initial pose: PnP in the first camera that saw the target.
    State s;
    s.view_used = {false};
    s.rig_from_target.resize(1);
    for (size_t c = 0; c < nc; ++c) {
      s.intrinsics.push_back(rig.cameras[c].intrinsics.ToArray());
      s.cam_from_rig.push_back(PoseBlock::From(rig.cameras[c].cam_from_rig));
    }
    for (size_t c = 0; c < nc && !s.view_used[0]; ++c) {
      const TargetObservation& obs = view.observations[c];
      if (!UsableObservation(obs, options)) continue;
      std::vector<cv::Point3d> obj;
      std::vector<cv::Point2d> img;
      for (size_t i = 0; i < obs.pixels.size(); ++i) {
        obj.emplace_back(obs.p_in_target[i].x(), obs.p_in_target[i].y(),
                         obs.p_in_target[i].z());
        img.emplace_back(obs.pixels[i].x(), obs.pixels[i].y());
      }
      cv::Mat K;
      cv::eigen2cv(rig.cameras[c].intrinsics.K(), K);
      cv::Vec3d rvec, tvec;
      if (!cv::solvePnP(obj, img, K, DistortionMat(rig.cameras[c].intrinsics),
                        rvec, tvec)) {
        continue;
      }
      const Rigid3 cam_from_target = FromRvecTvec(rvec, tvec);
      s.rig_from_target[0] = PoseBlock::From(
          rig.cameras[c].cam_from_rig.Inverse() * cam_from_target);
      s.view_used[0] = true;
    }
    if (!s.view_used[0]) continue;
    const std::vector<CalibrationView> one = {view};
    ceres::Problem problem;
    BuildProblem(one, options, /*refine_cameras=*/false, &s, &problem);
    ceres::Solver::Summary summary;
    ceres::Solve(SolverOptions(options), &problem, &summary);
    const Residuals r = ComputeResiduals(one, options, s);
    for (size_t c = 0; c < nc; ++c) {
      for (double e : r.norms[c][0]) {
        if (std::isnan(e)) continue;
        (*ss)[c] += e * e;
        ++(*count)[c];
      }
    }
  }
}

std::string TerminationName(ceres::TerminationType t) {
  return ceres::TerminationTypeToString(t);
}

}  // namespace

void CalibrationOptions::Check() const {
  Require(num_distortion == 0 || num_distortion == 4 || num_distortion == 5 ||
              num_distortion == 8,
          "calibration: num_distortion must be 0, 4, 5 or 8, got " +
              std::to_string(num_distortion));
  Require(loss_scale_px > 0, "calibration: loss_scale_px must be > 0");
  Require(min_points_per_view >= 4,
          "calibration: min_points_per_view must be >= 4");
  Require(min_views >= 2, "calibration: min_views must be >= 2");
  Require(max_iterations > 0, "calibration: max_iterations must be > 0");
  Require(max_rms_px > 0, "calibration: max_rms_px must be > 0");
  Require(regularization >= 0, "calibration: regularization must be >= 0");
  Require(lens_regularization >= 0,
          "calibration: lens_regularization must be >= 0");
  Require(uncertainty.distance > 0,
          "calibration: the uncertainty distance must be > 0");
  Require(uncertainty.valid_threshold_px > 0,
          "calibration: the valid-region threshold must be > 0 px");
}

std::string SolveFailure(const CalibrationSummary& summary,
                         const CalibrationOptions& options) {
  char text[512];
  if (!summary.converged) {
    std::snprintf(
        text, sizeof text,
        "the camera solve did not converge (%s after %d iterations, RMS "
        "%.3g px): likely too many distortion terms for the views (%d); try "
        "--distortion 5 (or 4), or record more views covering the image "
        "corners",
        summary.termination.c_str(), summary.iterations, summary.rms_px,
        options.num_distortion);
    return text;
  }
  if (!(summary.rms_px <= options.max_rms_px)) {
    std::snprintf(
        text, sizeof text,
        "the camera solve ends at an RMS of %.4g px (above %g px, no "
        "calibration): likely the wrong --target size or layout (columns x "
        "rows of inner corners or tags, the tag spacing ratio) or images of "
        "another target; check --target against the printed sheet",
        summary.rms_px, options.max_rms_px);
    return text;
  }
  return "";
}

std::vector<double> HeldOutRmsPx(const Rig& rig,
                                 const std::vector<CalibrationView>& views,
                                 const CalibrationOptions& options) {
  std::vector<double> ss;
  std::vector<int> count;
  HeldOutSums(rig, views, options, &ss, &count);
  std::vector<double> rms(ss.size(), kNaN);
  for (size_t c = 0; c < ss.size(); ++c) {
    if (count[c] > 0) rms[c] = std::sqrt(ss[c] / count[c]);
  }
  return rms;
}

ProjectionDifference ProjectionDifferenceOf(const CameraIntrinsics& a,
                                            const CameraIntrinsics& b,
                                            double focus_radius_px,
                                            int grid_width) {
  ProjectionDifference out;
  out.focus_radius_px =
      focus_radius_px > 0 ? focus_radius_px : std::min(a.width, a.height) / 3.0;
  // mrcal.sample_imager: grid_width columns over 0..width-1, rows in
  // proportion over 0..height-1.
  const int nx = std::max(grid_width, 2);
  const int ny = static_cast<int>(std::lround(static_cast<double>(a.height) /
                                              a.width * (nx - 1))) +
                 1;
  const Eigen::Vector2d centre((a.width - 1) / 2.0, (a.height - 1) / 2.0);
  std::vector<Eigen::Vector2d> pixels;
  std::vector<Eigen::Vector3d> rays_a, rays_b;
  Eigen::Matrix3d correlation = Eigen::Matrix3d::Zero();
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) {
      const Eigen::Vector2d px((a.width - 1) * i / (nx - 1.0),
                               (a.height - 1) * j / std::max(ny - 1.0, 1.0));
      const Eigen::Vector3d ray_a = Unproject(a, px);
      const Eigen::Vector3d ray_b = Unproject(b, px);
      if (!ray_a.allFinite() || !ray_b.allFinite()) continue;
      pixels.push_back(px);
      rays_a.push_back(ray_a);
      if ((px - centre).norm() <= out.focus_radius_px) {
        correlation += ray_b * ray_a.transpose();
      }
    }
  }
  // b_from_a = argmin sum |R ray_a - ray_b|^2 over the focus (Kabsch).
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(
      correlation, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d sign = Eigen::Matrix3d::Identity();
  sign(2, 2) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0
                   ? -1.0
                   : 1.0;
  const Eigen::Matrix3d b_from_a =
      svd.matrixU() * sign * svd.matrixV().transpose();
  double ss = 0, ss_focus = 0;
  int n = 0, n_focus = 0;
  for (size_t k = 0; k < pixels.size(); ++k) {
    const Eigen::Vector2d px = Project(b, b_from_a * rays_a[k]);
    if (!px.allFinite()) continue;
    const double e = (px - pixels[k]).norm();
    ss += e * e;
    out.max_px = std::max(out.max_px, e);
    ++n;
    if ((pixels[k] - centre).norm() <= out.focus_radius_px) {
      ss_focus += e * e;
      ++n_focus;
    }
  }
  out.rms_px = n ? std::sqrt(ss / n) : kNaN;
  out.focus_rms_px = n_focus ? std::sqrt(ss_focus / n_focus) : kNaN;
  if (n == 0) out.max_px = kNaN;
  return out;
}

namespace {

// The parameter blocks of the full covariance (every camera's intrinsics,
// the extrinsics of the cameras after the first, every used view's pose)
// and where each parameter sits in its tangent-space vector.
struct CovarianceLayout {
  std::vector<const double*> blocks;
  std::vector<int> rotation_index;  // first entry of each quaternion block
  CalibrationCovariance cal;        // the solve; indices; no covariance yet
  int size = 0;
};

CovarianceLayout LayoutOf(const State& s, const ceres::Problem& problem) {
  CovarianceLayout layout;
  CalibrationCovariance& cal = layout.cal;
  auto add_pose = [&](const PoseBlock& pose) {
    layout.blocks.push_back(pose.q.data());
    layout.blocks.push_back(pose.t.data());
    layout.rotation_index.push_back(layout.size);
    layout.size += 6;
    return layout.size - 6;
  };
  for (size_t c = 0; c < s.intrinsics.size(); ++c) {
    const double* block = s.intrinsics[c].data();
    layout.blocks.push_back(block);
    const ceres::Manifold* manifold = problem.GetManifold(block);
    std::array<int, kNumIntrinsics> index;
    index.fill(-1);
    // A SubsetManifold holds the trailing coefficients beyond the model.
    const int free = manifold ? manifold->TangentSize() : kNumIntrinsics;
    for (int i = 0; i < free; ++i) index[i] = layout.size + i;
    layout.size += free;
    cal.intrinsics.push_back(s.intrinsics[c]);
    cal.intrinsic_index.push_back(index);
  }
  for (size_t c = 0; c < s.intrinsics.size(); ++c) {
    cal.cam_from_rig.push_back(c == 0 ? Rigid3()
                                      : s.cam_from_rig[c].ToRigid3());
    cal.cam_from_rig_index.push_back(c == 0 ? -1 : add_pose(s.cam_from_rig[c]));
  }
  for (size_t v = 0; v < s.rig_from_target.size(); ++v) {
    if (!s.view_used[v]) continue;
    cal.rig_from_target.push_back(s.rig_from_target[v].ToRigid3());
    cal.rig_from_target_index.push_back(add_pose(s.rig_from_target[v]));
  }
  return layout;
}

// sigma of the intrinsics and, with two cameras, of the extrinsics and the
// baseline, from the covariance of the tangent vector (rotations as
// rotation vectors).
void AddSigmas(const CalibrationCovariance& cal, CalibrationSummary* out) {
  const Eigen::MatrixXd& cov = cal.covariance;
  auto sigma = [&](int i) { return std::sqrt(std::max(0.0, cov(i, i))); };
  for (size_t c = 0; c < cal.intrinsics.size(); ++c) {
    for (int i = 0; i < kNumIntrinsics; ++i) {
      const int index = cal.intrinsic_index[c][i];
      out->cameras[c].sigma.push_back(index < 0 ? 0.0 : sigma(index));
    }
  }
  if (cal.intrinsics.size() >= 2) {
    const int e = cal.cam_from_rig_index[1];
    for (int i = 0; i < 3; ++i) {
      out->extrinsic_rotation_sigma_deg.push_back(sigma(e + i) * 180.0 / M_PI);
      out->extrinsic_translation_sigma.push_back(sigma(e + 3 + i));
    }
    // baseline = |t| (camera centre distance = |R^T t| = |t|).
    const Eigen::Vector3d u = cal.cam_from_rig[1].t.normalized();
    out->baseline_sigma = std::sqrt(u.dot(cov.block<3, 3>(e + 3, e + 3) * u));
  }
}

// The full covariance of the solve scaled by the residual variance; from
// it the parameter sigma and each camera's projection uncertainty map; a
// note instead when the Jacobian is rank deficient.
void AddCovariance(const State& s, double variance,
                   const CalibrationOptions& options, ceres::Problem* problem,
                   CalibrationSummary* out) {
  CovarianceLayout layout = LayoutOf(s, *problem);
  ceres::Covariance::Options copt;
  copt.algorithm_type = ceres::DENSE_SVD;
  copt.num_threads = 1;
  ceres::Covariance covariance(copt);
  if (!covariance.Compute(layout.blocks, problem)) {
    out->covariance_note =
        "covariance not available: the Jacobian is rank deficient (the "
        "views do not determine every parameter)";
    return;
  }
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> cov(
      layout.size, layout.size);
  covariance.GetCovarianceMatrixInTangentSpace(layout.blocks, cov.data());
  cov *= variance;
  // EigenQuaternionManifold's tangent is half the rotation vector.
  for (int r : layout.rotation_index) {
    cov.middleRows(r, 3) *= 2.0;
    cov.middleCols(r, 3) *= 2.0;
  }
  CalibrationCovariance& cal = layout.cal;
  cal.covariance = cov;
  AddSigmas(cal, out);
  for (size_t c = 0; c < out->cameras.size(); ++c) {
    const CameraIntrinsics& in = out->cameras[c].intrinsics;
    out->cameras[c].projection_uncertainty = MapProjectionUncertainty(
        cal, static_cast<int>(c), in.width, in.height, options.uncertainty);
    out->rig.cameras[c].valid_intrinsics_region =
        out->cameras[c].projection_uncertainty.valid_region;
  }
}

// Even/odd views calibrated apart: each half's held-out RMS on the other
// and the projection difference between the halves' intrinsics (NaN when a
// half has too few views).
void CrossValidateHalves(const CalibrationProblem& input,
                         const CalibrationOptions& options,
                         CalibrationSummary* out) {
  const size_t nc = input.cameras.size();
  const size_t nv = input.views.size();
  // Even and odd views.
  CalibrationProblem half[2];
  for (int h = 0; h < 2; ++h) half[h].cameras = input.cameras;
  for (size_t v = 0; v < nv; ++v) half[v % 2].views.push_back(input.views[v]);
  CalibrationOptions sub = options;
  sub.cross_validate = false;
  sub.compute_covariance = false;
  try {
    const CalibrationSummary a = CalibrateCameras(half[0], sub);
    const CalibrationSummary b = CalibrateCameras(half[1], sub);
    // Held out on the inliers of the other half's own solve.
    const std::vector<double> a_on_b = HeldOutRmsPx(a.rig, b.inlier_views, sub);
    const std::vector<double> b_on_a = HeldOutRmsPx(b.rig, a.inlier_views, sub);
    for (size_t c = 0; c < nc; ++c) {
      out->cameras[c].holdout_rms_px =
          std::sqrt(0.5 * (a_on_b[c] * a_on_b[c] + b_on_a[c] * b_on_a[c]));
      const ProjectionDifference diff = ProjectionDifferenceOf(
          a.rig.cameras[c].intrinsics, b.rig.cameras[c].intrinsics,
          options.half_diff_focus_radius_px);
      CameraCalibrationSummary& cs = out->cameras[c];
      cs.half_diff_focus_radius_px = diff.focus_radius_px;
      cs.half_diff_focus_rms_px = diff.focus_rms_px;
      cs.half_diff_rms_px = diff.rms_px;
      cs.half_diff_max_px = diff.max_px;
    }
  } catch (const InputError&) {
    // Too few views in a half: cross-validation figures stay NaN.
  }
}

// One refinement of all intrinsics, view poses and extrinsics on `views`,
// starting from `s`, with the distortion regulariser.
struct Refinement {
  std::unique_ptr<ceres::Problem> problem;
  ceres::Solver::Summary solver;
  std::vector<RegularizationScales> regularization_scale;
  int num_points = 0;
};

Refinement Refine(const std::vector<CalibrationView>& views,
                  const CalibrationOptions& options, State* s) {
  Refinement r;
  r.problem = std::make_unique<ceres::Problem>();
  r.num_points =
      BuildProblem(views, options, /*refine_cameras=*/true, s, r.problem.get());
  r.regularization_scale = AddRegularizers(views, options, s, r.problem.get());
  ceres::Solve(SolverOptions(options), r.problem.get(), &r.solver);
  return r;
}

// Which corners of the problem's views the solve keeps: inlier[c][v][i];
// dropped[c][v] when the whole observation is rejected; counts per camera.
struct InlierMask {
  std::vector<std::vector<std::vector<bool>>> inlier;
  std::vector<std::vector<bool>> dropped;
  std::vector<int> rejected_corners, rejected_views;
};

InlierMask AllInliers(const CalibrationProblem& problem) {
  const size_t nc = problem.cameras.size();
  InlierMask mask;
  mask.inlier.resize(nc);
  mask.dropped.assign(nc, std::vector<bool>(problem.views.size(), false));
  mask.rejected_corners.assign(nc, 0);
  mask.rejected_views.assign(nc, 0);
  for (size_t c = 0; c < nc; ++c) {
    for (const CalibrationView& view : problem.views) {
      mask.inlier[c].emplace_back(view.observations[c].pixels.size(), true);
    }
  }
  return mask;
}

// The views with only the inlier corners.
std::vector<CalibrationView> InlierViews(
    const std::vector<CalibrationView>& views, const InlierMask& mask) {
  std::vector<CalibrationView> out;
  for (size_t v = 0; v < views.size(); ++v) {
    CalibrationView view;
    view.label = views[v].label;
    for (size_t c = 0; c < views[v].observations.size(); ++c) {
      const TargetObservation& obs = views[v].observations[c];
      TargetObservation kept;
      for (size_t i = 0; i < obs.pixels.size(); ++i) {
        if (!mask.inlier[c][v][i]) continue;
        kept.p_in_target.push_back(obs.p_in_target[i]);
        kept.pixels.push_back(obs.pixels[i]);
      }
      view.observations.push_back(std::move(kept));
    }
    out.push_back(std::move(view));
  }
  return out;
}

// RMS of the residual coordinates (x and y of every finite corner).
double CoordinateSigma(const Residuals& r) {
  double ss = 0;
  int n = 0;
  for (const auto& camera : r.errors) {
    for (const auto& view : camera) {
      for (const Eigen::Vector2d& e : view) {
        if (!e.allFinite()) continue;
        ss += e.squaredNorm();
        n += 2;
      }
    }
  }
  return n ? std::sqrt(ss / n) : kNaN;
}

// One round of outlier rejection (CalibrationOptions::reject_sigma) on the
// residuals `r` of InlierViews(views, *mask); returns whether a corner was
// rejected.
bool RejectOutliers(const std::vector<CalibrationView>& views,
                    const Residuals& r, const CalibrationOptions& options,
                    InlierMask* mask) {
  const double sigma = CoordinateSigma(r);
  const double limit = options.reject_sigma * sigma;
  const double trigger = options.reject_trigger * limit;
  auto beyond = [](const Eigen::Vector2d& e, double l) {
    return e.allFinite() && (std::abs(e.x()) > l || std::abs(e.y()) > l);
  };
  bool triggered = false;
  for (const auto& camera : r.errors) {
    for (const auto& view : camera) {
      for (const Eigen::Vector2d& e : view) triggered |= beyond(e, trigger);
    }
  }
  if (!triggered) return false;
  for (size_t c = 0; c < r.errors.size(); ++c) {
    for (size_t v = 0; v < views.size(); ++v) {
      std::vector<bool>& inlier = mask->inlier[c][v];
      const std::vector<Eigen::Vector2d>& errors = r.errors[c][v];
      if (mask->dropped[c][v] ||
          errors.size() != static_cast<size_t>(std::count(
                               inlier.begin(), inlier.end(), true))) {
        continue;  // not in the solve (too few points)
      }
      size_t k = 0;
      for (size_t i = 0; i < inlier.size(); ++i) {
        if (!inlier[i]) continue;
        if (beyond(errors[k++], limit)) {
          inlier[i] = false;
          ++mask->rejected_corners[c];
        }
      }
      const size_t kept = std::count(inlier.begin(), inlier.end(), true);
      if (2 * kept < inlier.size()) {
        inlier.assign(inlier.size(), false);
        mask->dropped[c][v] = true;
        ++mask->rejected_views[c];
      }
    }
  }
  return true;
}

// A view stays used while some camera still has a usable observation of it.
void UpdateViewsUsed(const std::vector<CalibrationView>& views,
                     const CalibrationOptions& options, State* s) {
  for (size_t v = 0; v < views.size(); ++v) {
    bool usable = false;
    for (const TargetObservation& obs : views[v].observations) {
      usable |= UsableObservation(obs, options);
    }
    s->view_used[v] = s->view_used[v] && usable;
  }
}

// Per camera: the solved intrinsics into the rig and the camera summary
// (residual statistics over `views`); the overall RMS into out->rms_px.
void SummarizeCameras(const CalibrationProblem& input,
                      const std::vector<CalibrationView>& views,
                      const CalibrationOptions& options, const State& s,
                      const std::vector<double>& opencv_rms,
                      const InlierMask& mask, CalibrationSummary* out) {
  const size_t nc = input.cameras.size();
  const Residuals res = ComputeResiduals(views, options, s);
  double ss_all = 0;
  int n_all = 0;
  for (size_t c = 0; c < nc; ++c) {
    Camera cam;
    cam.intrinsics = CameraIntrinsics::FromArray(s.intrinsics[c].data(),
                                                 options.num_distortion);
    cam.intrinsics.name = input.cameras[c].name;
    cam.intrinsics.width = input.cameras[c].width;
    cam.intrinsics.height = input.cameras[c].height;
    cam.cam_from_rig = c == 0 ? Rigid3() : s.cam_from_rig[c].ToRigid3();
    out->rig.cameras.push_back(cam);

    CameraCalibrationSummary cs;
    cs.intrinsics = cam.intrinsics;
    cs.opencv_rms_px = opencv_rms[c];
    cs.rejected_corners = mask.rejected_corners[c];
    cs.rejected_views = mask.rejected_views[c];
    std::vector<double> all;
    for (size_t v = 0; v < views.size(); ++v) {
      const std::vector<double>& e = res.norms[c][v];
      cs.view_rms_px.push_back(Rms(e));
      if (!e.empty()) ++cs.num_views;
      all.insert(all.end(), e.begin(), e.end());
    }
    cs.num_points = static_cast<int>(all.size());
    cs.rms_px = Rms(all);
    cs.image_grid = GridOverImage(res.vectors[c], input.cameras[c].width,
                                  input.cameras[c].height, 8, 6);
    for (double e : all) {
      cs.max_px = std::max(cs.max_px, e);
      ss_all += e * e;
      ++n_all;
    }
    for (double e : all) {
      if (e > options.outlier_factor * cs.rms_px) ++cs.outliers;
    }
    out->cameras.push_back(cs);
  }
  out->rms_px = n_all ? std::sqrt(ss_all / n_all) : kNaN;
  out->rejection_sigma_px = CoordinateSigma(res);
}

}  // namespace

std::vector<int> UnconnectedCameras(const CalibrationProblem& problem,
                                    const CalibrationOptions& options) {
  const size_t nc = problem.cameras.size();
  std::vector<bool> connected(nc, false);
  if (nc == 0) return {};
  connected[0] = true;
  // Grow the set through views in which a connected and an unconnected
  // camera both see the target, until nothing changes.
  for (bool grew = true; grew;) {
    grew = false;
    for (const CalibrationView& view : problem.views) {
      bool any = false;
      for (size_t c = 0; c < nc; ++c) {
        any = any || (connected[c] &&
                      UsableObservation(view.observations[c], options));
      }
      if (!any) continue;
      for (size_t c = 0; c < nc; ++c) {
        if (!connected[c] && UsableObservation(view.observations[c], options)) {
          connected[c] = true;
          grew = true;
        }
      }
    }
  }
  std::vector<int> out;
  for (size_t c = 0; c < nc; ++c) {
    if (!connected[c]) out.push_back(static_cast<int>(c));
  }
  return out;
}

std::string UnconnectedMessage(const CalibrationProblem& problem,
                               const std::vector<int>& unconnected) {
  std::string names;
  for (int c : unconnected) {
    names += (names.empty() ? "'" : ", '") + problem.cameras[c].name + "'";
  }
  return "camera" + std::string(unconnected.size() > 1 ? "s " : " ") + names +
         " never see" + (unconnected.size() > 1 ? "" : "s") +
         " the target in the same view as the reference camera '" +
         problem.cameras[0].name + "' or a camera connected to it, so " +
         (unconnected.size() > 1 ? "their" : "its") +
         " pose in the rig is not determined: record views in which the "
         "board is seen by " +
         (unconnected.size() > 1 ? "each of them" : "it") +
         " and by an already connected camera at once (a chain of shared "
         "views is enough)";
}

CalibrationSummary CalibrateCameras(const CalibrationProblem& input,
                                    const CalibrationOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  ValidateProblem(input, options);
  const std::vector<int> unconnected = UnconnectedCameras(input, options);
  if (!unconnected.empty()) {
    throw InputError(UnconnectedMessage(input, unconnected));
  }
  const size_t nc = input.cameras.size();
  const size_t nv = input.views.size();

  CalibrationSummary out;
  std::vector<double> opencv_rms;
  State s = Initialize(input, options, &opencv_rms);

  // Solve, reject outliers, solve again on the inliers until none is left.
  InlierMask mask = AllInliers(input);
  std::vector<CalibrationView> views = input.views;
  Refinement refined = Refine(views, options, &s);
  while (options.reject_sigma > 0 &&
         out.rejection_rounds < options.max_rejection_rounds &&
         RejectOutliers(views, ComputeResiduals(views, options, s), options,
                        &mask)) {
    ++out.rejection_rounds;
    views = InlierViews(input.views, mask);
    UpdateViewsUsed(views, options, &s);
    refined = Refine(views, options, &s);
  }
  const ceres::Solver::Summary& solver_summary = refined.solver;
  out.termination = TerminationName(solver_summary.termination_type);
  out.converged = solver_summary.termination_type == ceres::CONVERGENCE;
  out.iterations = static_cast<int>(solver_summary.iterations.size()) - 1;
  out.initial_cost = solver_summary.initial_cost;
  out.final_cost = solver_summary.final_cost;
  out.regularization_cost = RegularizationCost(s, refined.regularization_scale);
  if (out.final_cost > 0) {
    out.regularization_share = out.regularization_cost / out.final_cost;
  }

  SummarizeCameras(input, views, options, s, opencv_rms, mask, &out);
  out.baseline = out.rig.BaselineMm();
  out.view_used = s.view_used;
  out.board_warp = s.board_warp;
  for (size_t v = 0; v < nv; ++v) {
    out.rig_from_target.push_back(s.rig_from_target[v].ToRigid3());
  }

  // Residual variance per coordinate: sum r^2 / (m - n).
  double ss_all = 0;
  for (const CameraCalibrationSummary& cs : out.cameras) {
    ss_all += cs.rms_px * cs.rms_px * cs.num_points;
  }
  int num_free = 0;
  for (size_t v = 0; v < nv; ++v) num_free += s.view_used[v] ? 6 : 0;
  num_free += static_cast<int>(nc) * (4 + options.num_distortion);
  num_free += static_cast<int>(nc - 1) * 6;
  if (options.board_warp) num_free += 2;
  const int dof = 2 * refined.num_points - num_free;
  const double variance = dof > 0 ? ss_all / dof : kNaN;
  out.residual_sigma_px = std::sqrt(variance);

  if (options.compute_covariance && dof > 0) {
    AddCovariance(s, variance, options, refined.problem.get(), &out);
  }
  out.inlier_views = std::move(views);
  if (options.cross_validate) CrossValidateHalves(input, options, &out);
  out.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
          .count();
  return out;
}

}  // namespace kincal
