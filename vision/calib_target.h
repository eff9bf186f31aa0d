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
//
// Lengths are in target units: give them in mm and the rig is in mm.

#include <memory>
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
  std::string text;          // the spec as given

  // All target points in index order (target units, z = 0).
  std::vector<Eigen::Vector3d> Points() const;
};

// Parses a --target value; InputError naming what is wrong otherwise.
CalibTargetSpec ParseCalibTargetSpec(const std::string& text);

class CalibTargetDetector {
 public:
  explicit CalibTargetDetector(const CalibTargetSpec& spec);
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
