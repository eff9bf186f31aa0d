#ifndef KINCAL_SYNTH_RENDER_H_
#define KINCAL_SYNTH_RENDER_H_

// Synthetic stereo images of the tool target (and of AprilGrid boards) seen
// through the rig's camera models, with their ground truth.
//
// Rendering is by inverse mapping: every pixel's ray (camcal's UndistortPixel,
// so distortion is exact) is intersected with the textured planes; the pixel
// value is the box-filtered texture, i.e. the mean over a Fibonacci lattice of
// sub-pixel samples wherever the pixel straddles a texel or plane boundary
// (89 samples: edge positions are exact to ~0.01 px whatever their angle).
// Then: exposure gain, Gaussian blur (optics), Gaussian noise, 8-bit rounding.
//
// Ground-truth pixels follow OpenCV's convention ((0, 0) = centre of the
// top-left pixel); tag corners are in libapriltag's order
// (vision/apriltag_detector.h).

#include <Eigen/Core>
#include <array>
#include <memory>
#include <opencv2/core.hpp>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "camcal/camera_model.h"
#include "camcal/rig.h"
#include "vision/target.h"

namespace kincal {

// A textured rectangle in the plane z = 0 of its own frame. The texture's
// row 0 is at y = top_left_mm.y (y grows down the rows, x along the columns);
// one texel is size_mm / (cols, rows). Seen from the -z side only (z points
// into the plane, as for tags).
// The light falling on a plane: a gain on its texture's gray levels (1 = as
// RenderOptions::black/white say), and optionally a shadow edge across it:
// points (x, y) of the plane (mm) with shadow_normal . (x, y) >
// shadow_offset_mm get shadow_gain instead, through a linear penumbra of
// penumbra_mm.
struct PlaneLight {
  double gain = 1.0;
  double shadow_gain = 1.0;  // 1 = no shadow
  Eigen::Vector2d shadow_normal = Eigen::Vector2d::UnitX();
  double shadow_offset_mm = 0.0;
  double penumbra_mm = 0.5;
  bool Uniform() const { return gain == 1.0 && shadow_gain == 1.0; }
};

struct TexturedPlane {
  Rigid3 rig_from_plane;
  cv::Mat texture;  // CV_8UC1, 0 = black, 255 = white
  Eigen::Vector2d top_left_mm = Eigen::Vector2d::Zero();
  Eigen::Vector2d size_mm = Eigen::Vector2d::Zero();
  PlaneLight light;
};

// The plane of one printed tag (black square of edge size_mm plus its white
// border) in the tag frame of docs/CONVENTIONS.md.
TexturedPlane TagPlane(const std::string& family, int id, double size_mm,
                       const Rigid3& rig_from_tag);
// All tags of `target` with the tool at rig_from_tool.
std::vector<TexturedPlane> TargetPlanes(const Target& target,
                                        const Rigid3& rig_from_tool);

// A straight needle (a thin cylinder) drawn over the planes.
struct Needle {
  Eigen::Vector3d base_in_rig = Eigen::Vector3d::Zero();
  Eigen::Vector3d tip_in_rig = Eigen::Vector3d::Zero();
  double radius_mm = 0.4;
  double gray = 200;  // its brightness (0..255)
};

struct RenderOptions {
  double background = 90;  // gray level behind the planes
  double black = 30;       // gray level of texture value 0
  double white = 220;      // gray level of texture value 255
  double blur_sigma_px = 0.0;
  double noise_sigma = 0.0;  // gray levels, Gaussian
  // Exposure: gain drawn per image from N(1, exposure_jitter), clamped to
  // [0.5, 1.5], applied to all gray levels.
  double exposure_jitter = 0.0;
  // Optics and sensor beyond the Gaussian blur, so that tests do not share
  // the tracker's assumptions: a defocus disk (radius, px), a linear motion
  // blur (length, px, along motion_angle_deg from the image x axis),
  // vignetting (gain 1 - vignetting * (r / r_corner)^2), a horizontal light
  // gradient (gain 1 + light_gradient * (x / width - 0.5)), and JPEG
  // compression of the 8-bit image (quality 1..100, 0 = lossless).
  double defocus_px = 0.0;
  double motion_px = 0.0;
  double motion_angle_deg = 0.0;
  double vignetting = 0.0;
  double light_gradient = 0.0;
  int jpeg_quality = 0;
  // The optics (defocus, motion, Gaussian blur) act on the light before a
  // pixel integrates it, as in a camera: the scene is shaded on a grid
  // kFineOptics times finer, blurred there and averaged over each pixel.
  // false: they act on the pixel-integrated image (each pixel's light
  // spread to its neighbours), whose spread function is a comb of pixel
  // boxes rather than the optics' and, under ~1 px, not Gaussian (a
  // sampled sigma of 0.5 px is the taps 0.107 / 0.786 / 0.107): a model
  // of round optics then leans on small tags (docs/VISION.md).
  bool fine_optics = true;
  // Light on the tags (the "light-aware" renders; all off by default, the
  // simple renderer is the fast one):
  //  - light_in_rig: the direction a distant light travels (rig frame; zero
  //    = even light). A tag's paper then has the gain ambient + (1 -
  //    ambient) * max(0, cos) (Lambert, cos between the light and the tag's
  //    normal), so tags turned away from it are dim;
  //  - tag_gain[i]: a further gain on tag i of the target (missing = 1);
  //  - a shadow edge across tag shadow_tag (index in the target, -1 = none):
  //    the part beyond a line at shadow_angle_deg through the point
  //    shadow_offset * size from the tag's centre gets shadow_gain;
  //  - bayer: a colour sensor (RGGB mosaic with the channel gains
  //    bayer_gains for gray paper, noise and 8 bits per photosite), whose
  //    image is demosaiced to gray by OpenCV (cvtColor, Bayer to gray), as
  //    a colour camera's driver delivers it; with bayer_raw the mosaic
  //    itself (one 8-bit photosite per pixel, not demosaiced), as a colour
  //    camera delivers it in its raw formats (GenICam BayerRG8, V4L2 RGGB);
  //    demosaic: how the mosaic becomes gray (a driver's choice; the
  //    refinement must not depend on it): kBilinear (the default) OpenCV's
  //    Bayer to gray (bilinear colour, then OpenCV's gray weights), kVng
  //    and kEdgeAware OpenCV's VNG and edge-aware demosaics to colour, then
  //    to gray (VNG's two-row shift in OpenCV < 4.12 undone).
  Eigen::Vector3d light_in_rig = Eigen::Vector3d::Zero();
  double ambient = 0.15;
  std::vector<double> tag_gain;
  int shadow_tag = -1;
  double shadow_angle_deg = 0.0;
  double shadow_offset = 0.0;
  double shadow_gain = 0.35;
  bool bayer = false;
  bool bayer_raw = false;  // with bayer: write the mosaic, not demosaiced
  enum class Demosaic { kBilinear, kVng, kEdgeAware };
  Demosaic demosaic = Demosaic::kBilinear;
  std::array<double, 3> bayer_gains = {0.55, 1.0, 0.75};  // R, G, B
  // The needle: a cylinder from needle_base_in_tool to the target's tip.
  bool draw_needle = false;
  Eigen::Vector3d needle_base_in_tool = Eigen::Vector3d::Zero();
  double needle_radius_mm = 0.4;
  double needle_gray = 200;

