#include "vision/tool_pose.h"

#include <ceres/ceres.h>
#include <ceres/rotation.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <map>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>
#include <sstream>

#include "camcal/cost_functions.h"
#include "data/error.h"
#include "vision/triangulate.h"

namespace kincal {

namespace {

// One tag seen by one camera, with its target placement.
struct TagObs {
  int camera = 0;
  const TagDetection* det = nullptr;
  const TargetTag* tag = nullptr;
  // The corners the fit uses (the detection's, or libapriltag's where the
  // per-corner check swapped them back) and which of them take part.
  std::array<Eigen::Vector2d, 4> px;
  std::array<bool, 4> use = {true, true, true, true};
  std::string left_out;  // reason code when not used
};

// The weakest side's contrast (0 when the edge refinement did not run).
double Contrast(const TagDetection& d) {
  double c = 1e9;
  for (const TagSideQuality& s : d.sides) c = std::min(c, s.contrast);
  return d.sides[0].points > 0 ? c : 0.0;
}

// Angle between the tag's normal and the ray from the camera to its centre.
double ObliquityDeg(const Camera& cam, const Rigid3& rig_from_tool,
                    const TargetTag& tag) {
  const Rigid3 cam_from_tag =
      cam.cam_from_rig * rig_from_tool * tag.tool_from_tag;
  const Eigen::Vector3d ray = cam_from_tag.t.normalized();
  const double c = std::abs(ray.dot(cam_from_tag.R.col(2)));
  return std::acos(std::min(1.0, c)) * 180 / M_PI;
}

// Whether the used tag observations without `drop` still determine the
// pose: two or more, in every camera that has one now.
bool DeterminedWithout(const std::vector<TagObs>& obs,
                       const std::vector<bool>& used, size_t drop) {
  std::map<int, int> now, after;
  for (size_t i = 0; i < obs.size(); ++i) {
    if (!used[i]) continue;
    ++now[obs[i].camera];
    if (i != drop) ++after[obs[i].camera];
  }
  int left = 0;
  for (const auto& [camera, count] : now) {
    if (after[camera] == 0) return false;
    left += after[camera];
  }
  return left >= 2;
}

// Whether the detector's edge refinement ran on the tag (TagDetection's
// sides filled, or a corner refined).
bool Refined(const TagDetection& d) {
  return d.sides[0].points > 0 ||
         std::count(d.refined.begin(), d.refined.end(), true) > 0;
}

// Tag observations the edge refinement could not refine keep libapriltag's
// corners, 1-2 px off on 1-2 % of the corners (bench/corner_bench.cc): when
// other observations were refined, each such one is left out ("unrefined")
// while the rest still determine the pose (DeterminedWithout).
void LeaveOutUnrefined(std::vector<TagObs>* obs, std::vector<bool>* used) {
  bool any_refined = false;
  for (const TagObs& o : *obs) any_refined = any_refined || Refined(*o.det);
  if (!any_refined) return;
  for (size_t i = 0; i < obs->size(); ++i) {
    if ((*used)[i] && !Refined(*(*obs)[i].det) &&
        DeterminedWithout(*obs, *used, i)) {
      (*used)[i] = false;
      (*obs)[i].left_out = "unrefined";
    }
  }
}

std::vector<TagObs> CollectObservations(
    const Rig& rig, const Target& target,
    const std::vector<std::vector<TagDetection>>& detections) {
  std::vector<TagObs> obs;
  const size_t n = std::min(rig.cameras.size(), detections.size());
  for (size_t c = 0; c < n; ++c) {
    std::map<int, int> count;
    for (const auto& d : detections[c]) ++count[d.id];
    for (const auto& d : detections[c]) {
      const TargetTag* tag = target.FindTag(d.id);
      if (tag == nullptr || count[d.id] != 1) continue;
      TagObs o;
      o.camera = static_cast<int>(c);
      o.det = &d;
      o.tag = tag;
      o.px = d.corners;
      o.use = d.usable;
      obs.push_back(o);
    }
  }
  return obs;
}

// Rigid transform b_from_a minimizing sum |b_i - (R a_i + t)|^2 (Kabsch).
Rigid3 Kabsch(const std::vector<Eigen::Vector3d>& a,
              const std::vector<Eigen::Vector3d>& b) {
  Eigen::Vector3d ma = Eigen::Vector3d::Zero(), mb = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < a.size(); ++i) {
    ma += a[i];
    mb += b[i];
  }
  ma /= static_cast<double>(a.size());
  mb /= static_cast<double>(b.size());
  Eigen::Matrix3d H = Eigen::Matrix3d::Zero();
  for (size_t i = 0; i < a.size(); ++i) {
    H += (a[i] - ma) * (b[i] - mb).transpose();
  }
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(
      H, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d D = Eigen::Matrix3d::Identity();
  if ((svd.matrixV() * svd.matrixU().transpose()).determinant() < 0) {
    D(2, 2) = -1;
  }
  Rigid3 out;
  out.R = svd.matrixV() * D * svd.matrixU().transpose();
  out.t = mb - out.R * ma;
  return out;
}

double TagRms(const Camera& cam, const Rigid3& rig_from_tool, const TagObs& o) {
  double sum = 0;
  int n = 0;
  for (int k = 0; k < 4; ++k) {
    if (!o.use[k]) continue;
    const Eigen::Vector3d p_in_cam =
        cam.cam_from_rig * (rig_from_tool * o.tag->CornerInTool(k));
    const Eigen::Vector2d px = Project(cam.intrinsics, p_in_cam);
    if (!px.allFinite()) return 1e9;
    sum += (px - o.px[k]).squaredNorm();
    ++n;
  }
  return n > 0 ? std::sqrt(sum / n) : 1e9;
}

bool InitialFromObservations(const Rig& rig, const std::vector<TagObs>& obs,
                             Rigid3* rig_from_tool) {
  // Triangulate corners of tags seen by two or more cameras.
  std::map<int, std::vector<const TagObs*>> by_id;
  for (const auto& o : obs) by_id[o.tag->id].push_back(&o);
  std::vector<Eigen::Vector3d> in_tool, in_rig;
  for (const auto& kv : by_id) {
    if (kv.second.size() < 2) continue;
    for (int k = 0; k < 4; ++k) {
      std::vector<PixelObservation> px;
      for (const TagObs* o : kv.second) {
        if (o->use[k]) px.push_back({o->camera, o->det->corners[k]});
      }
      if (px.size() < 2) continue;
      TriangulationOptions topt;
      topt.refine = false;
      const TriangulatedPoint p = TriangulatePoint(rig, px, topt);
      if (!p.ok) continue;
      in_tool.push_back(kv.second.front()->tag->CornerInTool(k));
      in_rig.push_back(p.p_in_rig);
    }
  }
  if (in_tool.size() >= 4) {
    *rig_from_tool = Kabsch(in_tool, in_rig);
    return true;
  }
  // PnP in the camera that sees the most tags.
  std::map<int, int> per_camera;
  for (const auto& o : obs) ++per_camera[o.camera];
  int best = -1, best_count = 0;
  for (const auto& kv : per_camera) {
    if (kv.second > best_count) {
      best = kv.first;
      best_count = kv.second;
    }
  }
  if (best < 0) return false;
  std::vector<cv::Point3d> object;
  std::vector<cv::Point2d> image;
  for (const auto& o : obs) {
    if (o.camera != best) continue;
    for (int k = 0; k < 4; ++k) {
      if (!o.use[k]) continue;
      const Eigen::Vector3d p = o.tag->CornerInTool(k);
      object.emplace_back(p.x(), p.y(), p.z());
      image.emplace_back(o.det->corners[k].x(), o.det->corners[k].y());
    }
  }
  const CameraIntrinsics& K = rig.cameras[best].intrinsics;
  cv::Mat camera_matrix =
      (cv::Mat_<double>(3, 3) << K.fx, 0, K.cx, 0, K.fy, K.cy, 0, 0, 1);
  cv::Mat dist(K.distortion);
  cv::Mat rvec, tvec;
  bool ok = false;
  try {
    ok = cv::solvePnP(
        object, image, camera_matrix, dist, rvec, tvec, false,
        object.size() == 4 ? cv::SOLVEPNP_IPPE : cv::SOLVEPNP_SQPNP);
  } catch (const cv::Exception&) {
    ok = false;
  }
  if (!ok) return false;
  cv::Mat Rcv;
  cv::Rodrigues(rvec, Rcv);
  Rigid3 cam_from_tool;
  cv::cv2eigen(Rcv, cam_from_tool.R);
  cam_from_tool.t = Eigen::Vector3d(tvec.at<double>(0), tvec.at<double>(1),
                                    tvec.at<double>(2));
  *rig_from_tool = rig.cameras[best].cam_from_rig.Inverse() * cam_from_tool;
  return rig_from_tool->t.allFinite();
}

// Fits rig_from_tool to the used observations; returns false when Ceres
// could not produce a usable solution.
bool FitPose(const Rig& rig, const std::vector<TagObs>& obs,
             const std::vector<bool>& used, double huber_px, int max_iterations,
             Rigid3* rig_from_tool) {
  const Eigen::Quaterniond q0(rig_from_tool->R);
  double q[4] = {q0.w(), q0.x(), q0.y(), q0.z()};
  double t[3] = {rig_from_tool->t.x(), rig_from_tool->t.y(),
                 rig_from_tool->t.z()};
  // Non-finite guard: nothing non-finite may reach Ceres (its manifold
  // CHECKs abort the process instead of failing the solve).
  for (double v : q)
    if (!std::isfinite(v)) return false;
  for (double v : t)
    if (!std::isfinite(v)) return false;
  for (size_t i = 0; i < obs.size(); ++i) {
    if (!used[i]) continue;
    for (int k = 0; k < 4; ++k) {
      if (!obs[i].tag->CornerInTool(k).allFinite() ||
          !obs[i].det->corners[k].allFinite()) {
        return false;
      }
    }
  }
  ceres::Problem problem;
  for (size_t i = 0; i < obs.size(); ++i) {
    if (!used[i]) continue;
    const Camera& cam = rig.cameras[obs[i].camera];
    for (int k = 0; k < 4; ++k) {
      if (!obs[i].use[k]) continue;
      problem.AddResidualBlock(
          ToolCornerReprojectionCost::Create(obs[i].px[k],
                                             obs[i].tag->CornerInTool(k), cam),
          huber_px > 0 ? new ceres::HuberLoss(huber_px) : nullptr, q, t);
    }
  }
  problem.SetManifold(q, new ceres::QuaternionManifold());
  ceres::Solver::Options so;
  so.linear_solver_type = ceres::DENSE_QR;
  so.max_num_iterations = max_iterations;
  so.num_threads = 1;
  so.logging_type = ceres::SILENT;
  so.function_tolerance = 1e-12;
  so.gradient_tolerance = 1e-12;
  so.parameter_tolerance = 1e-12;
  ceres::Solver::Summary summary;
  ceres::Solve(so, &problem, &summary);
  if (!summary.IsSolutionUsable()) return false;
  const Eigen::Quaterniond qs(q[0], q[1], q[2], q[3]);
  rig_from_tool->R = qs.normalized().toRotationMatrix();
  rig_from_tool->t = Eigen::Vector3d(t[0], t[1], t[2]);
  return rig_from_tool->R.allFinite() && rig_from_tool->t.allFinite();
}

// Pixel residual of corner k of `o` at `pose` against `px`.
double CornerResidual(const Camera& cam, const Rigid3& pose, const TagObs& o,
                      int k, const Eigen::Vector2d& px) {
  const Eigen::Vector2d p = Project(
      cam.intrinsics, cam.cam_from_rig * (pose * o.tag->CornerInTool(k)));
  return p.allFinite() ? (p - px).norm() : 1e9;
}

// The per-corner check of the refinement against the pose fit (robust first
// fit): a corner far off the pose (> max(corner_outlier_px, ratio * median
// corner residual)) goes back to libapriltag's corner when that fits better,
// and is left out when it still does not fit. A tag observation left with
// fewer than 3 corners is left out. Returns the number of corners changed.
int CheckCornersAgainstPose(const Rig& rig, const Rigid3& pose,
                            const ToolPoseOptions& options,
                            std::vector<TagObs>* obs, std::vector<bool>* used) {
  std::vector<double> all;
  for (size_t i = 0; i < obs->size(); ++i) {
    if (!(*used)[i]) continue;
    const TagObs& o = (*obs)[i];
    for (int k = 0; k < 4; ++k) {
      if (o.use[k]) {
        all.push_back(
            CornerResidual(rig.cameras[o.camera], pose, o, k, o.px[k]));
      }
    }
  }
  if (all.size() < 8) return 0;
  std::nth_element(all.begin(), all.begin() + all.size() / 2, all.end());
  const double limit = std::max(options.corner_outlier_px,
                                options.outlier_ratio * all[all.size() / 2]);
  int changed = 0;
  for (size_t i = 0; i < obs->size(); ++i) {
    if (!(*used)[i]) continue;
    TagObs& o = (*obs)[i];
    const Camera& cam = rig.cameras[o.camera];
    int kept = 0;
    for (int k = 0; k < 4; ++k) {
      if (!o.use[k]) continue;
      double r = CornerResidual(cam, pose, o, k, o.px[k]);
      if (r > limit && o.det->refined[k]) {
        const double r_raw =
            CornerResidual(cam, pose, o, k, o.det->detector_corners[k]);
        if (r_raw < r) {
          o.px[k] = o.det->detector_corners[k];
          r = r_raw;
          ++changed;
        }
      }
      if (r > limit) {
        o.use[k] = false;
        ++changed;
      } else {
        ++kept;
      }
    }
    if (kept < 3) {
      (*used)[i] = false;
      o.left_out = "corners";
    }
  }
  return changed;
}

}  // namespace

void ToolPoseOptions::Check() const {
  auto fail = [](const char* what, double v) {
    std::ostringstream os;
    os << "tool pose option " << what << " = " << v;
    throw InputError(os.str());
  };
  if (!(outlier_px > 0)) fail("outlier_px (expected > 0)", outlier_px);
  if (!(hard_outlier_px >= outlier_px)) {
    fail("hard_outlier_px (expected >= outlier_px)", hard_outlier_px);
  }
  if (!(min_contrast >= 0)) fail("min_contrast (expected >= 0)", min_contrast);
  if (!(outlier_ratio >= 1))
    fail("outlier_ratio (expected >= 1)", outlier_ratio);
  if (!(huber_px >= 0)) fail("huber_px (expected >= 0)", huber_px);
  if (min_tag_observations < 1) {
    fail("min_tag_observations (expected >= 1)", min_tag_observations);
  }
  if (max_iterations < 1)
    fail("max_iterations (expected >= 1)", max_iterations);
}

bool InitialToolPose(const Rig& rig, const Target& target,
                     const std::vector<std::vector<TagDetection>>& detections,
                     Rigid3* rig_from_tool) {
  return InitialFromObservations(
      rig, CollectObservations(rig, target, detections), rig_from_tool);
}

bool PassesTrackGate(const ToolPoseResult& r, size_t num_cameras, int min_tags,
                     double max_reproj_px) {
  std::vector<bool> cameras(num_cameras, false);
  for (const TagObservationResult& t : r.tags) {
    if (t.used && t.camera >= 0 && t.camera < static_cast<int>(num_cameras)) {
      cameras[t.camera] = true;
    }
  }
  const size_t seen = std::count(cameras.begin(), cameras.end(), true);
  return r.found && r.tags_used >= min_tags && r.rms_px <= max_reproj_px &&
         seen >= std::min<size_t>(2, num_cameras);
}

ToolPoseResult EstimateToolPose(
    const Rig& rig, const Target& target,
    const std::vector<std::vector<TagDetection>>& detections,
    const ToolPoseOptions& options) {
  options.Check();
  ToolPoseResult result;
  std::vector<TagObs> all = CollectObservations(rig, target, detections);
  // Tags too faint to measure are left out before the fit.
  std::vector<TagObs> obs, faint;
  for (TagObs& o : all) {
    const double c = Contrast(*o.det);
    const int usable =
        static_cast<int>(std::count(o.use.begin(), o.use.end(), true));
    if (c > 0 && c < options.min_contrast) {
      o.left_out = "contrast";
      faint.push_back(o);
    } else if (usable < 3) {
      // The detector trusted fewer than 3 of its corners.
      o.left_out = "corners";
      faint.push_back(o);
    } else {
      obs.push_back(o);
    }
  }
  if (static_cast<int>(obs.size()) < options.min_tag_observations ||
      obs.empty()) {
    result.why_not = faint.empty() ? "no tag of the target seen"
                                   : "every tag seen is too faint (contrast "
                                     "under --min-contrast gray levels)";
    return result;
  }
  Rigid3 pose;
  if (!InitialFromObservations(rig, obs, &pose)) {
    result.why_not = "no initial pose (triangulation and PnP failed)";
    return result;
  }
  std::vector<bool> used(obs.size(), true);
  LeaveOutUnrefined(&obs, &used);
  if (!FitPose(rig, obs, used, options.huber_px, options.max_iterations,
               &pose)) {
    result.why_not = "pose fit failed";
    return result;
  }
  // Per corner: refined corners off the pose go back to libapriltag's, or
  // out; then refit.
  if (CheckCornersAgainstPose(rig, pose, options, &obs, &used) > 0) {
    int n_used = 0;
    for (bool u : used) n_used += u ? 1 : 0;
    if (n_used < options.min_tag_observations || n_used == 0) {
      result.why_not = "no tag left after the per-corner check";
      return result;
    }
    if (!FitPose(rig, obs, used, options.huber_px, options.max_iterations,
                 &pose)) {
      result.why_not = "pose fit failed after the per-corner check";
      return result;
    }
  }
  // Reject the worst tag observation while it is an outlier, refitting.
  std::vector<double> rms(obs.size());
  for (;;) {
    int n_used = 0;
    std::vector<double> used_rms;
    for (size_t i = 0; i < obs.size(); ++i) {
      rms[i] = TagRms(rig.cameras[obs[i].camera], pose, obs[i]);
      if (used[i]) {
        ++n_used;
        used_rms.push_back(rms[i]);
      }
    }
    std::nth_element(used_rms.begin(), used_rms.begin() + used_rms.size() / 2,
                     used_rms.end());
    const double median = used_rms[used_rms.size() / 2];
    const double limit =
        std::max(options.outlier_px, options.outlier_ratio * median);
    int worst = -1;
    for (size_t i = 0; i < obs.size(); ++i) {
      if (used[i] && rms[i] > limit && (worst < 0 || rms[i] > rms[worst])) {
        worst = static_cast<int>(i);
      }
    }
    if (worst < 0 || n_used - 1 < options.min_tag_observations) break;
    if (rms[worst] <= std::max(options.hard_outlier_px, limit) &&
        !DeterminedWithout(obs, used, worst)) {
      break;
    }
    used[worst] = false;
    obs[worst].left_out = "residual";
    if (!FitPose(rig, obs, used, options.huber_px, options.max_iterations,
                 &pose)) {
      result.why_not = "pose fit failed after outlier rejection";
      return result;
    }
  }
  // Final plain least-squares fit on the inliers.
  if (!FitPose(rig, obs, used, 0.0, options.max_iterations, &pose)) {
    result.why_not = "final pose fit failed";
    return result;
  }
  double sum = 0;
  int corners = 0;
  for (const TagObs& o : faint) obs.push_back(o);
  used.resize(obs.size(), false);
  for (size_t i = 0; i < obs.size(); ++i) {
    const Camera& cam = rig.cameras[obs[i].camera];
    const double r = TagRms(cam, pose, obs[i]);
    TagObservationResult t;
    t.camera = obs[i].camera;
    t.tag_id = obs[i].tag->id;
    t.rms_px = r;
    t.used = used[i];
    t.left_out = used[i] ? "" : obs[i].left_out;
    t.contrast = Contrast(*obs[i].det);
    t.obliquity_deg = ObliquityDeg(cam, pose, *obs[i].tag);
    t.corner_used = obs[i].use;
    t.corners_px = obs[i].px;
    result.tags.push_back(t);
    if (!used[i]) continue;
    int n = 0;
    for (bool u : obs[i].use) n += u ? 1 : 0;
    sum += n * r * r;
    corners += n;
    ++result.tags_used;
  }
  // A single tag in a single camera fixes the pose only weakly, but it does
  // fix it; the caller sees tags_used.
  result.found = true;
  result.rig_from_tool = pose;
  result.tip_in_rig = pose * target.tip_in_tool;
  result.rms_px = std::sqrt(sum / corners);
  return result;
}

}  // namespace kincal
