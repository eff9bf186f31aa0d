#ifndef KINCAL_VISION_CAMERA_ORDER_H_
#define KINCAL_VISION_CAMERA_ORDER_H_

// Whether a stereo session's images are given in the rig's camera order.
// Images of the right camera given as the left (and the reverse) parse and
// detect fine, but no tool pose fits both views: every frame then fails
// track's quality gate. A sample of pairs is tried as given and with the
// two images exchanged; when the exchange explains the data, the caller
// says so instead of writing tips that are not there.

#include <functional>
#include <string>
#include <vector>

#include "camcal/rig.h"
#include "vision/apriltag_detector.h"
#include "vision/bayer.h"
#include "vision/target.h"
#include "vision/tool_pose.h"

namespace kincal {

struct CameraOrderCheck {
  int sampled = 0;        // pairs tried
  int pass_as_given = 0;  // tool poses passing the gate as given
  int pass_swapped = 0;   // the same with the two images exchanged

  // At least two sampled pairs, at least half of them, pass exchanged, and
  // more than twice as many as pass as given.
  bool LooksSwapped() const;
};

// Tries up to `max_pairs` pairs, spread evenly over the session (first[k]
// is the image of rig camera 0, second[k] of camera 1), each with
// full-frame detection. An image whose size does not fit the camera it is
// tried for counts as not passing. `bayer`: the images are raw mosaics of
// this pattern (vision/bayer.h).
CameraOrderCheck CheckCameraOrder(
    const Rig& rig, const Target& target, const std::vector<std::string>& first,
    const std::vector<std::string>& second,
    const std::function<bool(const ToolPoseResult&)>& passes_gate,
    const AprilTagOptions& detector, int max_pairs = 6,
    BayerPattern bayer = BayerPattern::kNone);

}  // namespace kincal

#endif  // KINCAL_VISION_CAMERA_ORDER_H_