  void Check() const;  // InputError naming the bad option
};

// Sub-pixels per pixel along x and along y for RenderOptions::fine_optics.
constexpr int kFineOptics = 3;

// Renders one camera. Holds the camera's per-pixel-corner undistortion grid,
// so make one per camera and reuse it across frames. Thread-compatible
// (Render is const).
class ViewRenderer {
 public:
  explicit ViewRenderer(const Camera& camera);
  // Image of `planes` (nearest plane wins; on a tie the later one, so a tag
  // lying on a board is drawn over it) and `needles`; CV_8UC1.
  cv::Mat Render(const std::vector<TexturedPlane>& planes,
                 const std::vector<Needle>& needles,
                 const RenderOptions& options, std::mt19937_64* rng) const;
  const Camera& camera() const { return camera_; }

 private:
  // `fine`: the camera of `coarse` kFineOptics times finer, its corner
  // rays interpolated from the coarse ones.
  ViewRenderer(const Camera& fine, const ViewRenderer& coarse);
  // The light each pixel integrates (planes shaded, needles drawn).
  cv::Mat Radiance(const std::vector<TexturedPlane>& planes,
                   const std::vector<Needle>& needles,
                   const RenderOptions& options) const;
  // The same camera kFineOptics times finer, built on first use (shared by
  // copies; thread-safe).
  const ViewRenderer& Fine() const;

  Camera camera_;
  int width_ = 0, height_ = 0;
  // Undistorted normalized (x, y) at pixel corners (u - 0.5, v - 0.5),
  // (width + 1) x (height + 1), row-major.
  std::vector<Eigen::Vector2d> corner_rays_;
  struct FineView;
  std::shared_ptr<FineView> fine_;
};

// Ground truth of one tag in one view.
struct TagTruth {
  int id = 0;
  std::array<Eigen::Vector2d, 4> corners;  // px, libapriltag order
  // Front-facing, in front of the camera, all corners >= 3 px inside.
  bool visible = false;
};

struct ViewTruth {
  cv::Mat image;
  std::vector<TagTruth> tags;
  Eigen::Vector2d tip_px = Eigen::Vector2d::Zero();
};

struct StereoFrameTruth {
  Rigid3 rig_from_tool;
  Eigen::Vector3d tip_in_rig = Eigen::Vector3d::Zero();
  std::vector<ViewTruth> views;  // one per rig camera
};

// Projects the target's tag corners into `camera` (ground truth).
std::vector<TagTruth> ProjectTargetCorners(const Camera& camera,
                                           const Target& target,
                                           const Rigid3& rig_from_tool);

// Sets the light of the target's tag planes (TargetPlanes order) from the
// options' light, tag gains and shadow.
void LightTags(const RenderOptions& options, const Target& target,
               std::vector<TexturedPlane>* planes);

// Renders every camera of a rig (caches their undistortion grids).
class StereoRenderer {
 public:
  StereoRenderer(const Rig& rig, const Target& target,
                 const RenderOptions& options);
  // Deterministic for a given rng state.
  StereoFrameTruth Render(const Rigid3& rig_from_tool,
                          std::mt19937_64* rng) const;

