#ifndef KINCAL_SYNTH_POVRAY_SCENE_H_
#define KINCAL_SYNTH_POVRAY_SCENE_H_

// Scenes for POV-Ray, a ray tracer we did not write (Debian `povray`), so
// that tests and benchmarks can show the tracker and the bundle images whose
// antialiasing, texture sampling, shading and shadows share nothing with
// synth/render.cc: the tags as matte paper on grey anodised plates, the
// needle, a checked table behind, an area light from the side (soft
// shadows, tags turned away from it dimmer) and a weak light at the rig.
// POV-Ray's camera is a pinhole: the views have no lens distortion.
// bench/povray_session.sh renders whole sessions; tests/povray_render_test
// a few frames.

#include <opencv2/core.hpp>
#include <random>
#include <string>

#include "camcal/camera_model.h"
#include "data/rigid3.h"
#include "vision/target.h"

namespace kincal {

struct PovSceneOptions {
  // Where the area light stands in the rig frame: at `light_distance` times
  // the target's depth, turned light_deg from the rig's -x axis (camera
  // left) toward -y (up), and a third of the depth in front of the rig.
  double light_deg = 35;
  double light_distance = 1.1;
  // White paper beyond the tag's own one-cell white border, cells per side
  // (0: the paper ends with the printed tag, as synth/render.cc's tags).
  double margin_cells = 0;
  // Depth of the table behind the target, times the target's depth.
  double table_depth = 1.7;

  // Throws InputError naming the bad option.
  void Check() const;
};

// The POV-Ray scene of one view of the target: camera `camera` (its
// distortion ignored) at cam_from_rig, the tool at rig_from_tool,
// `depth_mm` the target's typical depth in the rig (places the light and
// the table). The tag textures are read from "tag_<id>.pgm" next to the
// scene (WriteTagImages).
std::string PovViewScene(const CameraIntrinsics& camera,
                         const Rigid3& cam_from_rig, const Target& target,
                         const Rigid3& rig_from_tool, double depth_mm,
                         const PovSceneOptions& options);

// The POV-Ray camera alone: pixel (u, v) (OpenCV pixel centres) looks along
// (u - cx) / fx, (v - cy) / fy, 1 in the camera frame. Exposed for tests.
std::string PovCamera(const CameraIntrinsics& camera);

// Writes tag_<id>.pgm (one pixel per cell, TagImage) for every tag into
// `dir`.
void WriteTagImages(const Target& target, const std::string& dir);

// A rendered view as a sensor gives it: 8-bit gray with shot noise
// (variance shot * level) and read noise (sigma read_noise, levels).
cv::Mat SensorImage(const cv::Mat& rendered, double read_noise, double shot,
                    std::mt19937_64* rng);

}  // namespace kincal

#endif  // KINCAL_SYNTH_POVRAY_SCENE_H_
