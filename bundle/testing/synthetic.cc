#include "bundle/testing/synthetic.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <random>

#include "calib/evaluate.h"
#include "data/error.h"
#include "synth/flange_scene.h"
#include "synth/render.h"
#include "synth/rig_placement.h"
#include "vision/apriltag_detector.h"
#include "vision/tool_pose.h"

namespace kincal {

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

namespace {

// The parameters the bundle identifies in this configuration: asked of it
// on exact data.
std::vector<std::string> IdentifiedNames(const Robot& nominal,
                                         const SyntheticBundleOptions& o) {
  SyntheticBundleOptions probe = o;
  probe.only_identifiable = false;
  probe.noise_px = 0;
  probe.frames = std::max(o.frames, 30);
  const SyntheticBundle p = MakeSyntheticBundle(nominal, probe);
  BundleOptions bo;
  bo.holdout_fraction = 0;
  const BundleResult r = RunBundle(p.nominal, p.rig, p.target, p.frames, bo);
  std::vector<std::string> names;
  for (const BundleParam& bp : r.params) names.push_back(bp.name);
  return names;
}

// flange_from_tip: the truth's tool row.
Rigid3 FlangeFromTip(const Robot& truth_robot) {
  const Chain truth = Chain::FromRobot(truth_robot);
  const ChainRow& tool = truth.rows[truth.tool_row()];
  return Rigid3::FromMatrix(
      RowTransform<double>(truth.convention, tool, tool.p.data(), 0.0));
}

// The cameras on a stand facing the tips: the session and each frame's
// rig_from_tool.
SimulatedSession StandSession(const Robot& nominal, const SimulateOptions& so,
                              int cameras, SyntheticBundle* s,
                              std::vector<Rigid3>* rig_from_tool) {
  const SimulatedSession sim = Simulate(nominal, so);
  const Rigid3 tip_from_tool = TipFromTool(s->target);
  double distance = 0.0;
  s->rig_from_base = PlaceRigFacingTips(
      sim.base_from_tip, s->rig, tip_from_tool, /*in_view=*/1.0, &distance);
  s->rig = RigWithCameras(s->rig, cameras, distance);
  // flange_from_tool = flange_from_tip * tip_from_tool.
  s->flange_from_tool = FlangeFromTip(sim.truth) * tip_from_tool;
  for (const Eigen::Matrix4d& m : sim.base_from_tip) {
    rig_from_tool->push_back(s->rig_from_base * Rigid3::FromMatrix(m) *
                             tip_from_tool);
  }
  return sim;
}

// The hidden mounting of a rig on the flange: tip_from_rig, the optical
// axis tilted 5..15 deg from the tip frame's z and turned about it.
Rigid3 HiddenFlangeMounting(uint64_t seed) {
  std::mt19937_64 rng(seed * 104729 + 3);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const double phi = 2 * M_PI * u(rng);
  const double tilt = (5.0 + 10.0 * u(rng)) * M_PI / 180.0;
  const double roll = 2 * M_PI * u(rng);
  Rigid3 r;
  r.R = (Eigen::AngleAxisd(tilt,
                           Eigen::Vector3d(std::cos(phi), std::sin(phi), 0.0)) *
         Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitZ()))
            .toRotationMatrix();
  return r;
}

// The cameras on the flange looking at a fixed board: the session on the
// poses that see it and each frame's rig_from_tool (= rig_from_board).
SimulatedSession FlangeSession(const Robot& nominal, SimulateOptions so,
                               const SyntheticBundleOptions& o,
                               SyntheticBundle* s,
                               std::vector<Rigid3>* rig_from_tool) {
  AprilGrid grid;
  grid.cols = 5;
  grid.rows = 4;
  grid.tag_size_mm = o.tag_size_mm;
  s->target = grid.AsTarget();
  s->target.has_tip = false;
  s->rig = RigWithCameras(s->rig, o.cameras, o.flange_distance_mm);
  s->rig.mount = RigMount::kFlange;
  const Rigid3 tip_from_rig = HiddenFlangeMounting(o.seed);
  // The seed's random poses (same truth), then those that see the board.
  SimulateOptions candidates = so;
  candidates.poses = 320 * so.poses;
  candidates.effects.clear();
  const SimulatedSession all = Simulate(nominal, candidates);
  const FlangeBoardPlacement place = PlaceBoardForFlangeRig(
      all.base_from_tip, s->rig, tip_from_rig, s->target, o.flange_distance_mm,
      static_cast<int>(s->target.tags.size()) / 2);
  if (static_cast<int>(place.seen.size()) < so.poses) {
    throw InputError("synthetic flange scene: only " +
                     std::to_string(place.seen.size()) +
                     " poses see the board");
  }
  for (int k = 0; k < so.poses; ++k) {
    so.readings.push_back(all.observations.rows[place.seen[k]].q);
  }
  const SimulatedSession sim = Simulate(nominal, so);
  s->flange_from_rig = FlangeFromTip(sim.truth) * tip_from_rig;
  s->base_from_target = place.base_from_board;
  for (const Eigen::Matrix4d& m : sim.base_from_tip) {
    rig_from_tool->push_back((Rigid3::FromMatrix(m) * tip_from_rig).Inverse() *
                             place.base_from_board);
  }
  return sim;
}

// Frame f: the target's corners in every camera (Gaussian noise; corners
// outside the image drop the tag, and with respect_facing so does facing
// away) and the tracked pose from them.
BundleFrame ObserveFrame(const SyntheticBundle& s,
                         const SyntheticBundleOptions& o, int f,
                         const Observation& row, const Rigid3& rig_from_tool,
                         std::mt19937_64* rng,
                         std::normal_distribution<double>* noise) {
  BundleFrame bf;
  bf.frame = f;
  bf.q_reading = row.q;
  bf.t_s = row.HasTime() ? row.t_s : 0.0;
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
        const Eigen::Vector3d p = cam_from_tag * TagCornerInTag(i, tag.size_mm);
        Eigen::Vector2d px = Project(cam.intrinsics, p);
        inside = inside && p.z() > 0 && px.allFinite() && px.x() >= 0 &&
                 px.y() >= 0 && px.x() <= cam.intrinsics.width - 1 &&
                 px.y() <= cam.intrinsics.height - 1;
        px += o.noise_px * Eigen::Vector2d((*noise)(*rng), (*noise)(*rng));
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
      // BundleCorner::tag is the tag's index in the target, not its id.
      int index = 0;
      while (s.target.tags[index].id != d.id) ++index;
      for (int i = 0; i < 4; ++i) {
        bf.corners.push_back({static_cast<int>(c), index, i, d.corners[i]});
      }
    }
  }
  return bf;
}

}  // namespace

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
  if (o.only_identifiable) so.perturbed = IdentifiedNames(nominal, o);
  std::vector<Rigid3> rig_from_tool;
  const SimulatedSession sim =
      o.flange ? FlangeSession(nominal, so, o, &s, &rig_from_tool)
               : StandSession(nominal, so, o.cameras, &s, &rig_from_tool);
  s.truth = sim.truth;
  std::mt19937_64 rng(o.seed * 7919 + 17);
  std::normal_distribution<double> noise(0.0, 1.0);
  for (int f = 0; f < o.frames; ++f) {
    s.frames.push_back(ObserveFrame(s, o, f, sim.observations.rows[f],
                                    rig_from_tool[f], &rng, &noise));
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
