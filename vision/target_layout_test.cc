#include "vision/target_layout.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <map>
#include <random>

#include "data/error.h"
#include "data/rigid3.h"
#include "synth/render.h"

namespace kincal {
namespace {

constexpr double kTagMm = 25.0;

Eigen::Matrix3d Rot(const Eigen::Vector3d& axis, double deg) {
  return Eigen::AngleAxisd(deg * M_PI / 180, axis.normalized())
      .toRotationMatrix();
}

// Three tags on a holder: tag 4 flat, tag 7 turned 35 deg about y to one
// side and tag 9 turned 35 deg the other way (70 deg between them).
std::vector<std::pair<int, Rigid3>> TrueLayout() {
  Rigid3 a, b, c;
  a.R = Rot(Eigen::Vector3d::UnitX(), 5);
  a.t = Eigen::Vector3d(0, -5, 2);
  b.R = Rot(Eigen::Vector3d::UnitY(), 35);
  b.t = Eigen::Vector3d(-30, 0, 10);
  c.R = Rot(Eigen::Vector3d::UnitY(), -35);
  c.t = Eigen::Vector3d(30, 2, 10);
  return {{4, a}, {7, b}, {9, c}};
}

// A tool pose in front of the rig, tilted by up to ~35 deg.
Rigid3 ToolPose(int i, std::mt19937_64* rng) {
  std::uniform_real_distribution<double> u(-1, 1);
  Rigid3 pose;
  pose.R = Rot(Eigen::Vector3d(u(*rng), u(*rng), 0.2 * u(*rng)), 35 * u(*rng));
  pose.t = Eigen::Vector3d(60 + 30 * u(*rng), 10 * u(*rng),
                           420 + 40 * std::sin(0.3 * i));
  return pose;
}

// Per tag id, an offset of each corner in the tag's plane (mm).
using CornerOffsetsMm = std::map<int, std::array<Eigen::Vector2d, 4>>;

// Corners of every tag facing a camera (within 75 deg) and inside its
// image, with Gaussian pixel noise, at n tool poses pose(i, rng); each
// corner where `offsets` (optional) puts it in its tag's plane.
std::vector<LayoutFrame> FramesAt(
    const Rig& rig, const std::vector<std::pair<int, Rigid3>>& tags, int n,
    const std::function<Rigid3(int, std::mt19937_64*)>& pose, double noise_px,
    int seed, const CornerOffsetsMm& offsets = {}) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0, noise_px);
  std::vector<LayoutFrame> frames;
  for (int i = 0; i < n; ++i) {
    const Rigid3 rig_from_tool = pose(i, &rng);
    LayoutFrame f;
    f.frame = i;
    for (const Camera& cam : rig.cameras) {
      std::vector<TagDetection> dets;
      for (const auto& [id, tool_from_tag] : tags) {
        const Rigid3 cam_from_tag =
            cam.cam_from_rig * rig_from_tool * tool_from_tag;
        const Eigen::Vector3d view = cam_from_tag.t.normalized();
        if (view.dot(cam_from_tag.R.col(2)) < std::cos(75 * M_PI / 180)) {
          continue;
        }
        TagDetection d;
        d.id = id;
        bool inside = true;
        for (int k = 0; k < 4; ++k) {
          Eigen::Vector3d corner = TagCornerInTag(k, kTagMm);
          if (offsets.count(id)) corner.head<2>() += offsets.at(id)[k];
          const Eigen::Vector2d px =
              Project(cam.intrinsics, cam_from_tag * corner);
          inside = inside && px.x() > 5 && px.y() > 5 &&
                   px.x() < cam.intrinsics.width - 5 &&
                   px.y() < cam.intrinsics.height - 5;
          d.corners[k] = px + Eigen::Vector2d(noise(rng), noise(rng));
        }
        d.detector_corners = d.corners;
        if (inside) dets.push_back(d);
      }
      f.detections.push_back(dets);
    }
    frames.push_back(f);
  }
  return frames;
}

// n random tool poses (ToolPose), as FramesAt.
std::vector<LayoutFrame> Frames(const Rig& rig,
                                const std::vector<std::pair<int, Rigid3>>& tags,
                                int n, double noise_px, int seed) {
  return FramesAt(rig, tags, n, ToolPose, noise_px, seed);
}

TargetLayoutOptions Options() {
  TargetLayoutOptions o;
  o.tag_size_mm = kTagMm;
  return o;
}