 private:
  Rig rig_;
  Target target_;
  RenderOptions options_;
  std::vector<ViewRenderer> views_;
};

// The truth.csv and corners.csv tables of rendered frames (the layout below
// and in synth/recorded_session.h), for every writer of rendered sessions.
class TruthTables {
 public:
  // `header`: the comment line(s) that open both files ("# written by ...").
  // `seed`: the render noise seed, recorded in truth.csv.
  TruthTables(const std::string& header, uint64_t seed);
  // Frame `frame_index`: its rig_from_tool and tip (truth.csv), and the tag
  // corners of every view, view c under `camera_labels[c]` (corners.csv).
  void Add(size_t frame_index, const StereoFrameTruth& frame,
           const std::vector<std::string>& camera_labels);
  std::string TruthCsv() const { return truth_.str(); }
  std::string CornersCsv() const { return corners_.str(); }

 private:
  std::ostringstream truth_, corners_;
};

// Renders a whole session into `folder` (created if missing):
//   <camera name>_000000.png ...    one 8-bit PNG per camera and frame
//   rig.yaml, target.yaml           the inputs, for `kincal track`
//   truth.csv     frame, r00..r22, tx, ty, tz (rig_from_tool, mm),
//                 tip_x, tip_y, tip_z (tip in rig, mm)
//   corners.csv   frame, camera, tag, corner, u, v, visible (px, OpenCV)
// Every file is written atomically with a provenance comment (CSV/YAML).
// Noise is seeded by `seed` (recorded in truth.csv). Returns the number of
// frames written. Throws InputError for bad options or an unwritable folder.
int RenderSession(const Rig& rig, const Target& target,
                  const std::vector<Rigid3>& rig_from_tool,
                  const RenderOptions& options, uint64_t seed,
                  const std::string& folder);

// A Kalibr-style AprilGrid: cols x rows tags of edge tag_size_mm (black
// square), spaced by spacing_ratio * tag_size_mm, printed upright. Ids as
// Kalibr prints them (and as vision/calib_target.h's aprilgrid model
// expects): first_id.. row-major from the BOTTOM-left tag, i.e. tag
// first_id + i * cols + c is in the i-th row counted from the bottom.
// Board frame (the renderer's, tag-frame-like): origin at the top-left corner
// of the top-left tag's black square, x along a row, y down the columns, z
// into the board. Kalibr's target frame is BoardFromTarget() of it. As a
// Target: tags with tool_from_tag = board_from_tag.
struct AprilGrid {
  int cols = 6;
  int rows = 6;
  double tag_size_mm = 30;
  double spacing_ratio = 0.3;
  int first_id = 0;
  std::string family = "tag36h11";
  // Kalibr prints small black squares in the gaps at the tags' corners.
  bool corner_squares = false;

  Target AsTarget() const;
  // White board (margin of one spacing around the tags), the tags, and the
  // corner squares if asked, with the board at rig_from_board.
  std::vector<TexturedPlane> Planes(const Rigid3& rig_from_board) const;
  // Kalibr's target frame of the same board (vision/calib_target.h: origin
  // at the bottom-left corner of tag first_id's black square, x right, y up,
  // z out of the printed face) in the board frame: rotation of 180 deg about
  // x. rig_from_target = rig_from_board * BoardFromTarget().
  Rigid3 BoardFromTarget() const;
};

// A demonstration scene for tests, the bench and `kincal simulate --render`:
// two cameras (fx = fy = 1.40625 * width, the right one 120 mm to the right
// and turned 5 deg inwards, mild radial-tangential distortion) and a tool of
// four 25 mm tag36h11 tags (ids 0..3) on two faces folded by +-20 deg, tip at
// (0, 100, 10) mm in `tool`, working distance about 450 mm.
Rig ExampleStereoRig(int width = 640, int height = 512);
Target ExampleTarget();
// A tool pose near the middle of ExampleStereoRig's common view: `i`
// varies it deterministically (small rotations and shifts).
Rigid3 ExampleToolPose(int i);

}  // namespace kincal

#endif  // KINCAL_SYNTH_RENDER_H_
