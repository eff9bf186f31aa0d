#ifndef KINCAL_VISION_APRILTAG_DETECTOR_H_
#define KINCAL_VISION_APRILTAG_DETECTOR_H_

// A thin RAII wrapper over libapriltag 3 with sub-pixel corner refinement at
// full resolution.
//
// Pixel convention: OpenCV, (0, 0) is the CENTRE of the top-left pixel.
// libapriltag reports (0, 0) at the top-left CORNER of that pixel; Detect()
// shifts its corners and centre by -0.5 px in x and y, once, here.
//
// Corner order (libapriltag's, kept): for a tag seen upright as printed, with
// the tag frame of docs/CONVENTIONS.md (origin at the centre, x right, y down
// the printed image, z into the tag) and s = size of the black square,
//   corners[0] = (-s/2, +s/2)  bottom-left
//   corners[1] = (+s/2, +s/2)  bottom-right
//   corners[2] = (+s/2, -s/2)  top-right
//   corners[3] = (-s/2, -s/2)  top-left
// TagCornerInTag() returns these points; render_test checks the order.

#include <Eigen/Dense>
#include <array>
#include <memory>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace kincal {

struct TagDetection {
  int id = -1;
  // OpenCV pixel convention, libapriltag's corner order (see above).
  std::array<Eigen::Vector2d, 4> corners = {
      Eigen::Vector2d::Zero(), Eigen::Vector2d::Zero(), Eigen::Vector2d::Zero(),
      Eigen::Vector2d::Zero()};
  Eigen::Vector2d center = Eigen::Vector2d::Zero();
  // libapriltag's own corners (same convention and order); `corners` differ
  // from them only where refined[k] (the refinement passed its checks).
  std::array<Eigen::Vector2d, 4> detector_corners = corners;
  std::array<bool, 4> refined = {false, false, false, false};
  double decision_margin = 0;  // libapriltag's decoding quality
  int hamming = 0;             // bits corrected
};

// Corner of index k (0..3) in the tag frame, mm, for a black square of edge
// `size_mm` (z = 0).
Eigen::Vector3d TagCornerInTag(int k, double size_mm);

// How detected corners are refined at full resolution.
enum class CornerRefinement {
  kNone,          // libapriltag's corners as they are
  kCornerSubPix,  // cv::cornerSubPix on each corner
  kEdges,         // sub-pixel edge points along the four sides, a line fit
                  // per side, corners = intersections of adjacent lines
};

// Detector settings (libapriltag's fields plus the refinement).
struct AprilTagOptions {
  // tag36h11, tag25h9, tag16h5, tagStandard41h12 (reversed border: its
  // detected square is the white one inside the black ring; `size` in
  // target.yaml is that square's edge, width_at_border = 5 cells).
  std::string family = "tag36h11";
  double quad_decimate = 2.0;  // quad search on a decimated image
  double quad_sigma = 0.8;     // Gaussian blur for the quad search, px
  bool refine_edges = true;    // libapriltag's own edge snapping
  int nthreads = 1;
  double decode_sharpening = 0.25;
  int max_hamming = 1;  // bits corrected when decoding (0..2)
  CornerRefinement refinement = CornerRefinement::kEdges;
  // Tags whose decision margin is below this are dropped.
  double min_decision_margin = 0.0;
  // Checks of the edge refinement, per corner (the refinement must never be
  // worse than the detector it refines): a refined corner falls back to
  // libapriltag's when it moved more than max_refine_shift_px from it, when
  // an adjacent side's edge points scatter more than max_edge_rms_px about
  // their line, or when another tag's quad comes within one cell (+ the
  // sampling window) of an adjacent side (its edges would enter the window).
  double max_refine_shift_px = 0.3;
  double max_edge_rms_px = 0.15;

  // Throws InputError naming the bad option and its value.
  void Check() const;
};

class AprilTagDetector {
 public:
  using Options = AprilTagOptions;

  explicit AprilTagDetector(const Options& options = Options());
  ~AprilTagDetector();
  AprilTagDetector(const AprilTagDetector&) = delete;
  AprilTagDetector& operator=(const AprilTagDetector&) = delete;

  // Detects tags in an 8-bit gray image (CV_8UC1); sorted by id, then by x.
  // Not thread-safe (one detector per thread).
  std::vector<TagDetection> Detect(const cv::Mat& gray);

  // Detects tags in `roi` (clipped to the image) and reports full-image
  // coordinates. Refinement reads the full image, so a tag touching the
  // region's border is refined like any other.
  std::vector<TagDetection> DetectInRegion(const cv::Mat& gray, cv::Rect roi);

  const Options& options() const { return options_; }

 private:
  struct Impl;
  Options options_;
  std::unique_ptr<Impl> impl_;
};

// Refines the corners of one detection in place (exposed for tests and the
// bench). Returns false and leaves `det` unchanged when the refinement fails
// (e.g. a side too close to the image border).
// `side_rms` (optional) receives, per side k (corner k to k+1), the RMS
// distance of the side's edge points from their fitted line, px.
bool RefineCornersByEdges(const cv::Mat& gray, TagDetection* det,
                          std::array<double, 4>* side_rms = nullptr);
bool RefineCornersBySubPix(const cv::Mat& gray, TagDetection* det);
// Reverts to libapriltag's corners the corners of every side whose sampling
// band (1.5 cells + 1 px) reaches another detected tag's quad.
void RevertCornersNearOtherTags(std::vector<TagDetection>* dets);

// The tag's image as printed (libapriltag's apriltag_to_image): one pixel per
// cell, 0 = black, 255 = white, including the white border (10x10 cells for
// tag36h11, whose black square is the middle 8x8). Throws InputError for an
// unknown family or id.
cv::Mat TagImage(const std::string& family, int id);
// Cells across the black square of a family (8 for tag36h11).
int TagBlackSquareCells(const std::string& family);
// Whether `family` is one this wrapper supports, and its number of ids.
bool IsKnownTagFamily(const std::string& family);
int TagFamilySize(const std::string& family);

}  // namespace kincal

#endif  // KINCAL_VISION_APRILTAG_DETECTOR_H_