// ref_from_tag of the truth for the measured layout's reference tag.
Rigid3 TrueRefFromTag(const std::vector<std::pair<int, Rigid3>>& truth,
                      int reference, int id) {
  Rigid3 tool_from_ref, tool_from_tag;
  for (const auto& [tid, pose] : truth) {
    if (tid == reference) tool_from_ref = pose;
    if (tid == id) tool_from_tag = pose;
  }
  return tool_from_ref.Inverse() * tool_from_tag;
}

TEST(TargetLayout, RecoversTagPosesWithHonestSigma) {
  const Rig rig = ExampleStereoRig(1280, 1024);
  const auto truth = TrueLayout();
  double z2_t = 0, z2_r = 0, max_t = 0, max_r = 0;
  int count = 0;
  for (int seed = 1; seed <= 8; ++seed) {
    const TargetLayoutResult r =
        MeasureTargetLayout(rig, Frames(rig, truth, 40, 0.1, seed), Options());
    ASSERT_EQ(r.tags.size(), 3u);
    EXPECT_GE(r.views_used, 30);
    EXPECT_FALSE(r.target.has_tip);
    EXPECT_NEAR(r.sigma0_px, 0.1, 0.02);
    for (const LayoutTag& tag : r.tags) {
      const Rigid3 want = TrueRefFromTag(truth, r.reference_tag_id, tag.id);
      const Eigen::Vector3d dt = tag.tool_from_tag.t - want.t;
      const Eigen::Vector3d dr =
          RotationVectorFromMatrix(tag.tool_from_tag.R * want.R.transpose()) *
          180 / M_PI;
      if (tag.id == r.reference_tag_id) {
        EXPECT_LT(dt.norm() + dr.norm(), 1e-9);
        EXPECT_EQ(tag.sigma_t_mm.norm(), 0);
        continue;
      }
      max_t = std::max(max_t, dt.norm());
      max_r = std::max(max_r, dr.norm());
      for (int k = 0; k < 3; ++k) {
        ASSERT_GT(tag.sigma_t_mm(k), 0);
        ASSERT_GT(tag.sigma_r_deg(k), 0);
        z2_t += std::pow(dt(k) / tag.sigma_t_mm(k), 2);
        z2_r += std::pow(dr(k) / tag.sigma_r_deg(k), 2);
        ++count;
      }
    }
  }
  const double ratio_t = std::sqrt(z2_t / count);
  const double ratio_r = std::sqrt(z2_r / count);
  std::printf(
      "layout: max error %.4f mm, %.4f deg; RMS error/sigma t %.3f, r %.3f\n",
      max_t, max_r, ratio_t, ratio_r);
  EXPECT_LT(max_t, 0.05);
  EXPECT_LT(max_r, 0.05);
  EXPECT_GT(ratio_t, 0.7);
  EXPECT_LT(ratio_t, 1.4);
  EXPECT_GT(ratio_r, 0.7);
  EXPECT_LT(ratio_r, 1.4);
}

// Two tags are enough; a few wild corners are left out by the robust fit.
TEST(TargetLayout, TwoTagsAndOutliers) {
  const Rig rig = ExampleStereoRig(1280, 1024);
  auto truth = TrueLayout();
  truth.pop_back();
  auto frames = Frames(rig, truth, 20, 0.1, 3);
  int spoiled = 0;
  for (int i = 0; i < 20; i += 4) {
    if (frames[i].detections[0].empty()) continue;
    frames[i].detections[0][0].corners[1] += Eigen::Vector2d(6, -4);
    ++spoiled;
  }
  // Every tag observation of frame 2 spoiled: the frame drops out whole,
  // and the covariance stays finite.
  for (auto& camera : frames[2].detections) {
    for (TagDetection& d : camera) d.corners[2] += Eigen::Vector2d(-3, 5);
  }
  const TargetLayoutResult r = MeasureTargetLayout(rig, frames, Options());
  EXPECT_GE(r.corners_rejected, spoiled);
  EXPECT_TRUE(r.covariance.allFinite());
  for (const LayoutTag& tag : r.tags) {
    EXPECT_TRUE(tag.sigma_t_mm.allFinite() && tag.sigma_r_deg.allFinite());
    if (tag.id != r.reference_tag_id) {
      EXPECT_GT(tag.sigma_t_mm.minCoeff(), 0);
    }
  }
  for (const LayoutTag& tag : r.tags) {
    const Rigid3 want = TrueRefFromTag(truth, r.reference_tag_id, tag.id);
    EXPECT_LT((tag.tool_from_tag.t - want.t).norm(), 0.05);
  }
}

