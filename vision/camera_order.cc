#include "vision/camera_order.h"

#include <algorithm>

#include "data/error.h"
#include "vision/stereo_images.h"

namespace kincal {
namespace {

// The detections of `path` read as rig camera `camera`; empty when its size
// is not that camera's.
bool DetectAs(const Rig& rig, int camera, const std::string& path,
              BayerPattern bayer, AprilTagDetector* detector,
              std::vector<TagDetection>* out) {
  try {
    *out = detector->Detect(
        ReadCameraImage(path, rig.cameras[camera].intrinsics, bayer));
    return true;
  } catch (const InputError&) {
    return false;
  }
}

}  // namespace

bool CameraOrderCheck::LooksSwapped() const {
  return pass_swapped >= 2 && 2 * pass_swapped >= sampled &&
         pass_swapped > 2 * pass_as_given;
}

CameraOrderCheck CheckCameraOrder(
    const Rig& rig, const Target& target, const std::vector<std::string>& first,
    const std::vector<std::string>& second,
    const std::function<bool(const ToolPoseResult&)>& passes_gate,
    const AprilTagOptions& detector_options, int max_pairs,
    BayerPattern bayer) {
  CameraOrderCheck check;
  const int n = static_cast<int>(std::min(first.size(), second.size()));
  if (n == 0 || rig.cameras.size() < 2) return check;
  const int samples = std::min(n, max_pairs);
  AprilTagDetector detector(detector_options);
  for (int s = 0; s < samples; ++s) {
    const int k = static_cast<int>((s + 0.5) * n / samples);
    ++check.sampled;
    std::vector<std::vector<TagDetection>> given(2), swapped(2);
    if (DetectAs(rig, 0, first[k], bayer, &detector, &given[0]) &&
        DetectAs(rig, 1, second[k], bayer, &detector, &given[1]) &&
        passes_gate(EstimateToolPose(rig, target, given))) {
      ++check.pass_as_given;
    }
    if (DetectAs(rig, 0, second[k], bayer, &detector, &swapped[0]) &&
        DetectAs(rig, 1, first[k], bayer, &detector, &swapped[1]) &&
        passes_gate(EstimateToolPose(rig, target, swapped))) {
      ++check.pass_swapped;
    }
  }
  return check;
}

}  // namespace kincal
