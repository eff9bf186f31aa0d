#ifndef KINCAL_VISION_CALIB_TARGET_H_
#define KINCAL_VISION_CALIB_TARGET_H_

// Calibration targets for `kincal camcal`, and their detection producing the
// 2D-3D correspondences camcal/calibrate_cameras.h consumes.
//
// Specs (command line --target):
//   chessboard:COLSxROWS:SQUARE
//     COLS x ROWS inner corners (OpenCV's patternSize), SQUARE = square edge.
//     Target frame: origin at the first inner corner, x along a row, y along
//     a column, z = 0; point index = row * COLS + col (OpenCV's order).
//     Detection: cv::findChessboardCorners + cv::cornerSubPix (11x11 window,
//     as OpenCV's stereo_calib sample), in OpenCV's corner order. (A
//     normalisation "first corner nearest the image's top-left" was tried and
//     dropped: it flips one camera of a stereo pair when the board's rows run
//     diagonally, and OpenCV's own order is consistent across the pair.)
//   aprilgrid:COLSxROWS:TAG_SIZE:SPACING_RATIO
//     Kalibr's AprilGrid: COLS x ROWS tag36h11 tags, TAG_SIZE = edge of the
//     black square, gap between tags = SPACING_RATIO * TAG_SIZE. Ids are
//     row-major from 0 starting at the bottom-left tag as printed (Kalibr).
//     Target frame (Kalibr's): origin at the bottom-left corner of tag 0's
//     black square, x right along the rows, y up, z = 0. Tag id's corner k
//     (libapriltag order: bottom-left, bottom-right, top-right, top-left) is
//     point 4 * id + k. Detection: vision/apriltag_detector.h.
//   aprilgrid:COLSxROWS:TAG_SIZE:SPACING_RATIO:KEY=VALUE...
//     Another layout of the same grid, for boards not printed by Kalibr:
//     first=N (the first id, default 0), order=rows|columns (default rows),
//     origin=bottom-left|top-left (the tag with the first id, default
//     bottom-left), rotation=0|90|180|270 (each tag turned counter-clockwise
//     as printed, default 0). E.g. AprilTags.jl's 8 x 5 grid of ids 1..40:
//     aprilgrid:8x5:31.5:0.3:first=1:order=columns:origin=top-left:rotation=180
//     Point 4 * (id - first) + k; the target frame stays the grid's.
//
// Lengths are in target units: give them in mm and the rig is in mm.

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "camcal/calibrate_cameras.h"

namespace cv {
class Mat;
}

namespace kincal {

struct CalibTargetSpec {
  enum class Kind { kChessboard, kAprilGrid };
  Kind kind = Kind::kChessboard;
  int cols = 0;  // inner corners (chessboard) or tags (AprilGrid)
  int rows = 0;
  double size = 0;           // square edge or tag black-square edge
  double spacing_ratio = 0;  // AprilGrid only
  // AprilGrid layout, as printed (defaults: Kalibr's). Ids first_id ..
  // first_id + cols * rows - 1 run row by row (or column by column) from
  // the bottom-left (or top-left) tag; every tag turned by rotation_deg
  // counter-clockwise (0, 90, 180, 270).
  int first_id = 0;
  bool column_major = false;
  bool origin_top = false;
  int rotation_deg = 0;
  std::string text;  // the spec as given

  // Grid cell (column from the left, row from the bottom) of the tag
  // first_id + index.
  Eigen::Vector2i TagCell(int index) const;

  // All target points in index order (target units, z = 0).
  std::vector<Eigen::Vector3d> Points() const;
};

// Parses a --target value; InputError naming what is wrong otherwise.
CalibTargetSpec ParseCalibTargetSpec(const std::string& text);

class CalibTargetDetector {
 public:
  // `lens` (optional, AprilGrid only): the camera whose images are read,
  // its tags' sides fitted where they are straight (AprilTagOptions::lens);
  // camcal's second pass detects with the first pass's calibration.
  explicit CalibTargetDetector(
      const CalibTargetSpec& spec,
      const std::optional<CameraIntrinsics>& lens = std::nullopt);
  ~CalibTargetDetector();
  CalibTargetDetector(const CalibTargetDetector&) = delete;
  CalibTargetDetector& operator=(const CalibTargetDetector&) = delete;

  // Detects the target in an 8-bit gray image. Returns an empty observation
  // when the target is not found (chessboard: not all corners found).
  TargetObservation Detect(const cv::Mat& gray);

  const CalibTargetSpec& spec() const { return spec_; }

 private:
  struct Impl;
  CalibTargetSpec spec_;
  std::unique_ptr<Impl> impl_;
};

}  // namespace kincal

#endif  // KINCAL_VISION_CALIB_TARGET_H_