TEST(TargetLayout, RefusesTooFewViews) {
  const Rig rig = ExampleStereoRig(1280, 1024);
  try {
    MeasureTargetLayout(rig, Frames(rig, TrueLayout(), 6, 0.1, 1), Options());
    ADD_FAILURE() << "6 views accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("record the tool from more"),
              std::string::npos)
        << e.what();
  }
}

// Tag 9 only ever shows alone: its place on the tool is unknown.
TEST(TargetLayout, RefusesATagNeverSeenWithTheOthers) {
  const Rig rig = ExampleStereoRig(1280, 1024);
  auto truth = TrueLayout();
  const auto pair =
      std::vector<std::pair<int, Rigid3>>(truth.begin(), truth.begin() + 2);
  auto frames = Frames(rig, pair, 15, 0.1, 2);
  const auto alone = Frames(rig, {truth[2]}, 5, 0.1, 4);
  frames.insert(frames.end(), alone.begin(), alone.end());
  try {
    MeasureTargetLayout(rig, frames, Options());
    ADD_FAILURE() << "an unconnected tag accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("tags 9 were never seen"),
              std::string::npos)
        << e.what();
  }
}

// Corners of 25 mm tags fitted as 30 mm tags do not fit: refused.
TEST(TargetLayout, RefusesAWrongTagSize) {
  const Rig rig = ExampleStereoRig(1280, 1024);
  TargetLayoutOptions o = Options();
  o.tag_size_mm = 30;
  try {
    MeasureTargetLayout(rig, Frames(rig, TrueLayout(), 20, 0.1, 5), o);
    ADD_FAILURE() << "a wrong tag size accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("check --size"), std::string::npos)
        << e.what();
  }
}

TEST(TargetLayout, RejectsBadOptions) {
  const Rig rig = ExampleStereoRig(1280, 1024);
  TargetLayoutOptions o = Options();
  o.tag_size_mm = 0;
  EXPECT_THROW(MeasureTargetLayout(rig, {}, o), InputError);
  o = Options();
  o.family = "tag99";
  EXPECT_THROW(MeasureTargetLayout(rig, {}, o), InputError);
  const TargetLayoutResult layout;
  PivotTipOptions pivot;
  pivot.outlier_ratio = 0.5;
  EXPECT_THROW(MeasurePivotTip(rig, layout, {}, pivot), InputError);
  pivot = PivotTipOptions();
  pivot.outlier_mm = 0;
  EXPECT_THROW(MeasurePivotTip(rig, layout, {}, pivot), InputError);
  pivot = PivotTipOptions();
  pivot.min_views = 2;
  EXPECT_THROW(MeasurePivotTip(rig, layout, {}, pivot), InputError);
}

// A pivot session (20 poses tilted +-10 and +-20 deg about the tip, 0.05
// px) in which one frame's corners are 0.8 px off in one camera (a frame
// the cameras did not take at the same instant: the tags agree with each
// other, so the pose fit keeps them): that pose misses the pivot and is
// left out; kept (outlier_mm huge), it pulls the tip.
TEST(TargetLayout, PivotPoseOffThePivotIsLeftOut) {
  const Rig rig = ExampleStereoRig(1280, 1024);
  const auto truth = TrueLayout();
  const TargetLayoutResult layout =
      MeasureTargetLayout(rig, Frames(rig, truth, 40, 0.02, 3), Options());
  const Eigen::Vector3d tip_in_tool(5, 100, 10);
  Rigid3 mid;
  mid.t = Eigen::Vector3d(60, 0, 420);
  std::vector<Rigid3> poses;
  for (int i = 0; i < 20; ++i) {
    const double a = 2 * M_PI * i / 10, tilt = i < 10 ? 20 : 10;
    Rigid3 p;
    p.R = Rot(Eigen::Vector3d(std::sin(a), std::cos(a), 0), tilt);
    p.t = mid.t + mid.R * tip_in_tool - p.R * tip_in_tool;
    poses.push_back(p);
  }
  std::vector<LayoutFrame> frames = FramesAt(
      rig, truth, 20, [&](int i, std::mt19937_64*) { return poses[i]; }, 0.05,
      4);
  for (TagDetection& d : frames[6].detections[0]) {
    for (int k = 0; k < 4; ++k) d.corners[k].x() += 0.8;
  }
  const Rigid3 ref_from_tool =
      TrueRefFromTag(truth, layout.reference_tag_id, truth[0].first) *
      truth[0].second.Inverse();
  const Eigen::Vector3d want = ref_from_tool * tip_in_tool;
  const PivotTipResult robust =
      MeasurePivotTip(rig, layout, frames, PivotTipOptions());
  PivotTipOptions keep;
  keep.outlier_mm = 1e9;
  const PivotTipResult kept = MeasurePivotTip(rig, layout, frames, keep);
  const double robust_error = (robust.pivot.tip_in_tool - want).norm();
  const double kept_error = (kept.pivot.tip_in_tool - want).norm();
  std::printf(
      "pivot with a bad frame: tip error %.4f mm (sigma %.4f) with %zu "
      "frames left out, %.4f mm with all kept\n",
      robust_error, robust.tip_sigma_mm.norm(), robust.frames_rejected.size(),
      kept_error);
  EXPECT_NE(std::find(robust.frames_rejected.begin(),
                      robust.frames_rejected.end(), 6),
            robust.frames_rejected.end());
  EXPECT_EQ(robust.views + static_cast<int>(robust.frames_rejected.size()), 20);
  EXPECT_TRUE(kept.frames_rejected.empty());
  EXPECT_LT(robust_error, 0.5 * kept_error);
  EXPECT_LT(robust_error, 3 * robust.tip_sigma_mm.norm());
}

