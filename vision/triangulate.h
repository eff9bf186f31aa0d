#ifndef KINCAL_VISION_TRIANGULATE_H_
#define KINCAL_VISION_TRIANGULATE_H_

// Stereo matching of tag corners by id and triangulation of points seen by
// two or more cameras of a rig (points in the rig frame, mm).

#include <Eigen/Core>
#include <vector>

#include "camcal/rig.h"
#include "vision/apriltag_detector.h"

namespace kincal {

// One tag corner seen by two cameras (pixels in OpenCV's convention).
struct StereoCorner {
  int tag_id = 0;
  int corner = 0;  // 0..3, libapriltag order
  Eigen::Vector2d px0 = Eigen::Vector2d::Zero();
  Eigen::Vector2d px1 = Eigen::Vector2d::Zero();
};

// Pairs the corners of tags found in both views, by id. An id detected more
// than once in either view is ambiguous and left out.
std::vector<StereoCorner> MatchTagCorners(
    const std::vector<TagDetection>& view0,
    const std::vector<TagDetection>& view1);

// A pixel in one camera of the rig.
struct PixelObservation {
  int camera = 0;
  Eigen::Vector2d px = Eigen::Vector2d::Zero();
};

struct TriangulationOptions {
  bool refine = true;       // Gauss-Newton on the reprojection error
  int max_iterations = 10;  // of the refinement
};

struct TriangulatedPoint {
  bool ok = false;  // false: fewer than two rays, degenerate, or behind
  Eigen::Vector3d p_in_rig = Eigen::Vector3d::Zero();
  double rms_px = 0;  // reprojection RMS over the observations
};

// Linear triangulation (DLT on undistorted normalized coordinates, so
// distortion is removed exactly), then optional refinement of the
// reprojection error. Throws std::logic_error for a camera index outside the
// rig (a programming error).
TriangulatedPoint TriangulatePoint(
    const Rig& rig, const std::vector<PixelObservation>& observations,
    const TriangulationOptions& options = TriangulationOptions());

}  // namespace kincal

#endif  // KINCAL_VISION_TRIANGULATE_H_
