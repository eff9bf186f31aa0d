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
#include <optional>
#include <string>
#include <vector>

#include "camcal/camera_model.h"
#include "camcal/rig.h"
#include "vision/demosaic_model.h"

namespace kincal {

// The edge refinement's view of one side of a tag (corner k to k + 1).
struct TagSideQuality {
  double line_rms_px = 0;  // edge points about their fitted line
  double blur_px = 0;      // Gaussian sigma that fits the side's profiles
  double contrast = 0;     // white - black, gray levels (median over the side)
  double fit_rms = 0;      // profile residual RMS, gray levels (median)
  int points = 0;          // edge points on the line
  int near_other_tag = 0;  // samples whose window reaches another tag
};

// Another tag in the same image (libapriltag's corners), which the edge
// refinement's sampling keeps clear of.
struct NeighbourTag {
  std::array<Eigen::Vector2d, 4> corners;
};

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
  // False where neither the refined nor libapriltag's corner can be trusted
  // (JudgeCorner): the fits leave that corner out. `corners[k]` then holds
  // libapriltag's.
  std::array<bool, 4> usable = {true, true, true, true};
  // Per side, when the edge refinement ran (all zero otherwise).
  std::array<TagSideQuality, 4> sides{};
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
  // worse than the detector it refines; JudgeCorner): a refined corner is
  // taken when both adjacent sides' edge points scatter at most
  // max_edge_rms_px about their lines and it moved at most
  // max_refine_shift_px from libapriltag's. Otherwise libapriltag's corner
  // is judged by the same edge evidence: farther than detector_off_edges_px
  // from either refined side line, it is the bad one and the refined corner
  // is taken (within max_refine_shift_px; the corner is unusable beyond);
  // on the lines, it is taken while the sides scatter at most
  // max_fallback_edge_rms_px, and the corner is unusable beyond. The shift
  // limit is wide on purpose: libapriltag's own corners are off by 1-2 px
  // on 1-2 % of the corners of rendered holders (bench/corner_bench.cc).
  // The pose fit's per-corner check (vision/tool_pose.h) judges again
  // against the pose.
  double max_refine_shift_px = 3.0;
  double max_edge_rms_px = 0.15;
  double detector_off_edges_px = 0.3;
  double max_fallback_edge_rms_px = 0.3;
  // A colour camera's demosaiced image (Bayer to gray) blurs its four pixel
  // phases differently (bilinear demosaic: the pixels that sampled green
  // are sharper than those that sampled red or blue), so an edge read
  // through interpolation looks skewed wherever the phases either side of
  // it differ. An image whose phases differ in sharpness by more than this
  // ratio (PhaseSharpnessRatio) is refined as demosaiced: its profiles are
  // read at pixel centres with their phase, and each side fits one blur
  // per phase (edge_profile.h). Measured: gray renders 1.0-1.3 (any blur,
  // motion, defocus, JPEG), OpenCV-demosaiced Bayer renders 3-12.
  double demosaiced_ratio = 2.0;
  // A demosaiced image's tags are first fitted with a linear (bilinear)
  // demosaic's model (vision/demosaic_model.h: each pixel a known sum of its
  // neighbours' blurred samples, the channels' shares fitted on the image's
  // largest tags); the model refines the image when its profiles' residual
  // is below the blur per phase's, else the blur per phase does (another
  // demosaic: VNG, edge-aware). false: the blur per phase always.
  bool fit_demosaic = true;
  // The camera whose images are searched (optional). Its lens distortion
  // bends a tag's straight sides in the image, and lines fitted there meet
  // off the corners: a side of L px at normalized radius r bends by about
  // 6 |k1| r L^2 / (8 f) px, 0.03 px for a 40 px side at r = 0.2 with
  // k1 = -0.12 and f = 900 px, and the bias follows the tag across the
  // image. With the lens, each side's edge points are mapped to the pinhole
  // image (PinholePixel), where the sides are straight, the lines fitted and
  // intersected there and the corners distorted back. Its size must be the
  // images'. Without it (or without distortion) the lines are fitted in the
  // image.
  std::optional<CameraIntrinsics> lens;

  // Throws InputError naming the bad option and its value.
  void Check() const;
};

// Which corner a detection keeps at index k after the edge refinement (see
// AprilTagOptions' checks); `t` holds the refined corners, libapriltag's and
// the sides' quality. Exposed for tests.
enum class CornerSource { kRefined, kDetector, kNeither };
CornerSource JudgeCorner(const TagDetection& t, int k,
                         const AprilTagOptions& options);

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
  const cv::Mat& Pattern(int id);  // TagImage(family, id), cached
  void RefineByEdges(const cv::Mat& gray, std::vector<TagDetection>* dets);

  struct Impl;
  Options options_;
  std::unique_ptr<Impl> impl_;
};

// One detector per camera of `rig` (each used by one thread at a time),
// `options` with that camera as its lens (AprilTagOptions::lens).
std::vector<std::unique_ptr<AprilTagDetector>> CameraDetectors(
    const Rig& rig, const AprilTagOptions& options);

// Refines the corners of one detection in place by the pattern model of
// vision/edge_profile.h (exposed for tests and the bench): `tag_image` is
// TagImage(family, det->id), `cells` the family's cells across the detected
// square, `others` the other tags detected in the image: samples whose
// window comes within one of their cells are left out, unless that would
// leave fewer than a third of the side's samples (an AprilGrid's tags, one
// white board around them all, keep every sample).
// `phased`: the image is demosaiced (AprilTagOptions::demosaiced_ratio):
// profiles at pixel centres, a blur per Bayer phase, no area rule.
// Returns false and leaves `det` unchanged when the refinement fails (a
// side too short, too close to the image border, or with fewer than four
// edge points); fills det->sides otherwise.
// `demosaic` (with `phased`): the linear demosaic's kernels
// (FitTagsDemosaic) replace the blur per phase, one blur per side pair.
// `lens` (optional): the lines are fitted in its pinhole image
// (AprilTagOptions::lens).
bool RefineCornersByEdges(const cv::Mat& gray, const cv::Mat& tag_image,
                          int cells, TagDetection* det,
                          const std::vector<NeighbourTag>& others = {},
                          bool phased = false,
                          const DemosaicKernels* demosaic = nullptr,
                          const CameraIntrinsics* lens = nullptr);

// For a demosaiced image: the bilinear demosaic (FitBilinearDemosaic) that
// fits the sides of up to `max_tags` of the largest detections (`tag_images`
// per detection, libapriltag's corners), and whether its profiles'
// residual is below the blur per phase's on the same profiles.
struct TagsDemosaicFit {
  bool better = false;  // the model fits better than the blur per phase
  BilinearDemosaic model;
  double model_rms = 0;  // profile residual RMS, gray levels
  double phase_rms = 0;  // the same with the blur per phase
  int profiles = 0;      // compared
};
TagsDemosaicFit FitTagsDemosaic(const cv::Mat& gray,
                                const std::vector<const cv::Mat*>& tag_images,
                                int cells,
                                const std::vector<TagDetection>& dets,
                                int max_tags = 6);
bool RefineCornersBySubPix(const cv::Mat& gray, TagDetection* det);

// How differently the four Bayer phases ((x % 2, y % 2)) of `gray` are
// blurred around the detected tags: the largest phase's mean squared second
// difference (along x plus along y) over the smallest's, over the tags'
// bounding boxes; 1 when a phase has fewer than 100 pixels there. About 1
// for a gray sensor; a demosaiced mosaic's sharp and blunt phases give 3+.
double PhaseSharpnessRatio(const cv::Mat& gray,
                           const std::vector<TagDetection>& dets);

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