// Each tag corner off its printed place by a fixed offset in the tag's
// plane (N(0, 0.015 mm) per axis; about 0.04 px at these distances, as a
// detector's bias from a tag's own pattern), the same in every view of both
// sessions, on top of 0.1 px noise. Such offsets do not average out over
// views, and no residual-based covariance of the views sees them: without
// the shared term the layout's and the tip's RMS error/sigma come out well
// above 1.4. The moments from both sessions' residuals recover their sigma,
// and the error/sigma is honest (0.7 to 1.4) over 12 seeds.
TEST(TargetLayout, SharedCornerOffsetsAreInTheSigma) {
  const Rig rig = ExampleStereoRig(1280, 1024);
  const auto truth = TrueLayout();
  const double offset_mm = 0.015;
  const Eigen::Vector3d tip_in_tool(5, 100, 10);
  std::vector<double> z_t, z_r, z_tip, old_t, old_r, old_tip;
  double s2 = 0;
  const int seeds = 12;
  for (int seed = 1; seed <= seeds; ++seed) {
    std::mt19937_64 rng(100 + seed);
    std::normal_distribution<double> n(0, offset_mm);
    CornerOffsetsMm offsets;
    for (const auto& [id, pose] : truth) {
      for (auto& o : offsets[id]) o = Eigen::Vector2d(n(rng), n(rng));
    }
    const TargetLayoutResult layout = MeasureTargetLayout(
        rig, FramesAt(rig, truth, 40, ToolPose, 0.1, seed, offsets), Options());
    Rigid3 mid;
    mid.t = Eigen::Vector3d(60, 0, 420);
    std::vector<Rigid3> poses;
    for (int i = 0; i < 24; ++i) {
      const double a = 2 * M_PI * i / 12 + seed, tilt = i < 12 ? 20 : 10;
      Rigid3 p;
      p.R = Rot(Eigen::Vector3d(std::sin(a), std::cos(a), 0), tilt);
      p.t = mid.t + mid.R * tip_in_tool - p.R * tip_in_tool;
      poses.push_back(p);
    }
    const PivotTipResult tip = MeasurePivotTip(
        rig, layout,
        FramesAt(
            rig, truth, 24, [&](int i, std::mt19937_64*) { return poses[i]; },
            0.1, 50 + seed, offsets),
        PivotTipOptions());
    s2 += tip.corner_offset_sigma_mm * tip.corner_offset_sigma_mm;
    const double own2 =
        layout.corner_offset_sigma_mm * layout.corner_offset_sigma_mm;
    const Eigen::MatrixXd without =
        layout.covariance - own2 * layout.tags_from_corner_offsets *
                                layout.tags_from_corner_offsets.transpose();
    for (size_t i = 0; i < layout.tags.size(); ++i) {
      const LayoutTag& tag = layout.tags[i];
      if (tag.id == layout.reference_tag_id) continue;
      const Rigid3 want =
          TrueRefFromTag(truth, layout.reference_tag_id, tag.id);
      const Eigen::Vector3d dt = tag.tool_from_tag.t - want.t;
      const Eigen::Vector3d dr =
          RotationVectorFromMatrix(tag.tool_from_tag.R * want.R.transpose()) *
          180 / M_PI;
      for (int k = 0; k < 3; ++k) {
        const int row = 6 * static_cast<int>(i) + k;
        z_t.push_back(dt(k) / tag.sigma_t_mm(k));
        z_r.push_back(dr(k) / tag.sigma_r_deg(k));
        old_t.push_back(dt(k) / std::sqrt(without(row + 3, row + 3)));
        old_r.push_back(dr(k) * M_PI / 180 / std::sqrt(without(row, row)));
      }
    }
    const Rigid3 ref_from_tool =
        TrueRefFromTag(truth, layout.reference_tag_id, truth[0].first) *
        truth[0].second.Inverse();
    const Eigen::Vector3d error =
        tip.pivot.tip_in_tool - ref_from_tool * tip_in_tool;
    for (int k = 0; k < 3; ++k) {
      z_tip.push_back(error(k) / tip.tip_sigma_mm(k));
      old_tip.push_back(error(k) /
                        std::sqrt(std::pow(tip.tip_sigma_mm(k), 2) -
                                  std::pow(tip.systematic_sigma_mm(k), 2)));
    }
  }
  const auto rms = [](const std::vector<double>& v) {
    double sum = 0;
    for (double x : v) sum += x * x;
    return std::sqrt(sum / v.size());
  };
  const double s = std::sqrt(s2 / seeds);
  std::printf(
      "shared corner offsets %.4f mm: estimated %.4f mm; RMS error/sigma t "
      "%.2f r %.2f tip %.2f (without the shared term %.2f %.2f %.2f)\n",
      offset_mm, s, rms(z_t), rms(z_r), rms(z_tip), rms(old_t), rms(old_r),
      rms(old_tip));
  EXPECT_GT(s, 0.6 * offset_mm);
  EXPECT_LT(s, 1.4 * offset_mm);
  for (const auto* z : {&z_t, &z_r, &z_tip}) {
    EXPECT_GT(rms(*z), 0.7);
    EXPECT_LT(rms(*z), 1.4);
  }
  EXPECT_GT(std::max(rms(old_t), rms(old_r)), 1.4);
  EXPECT_GT(rms(old_tip), 1.4);
}

