#include "bundle/testing/synthetic.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <random>

#include "calib/evaluate.h"
#include "data/error.h"
#include "synth/render.h"
#include "synth/rig_placement.h"
#include "vision/apriltag_detector.h"
#include "vision/tool_pose.h"

namespace kincal {
namespace {}  // namespace

Target ThreeTagHolder(double s, const std::string& family) {
  Target t;
  t.family = family;
  const double turn = 35.0 * M_PI / 180.0;
  const double gap = 2.0;
  for (int i = 0; i < 3; ++i) {
    TargetTag tag;
    tag.id = i;
    tag.size_mm = s;
    // Middle tag flat at the origin; the outer ones hinged at its edges.
    // The printed squares (black square, white ring, any outer data ring)
    // touch along the hinge, but for the gap.
    const double half = 0.5 * s * TagImage(family, 0).cols /
                        TagBlackSquareCells(family);  // half printed width
    if (i == 1) {
      tag.tool_from_tag.t = Eigen::Vector3d::Zero();
    } else {
      const double sign = i == 0 ? -1.0 : 1.0;
      const double a = sign * turn;
      tag.tool_from_tag.R =
          Eigen::AngleAxisd(-a, Eigen::Vector3d::UnitY()).toRotationMatrix();
      // Hinge at x = sign * (half + gap / 2), z = 0; the tag centre lies a
      // further `half` along the turned x axis.
      const Eigen::Vector3d hinge(sign * (half + gap / 2), 0, 0);
      tag.tool_from_tag.t =
          hinge + tag.tool_from_tag.R * Eigen::Vector3d(sign * half, 0, 0);
    }
    t.tags.push_back(tag);
  }
  t.tip_in_tool = Eigen::Vector3d(0, 4 * s, 10);
  return t;
}

SyntheticBundle MakeSyntheticBundle(const Robot& nominal,
                                    const SyntheticBundleOptions& o) {
  SyntheticBundle s;
  s.nominal = nominal;
  s.rig = ExampleStereoRig(o.width, o.height);
  s.target = ThreeTagHolder(o.tag_size_mm);
  SimulateOptions so;
  so.poses = std::max(o.frames, 3);
  so.noise_mm = 0;
  so.seed = o.seed;
  so.effects = o.effects;
  if (o.only_identifiable) {
    // Which parameters does the bundle identify here? Ask it on exact data.
    SyntheticBundleOptions probe = o;
    probe.only_identifiable = false;
    probe.noise_px = 0;
    probe.frames = std::max(o.frames, 30);
    const SyntheticBundle p = MakeSyntheticBundle(nominal, probe);
    BundleOptions bo;
    bo.holdout_fraction = 0;
    const BundleResult r = RunBundle(p.nominal, p.rig, p.target, p.frames, bo);
    for (const BundleParam& bp : r.params) so.perturbed.push_back(bp.name);
  }
  const SimulatedSession sim = Simulate(nominal, so);
  s.truth = sim.truth;
  const Rigid3 tip_from_tool = TipFromTool(s.target);
  double distance = 0.0;
  s.rig_from_base = PlaceRigFacingTips(sim.base_from_tip, s.rig, tip_from_tool,
                                       /*in_view=*/1.0, &distance);
  s.rig = RigWithCameras(s.rig, o.cameras, distance);
  // flange_from_tool = flange_from_tip * tip_from_tool, where flange_from_tip
  // is the truth's tool row.
  const Chain truth = Chain::FromRobot(s.truth);
  const ChainRow& tool = truth.rows[truth.tool_row()];
  const Eigen::Matrix4d flange_from_tip =
      RowTransform<double>(truth.convention, tool, tool.p.data(), 0.0);
  s.flange_from_tool = Rigid3::FromMatrix(flange_from_tip) * tip_from_tool;

  std::mt19937_64 rng(o.seed * 7919 + 17);
  std::normal_distribution<double> noise(0.0, 1.0);
  for (int f = 0; f < o.frames; ++f) {
    const Observation& row = sim.observations.rows[f];
    BundleFrame bf;
    bf.frame = f;
    bf.q_reading = row.q;
    bf.t_s = row.HasTime() ? row.t_s : 0.0;
    const Rigid3 rig_from_tool = s.rig_from_base *
                                 Rigid3::FromMatrix(sim.base_from_tip[f]) *
                                 tip_from_tool;
    std::vector<std::vector<TagDetection>> dets(s.rig.cameras.size());
    for (size_t c = 0; c < s.rig.cameras.size(); ++c) {
      const Camera& cam = s.rig.cameras[c];
      for (size_t k = 0; k < s.target.tags.size(); ++k) {
        const TargetTag& tag = s.target.tags[k];
        const Rigid3 cam_from_tag =
            cam.cam_from_rig * rig_from_tool * tag.tool_from_tag;
        if (o.respect_facing && cam_from_tag.Inverse().t.z() >= 0) continue;
        TagDetection d;
        d.id = tag.id;
        bool inside = true;
        for (int i = 0; i < 4; ++i) {
          const Eigen::Vector3d p =
              cam_from_tag * TagCornerInTag(i, tag.size_mm);
          Eigen::Vector2d px = Project(cam.intrinsics, p);
          inside = inside && p.z() > 0 && px.allFinite() && px.x() >= 0 &&
                   px.y() >= 0 && px.x() <= cam.intrinsics.width - 1 &&
                   px.y() <= cam.intrinsics.height - 1;
          px += o.noise_px * Eigen::Vector2d(noise(rng), noise(rng));
          d.corners[i] = px;
        }
        if (inside) dets[c].push_back(d);
      }
    }
    const ToolPoseResult r = EstimateToolPose(s.rig, s.target, dets);
    if (r.found) {
      bf.tracked = true;
      bf.rig_from_tool = r.rig_from_tool;
      bf.tracked_rms_px = r.rms_px;
      bf.tracked_tags = r.tags_used;
    }
    for (size_t c = 0; c < dets.size(); ++c) {
      for (const TagDetection& d : dets[c]) {
        for (int i = 0; i < 4; ++i) {
          bf.corners.push_back({static_cast<int>(c), d.id, i, d.corners[i]});
        }
      }
    }
    s.frames.push_back(std::move(bf));
  }
  return s;
}

double TipRmsAgainstTruth(const SyntheticBundle& s, const Robot& robot,
                          int poses, uint64_t seed) {
  SimulateOptions so;
  so.poses = poses;
  so.noise_mm = 0;
  so.sigma_length_mm = 0;
  so.sigma_angle_deg = 0;
  so.seed = seed;
  const SimulatedSession fresh = Simulate(s.truth, so);
  return Evaluate(robot, fresh.observations).stats.rms_mm;
}

}  // namespace kincal
