#ifndef KINCAL_BUNDLE_TESTING_SYNTHETIC_H_
#define KINCAL_BUNDLE_TESTING_SYNTHETIC_H_

// Synthetic bundle observations for tests and the bench, without rendering:
// a simulated robot (synth/simulate.h) carries a tag holder on its flange,
// a stereo rig watches it, and the tag corners are projected with Gaussian
// pixel noise; per-frame tool poses come from vision's EstimateToolPose on
// those corners (as from real images). The holder is the one the issue
// describes: three adjacent tags, the outer two turned 35 deg.

#include <cstdint>
#include <string>
#include <vector>

#include "bundle/bundle.h"
#include "camcal/rig.h"
#include "data/robot.h"
#include "synth/simulate.h"
#include "vision/target.h"

namespace kincal {

struct SyntheticBundleOptions {
  int frames = 100;
  double noise_px = 0.1;  // per pixel coordinate
  uint64_t seed = 1;
  // Only the geometry parameters the bundle can identify deviate from
  // nominal (so estimates and truth are the same quantities).
  bool only_identifiable = false;
  // Corners of tags facing away from a camera are dropped (as in images);
  // false keeps every corner in the image (solver tests and the bench).
  bool respect_facing = false;
  std::vector<Effect> effects;
  double tag_size_mm = 30.0;
  int width = 1280, height = 1024;
  // Cameras on the stand: 1, 2 (the example stereo rig) or 3
  // (synth/rig_placement.h, RigWithCameras).
  int cameras = 2;
  // Cameras on the flange instead (rig.yaml mount: flange): the rig's origin
  // at the true robot's tool-row end, turned by a hidden rotation drawn from
  // the seed (optical axis within 15 deg of the tool row's z), looking at a
  // fixed 5 x 4 AprilGrid (tags of tag_size_mm) placed by
  // PlaceBoardForFlangeRig at flange_distance_mm; the frames are the first
  // poses of the seed's random ones whose reference camera sees half the
  // board's tags.
  bool flange = false;
  double flange_distance_mm = 450.0;
};

struct SyntheticBundle {
  Robot nominal, truth;
  Rig rig;
  Target target;
  std::vector<BundleFrame> frames;
  Rigid3 rig_from_base, flange_from_tool;    // truth, cameras on a stand
  Rigid3 flange_from_rig, base_from_target;  // truth, cameras on the flange
};

// The three-tag holder (tag36h11 ids 0..2, edge `tag_size_mm`, the outer
// two turned 35 deg about the holder's y axis, 2 mm gaps), needle tip 4 tag
// sizes below its centre.
Target ThreeTagHolder(double tag_size_mm,
                      const std::string& family = "tag36h11");

SyntheticBundle MakeSyntheticBundle(const Robot& nominal,
                                    const SyntheticBundleOptions& options);

// RMS distance (mm) between the tips of `robot` and of the truth at `poses`
// fresh random poses within the joint limits, after a rigid registration
// (kincal evaluate on noise-free true tips).
double TipRmsAgainstTruth(const SyntheticBundle& s, const Robot& robot,
                          int poses, uint64_t seed);

}  // namespace kincal

#endif  // KINCAL_BUNDLE_TESTING_SYNTHETIC_H_
