#ifndef KINCAL_BUNDLE_OBSERVE_H_
#define KINCAL_BUNDLE_OBSERVE_H_

// The bundle's observations from a recorded session: every frame with joint
// readings is read (both cameras in parallel), its tags detected at full
// frame (vision/apriltag_detector.h) and the tool pose fitted per frame
// (vision/tool_pose.h) for start values and held-out tips. Tag observations
// that the per-frame pose fit rejects as outliers are left out.

#include <functional>
#include <string>
#include <vector>

#include "bundle/bundle.h"
#include "camcal/rig.h"
#include "data/session.h"
#include "vision/apriltag_detector.h"
#include "vision/bayer.h"
#include "vision/target.h"
#include "vision/tool_pose.h"

namespace kincal {

struct ObserveOptions {
  AprilTagOptions detector;  // family is taken from the target
  ToolPoseOptions pose;
  // The images are a colour camera's raw mosaic of this pattern, balanced
  // to gray before detection (vision/bayer.h); kNone = gray images.
  BayerPattern bayer = BayerPattern::kNone;
  // Each corner's weight in the bundle (BundleCorner::weight): its tag
  // observation's contrast (the weakest side's white - black, gray levels)
  // over this, at most 1 and at least min_corner_weight. An edge's position
  // errs as the image noise over the edge's contrast, so a dim tag's
  // corners err in inverse proportion to it (measured on the light-aware
  // renders: 0.027 px RMS at contrast >= 100, 0.063 at 60-100, 0.41 below
  // 60, with an outward bias there); above this contrast other errors (the
  // edge model's) dominate and every corner counts alike. 0: every corner
  // weighs 1.
  double full_weight_contrast = 100.0;
  double min_corner_weight = 0.1;
  // Progress: called after each frame with (done, total).
  std::function<void(int, int)> progress;
};

struct SessionObservations {
  std::vector<BundleFrame> frames;  // frames with joint readings, in order
  int session_frames = 0;
  int without_joints = 0;
  int without_tags = 0;    // frames with joints where no target tag was seen
  int bayer_doubtful = 0;  // images whose Bayer balance is doubtful
  // Without a Bayer pattern: cameras whose first image looks like a raw
  // mosaic read as gray (LooksLikeRawMosaic).
  int looks_raw = 0;
  // Without a Bayer pattern: cameras whose first image with tags looks
  // demosaiced by the camera (PhaseSharpnessRatio above the detector's
  // demosaiced_ratio).
  int looks_demosaiced = 0;
  double seconds = 0.0;
};

// The weight of a corner of a tag observation of `contrast` gray levels
// (ObserveOptions::full_weight_contrast).
double CornerWeight(double contrast, const ObserveOptions& options);

// Throws InputError naming an image that cannot be read or whose size
// differs from its camera's in the rig.
SessionObservations ObserveSession(const Session& session, const Rig& rig,
                                   const Target& target,
                                   const ObserveOptions& options);

}  // namespace kincal

#endif  // KINCAL_BUNDLE_OBSERVE_H_