// ToolPoseLayoutJacobian against refitting the tool pose with one tag's
// pose corrected by a small rotation (left) or translation.
TEST(TargetLayout, ToolPoseLayoutJacobianMatchesRefits) {
  const Rig rig = ExampleStereoRig(1280, 1024);
  const auto truth = TrueLayout();
  const TargetLayoutResult layout =
      MeasureTargetLayout(rig, Frames(rig, truth, 30, 0.1, 5), Options());
  const auto frames = Frames(rig, truth, 4, 0.1, 9);
  const ToolPoseResult pose =
      EstimateToolPose(rig, layout.target, frames[1].detections);
  ASSERT_TRUE(pose.found);
  ASSERT_GE(pose.tags_used, 3);
  const Eigen::MatrixXd jacobian = ToolPoseLayoutJacobian(rig, layout, pose);
  ASSERT_EQ(jacobian.rows(), 6);
  ASSERT_EQ(jacobian.cols(), 6 * static_cast<int>(layout.tags.size()));
  const double h = 1e-4;
  for (size_t tag = 0; tag < layout.tags.size(); ++tag) {
    for (int k = 0; k < 6; ++k) {
      Target moved = layout.target;
      Eigen::Vector3d delta = Eigen::Vector3d::Zero();
      delta(k % 3) = k < 3 ? h : 100 * h;
      Rigid3& tool_from_tag = moved.tags[tag].tool_from_tag;
      if (k < 3) {
        tool_from_tag.R = RotationMatrixFromVector(delta) * tool_from_tag.R;
      } else {
        tool_from_tag.t += delta;
      }
      const ToolPoseResult refit =
          EstimateToolPose(rig, moved, frames[1].detections);
      ASSERT_TRUE(refit.found);
      Eigen::Matrix<double, 6, 1> numeric;
      numeric.head<3>() = RotationVectorFromMatrix(
          refit.rig_from_tool.R * pose.rig_from_tool.R.transpose());
      numeric.tail<3>() = refit.rig_from_tool.t - pose.rig_from_tool.t;
      const Eigen::Matrix<double, 6, 1> predicted =
          jacobian.col(6 * tag + k) * delta(k % 3);
      EXPECT_LT((numeric - predicted).norm(), 0.02 * predicted.norm() + 1e-7)
          << "tag " << tag << " component " << k;
    }
  }
}

}  // namespace
}  // namespace kincal
