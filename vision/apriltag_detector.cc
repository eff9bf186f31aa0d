#include "vision/apriltag_detector.h"

extern "C" {
#include <apriltag/apriltag.h>
}

#include <algorithm>
#include <cmath>
#include <map>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "data/error.h"
#include "data/median.h"
#include "data/minimize.h"
#include "vision/edge_profile.h"
#include "vision/image_lines.h"
#include "vision/tag_family.h"

namespace kincal {

using image_lines::Bilinear;
using image_lines::FitLine;
using image_lines::Inside;
using image_lines::Intersect;
using image_lines::Line2;
using image_lines::SegmentsDistance;

cv::Mat TagImage(const std::string& family, int id) {
  TagFamilyHandle f(family);
  if (id < 0 || id >= static_cast<int>(f.family->ncodes)) {
    std::ostringstream os;
    os << "tag id " << id << " is not in family " << family << " (0.."
       << f.family->ncodes - 1 << ")";
    throw InputError(os.str());
  }
  // As libapriltag's apriltag_to_image (whose image type is not exported):
  // black square of width_at_border cells with a one-cell white ring around
  // it, data bits at (bit_x, bit_y) from the black square's corner, MSB first.
  // Families with a reversed border (tagStandard41h12) have their white
  // ring on the detected square itself, with a black ring outside it and
  // data bits outside that (as libapriltag draws them).
  const apriltag_family_t* fam = f.family;
  const int total = fam->total_width;
  const int start = (total - fam->width_at_border) / 2;
  cv::Mat out(total, total, CV_8UC1, cv::Scalar(0));
  const int ring = fam->reversed_border ? start : start - 1;
  for (int i = ring; i < total - ring; ++i) {
    out.at<uint8_t>(ring, i) = 255;
    out.at<uint8_t>(total - 1 - ring, i) = 255;
    out.at<uint8_t>(i, ring) = 255;
    out.at<uint8_t>(i, total - 1 - ring) = 255;
  }
  const uint64_t code = fam->codes[id];
  for (uint32_t i = 0; i < fam->nbits; ++i) {
    if (code & (uint64_t{1} << (fam->nbits - i - 1))) {
      out.at<uint8_t>(start + fam->bit_y[i], start + fam->bit_x[i]) = 255;
    }
  }
  return out;
}

void AprilTagOptions::Check() const {
  auto fail = [](const std::string& what, double value) {
    std::ostringstream os;
    os << "apriltag detector option " << what << " = " << value;
    throw InputError(os.str());
  };
  if (FindTagFamily(family) == nullptr) {
    throw InputError("unknown tag family '" + family +
                     "' (expected one of: " + KnownTagFamilies() + ")");
  }
  if (!(quad_decimate >= 1.0))
    fail("quad_decimate (expected >= 1)", quad_decimate);
  if (!(quad_sigma >= 0.0)) fail("quad_sigma (expected >= 0)", quad_sigma);
  if (nthreads < 1) fail("nthreads (expected >= 1)", nthreads);
  if (max_hamming < 0 || max_hamming > 2) {
    fail("max_hamming (expected 0..2)", max_hamming);
  }
  if (!(max_refine_shift_px > 0.0)) {
    fail("max_refine_shift_px (expected > 0)", max_refine_shift_px);
  }
  if (!(max_edge_rms_px > 0.0)) {
    fail("max_edge_rms_px (expected > 0)", max_edge_rms_px);
  }
  if (!(detector_off_edges_px > 0.0)) {
    fail("detector_off_edges_px (expected > 0)", detector_off_edges_px);
  }
  if (!(max_fallback_edge_rms_px >= max_edge_rms_px)) {
    fail("max_fallback_edge_rms_px (expected >= max_edge_rms_px)",
         max_fallback_edge_rms_px);
  }
  if (!(demosaiced_ratio > 1.0)) {
    fail("demosaiced_ratio (expected > 1)", demosaiced_ratio);
  }
  if (!(decode_sharpening >= 0.0)) {
    fail("decode_sharpening (expected >= 0)", decode_sharpening);
  }
}

struct AprilTagDetector::Impl {
  explicit Impl(const Options& o) : family(o.family) {
    td = apriltag_detector_create();
    apriltag_detector_add_family_bits(td, family.family, o.max_hamming);
    td->quad_decimate = static_cast<float>(o.quad_decimate);
    td->quad_sigma = static_cast<float>(o.quad_sigma);
    td->refine_edges = o.refine_edges;
    td->nthreads = o.nthreads;
    td->decode_sharpening = o.decode_sharpening;
  }
  ~Impl() { apriltag_detector_destroy(td); }
  TagFamilyHandle family;
  apriltag_detector_t* td = nullptr;
  std::map<int, cv::Mat> patterns;  // TagImage by id
};

AprilTagDetector::AprilTagDetector(const Options& options) : options_(options) {
  options_.Check();
  impl_ = std::make_unique<Impl>(options_);
}

AprilTagDetector::~AprilTagDetector() = default;

const cv::Mat& AprilTagDetector::Pattern(int id) {
  auto it = impl_->patterns.find(id);
  if (it == impl_->patterns.end()) {
    it = impl_->patterns.emplace(id, TagImage(options_.family, id)).first;
  }
  return it->second;
}

namespace {

// Distance of p from the line through a and b.
double LineDistance(const Eigen::Vector2d& p, const Eigen::Vector2d& a,
                    const Eigen::Vector2d& b) {
  const Eigen::Vector2d d = (b - a).normalized();
  return std::abs(d.x() * (p - a).y() - d.y() * (p - a).x());
}

}  // namespace

// Corner k joins side k-1 (corners k-1, k) and side k (corners k, k+1).
// Refined corners whose two sides' edge points lie on their lines are taken.
// Otherwise libapriltag's corner is judged by the same edge evidence: off
// either refined line by more than detector_off_edges_px it is the worse of
// the two (bench/corner_bench.cc: 0.7-2.6 px against 0.1-0.6 for the
// refined one), and the refined corner is taken while it stays within
// max_refine_shift_px; on the lines, it is taken while the sides scatter
// less than max_fallback_edge_rms_px, and neither is trusted beyond that.
CornerSource JudgeCorner(const TagDetection& t, int k,
                         const AprilTagOptions& options) {
  const int prev = (k + 3) % 4, next = (k + 1) % 4;
  const double scatter =
      std::max(t.sides[k].line_rms_px, t.sides[prev].line_rms_px);
  const bool near = (t.corners[k] - t.detector_corners[k]).norm() <=
                    options.max_refine_shift_px;
  if (scatter <= options.max_edge_rms_px && near) return CornerSource::kRefined;
  const double off_edges = std::max(
      LineDistance(t.detector_corners[k], t.corners[prev], t.corners[k]),
      LineDistance(t.detector_corners[k], t.corners[k], t.corners[next]));
  if (off_edges > options.detector_off_edges_px) {
    return near ? CornerSource::kRefined : CornerSource::kNeither;
  }
  return scatter <= options.max_fallback_edge_rms_px ? CornerSource::kDetector
                                                     : CornerSource::kNeither;
}

// Per phase, the mean of (2 I - left - right)^2 + (2 I - up - down)^2 over
// the tags' bounding boxes (their edges are where the phases' blurs show);
// the ratio of the largest to the smallest, 1 with too few pixels.
double PhaseSharpnessRatio(const cv::Mat& gray,
                           const std::vector<TagDetection>& dets) {
  std::array<double, 4> energy = {0, 0, 0, 0};
  std::array<int, 4> count = {0, 0, 0, 0};
  for (const TagDetection& d : dets) {
    Eigen::Vector2d lo = d.corners[0], hi = d.corners[0];
    for (const auto& c : d.corners) {
      lo = lo.cwiseMin(c);
      hi = hi.cwiseMax(c);
    }
    const int x0 = std::max(1, static_cast<int>(lo.x()));
    const int y0 = std::max(1, static_cast<int>(lo.y()));
    const int x1 = std::min(gray.cols - 2, static_cast<int>(hi.x()) + 1);
    const int y1 = std::min(gray.rows - 2, static_cast<int>(hi.y()) + 1);
    for (int y = y0; y <= y1; ++y) {
      const uint8_t* r = gray.ptr<uint8_t>(y);
      const uint8_t* up = gray.ptr<uint8_t>(y - 1);
      const uint8_t* down = gray.ptr<uint8_t>(y + 1);
      for (int x = x0; x <= x1; ++x) {
        const double h = 2.0 * r[x] - r[x - 1] - r[x + 1];
        const double v = 2.0 * r[x] - up[x] - down[x];
        const int phase = (x & 1) + 2 * (y & 1);
        energy[phase] += h * h + v * v;
        ++count[phase];
      }
    }
  }
  double lo = 1e300, hi = 0;
  for (int p = 0; p < 4; ++p) {
    if (count[p] < 100) return 1.0;
    lo = std::min(lo, energy[p] / count[p]);
    hi = std::max(hi, energy[p] / count[p]);
  }
  return lo > 0 ? hi / lo : 1.0;
}

namespace {

// The lens whose pinhole image the sides are fitted in: options.lens when
// it has distortion (nullptr otherwise: the image is its own pinhole image).
const CameraIntrinsics* DistortingLens(const AprilTagOptions& options) {
  if (!options.lens) return nullptr;
  for (double k : options.lens->distortion) {
    if (k != 0) return &*options.lens;
  }
  return nullptr;
}

}  // namespace

// Each detection refined with the others' quads known (its sampling skips
// them), then checked corner by corner against libapriltag's.
void AprilTagDetector::RefineByEdges(const cv::Mat& gray,
                                     std::vector<TagDetection>* dets) {
  const int cells = static_cast<int>(impl_->family.family->width_at_border);
  const bool phased = !dets->empty() && PhaseSharpnessRatio(gray, *dets) >
                                            options_.demosaiced_ratio;
  DemosaicKernels kernels;
  bool linear_demosaic = false;
  if (phased && options_.fit_demosaic) {
    std::vector<const cv::Mat*> images;
    for (const TagDetection& t : *dets) images.push_back(&Pattern(t.id));
    const TagsDemosaicFit fit = FitTagsDemosaic(gray, images, cells, *dets);
    linear_demosaic = fit.better;
    kernels = fit.model.Kernels();
  }
  for (size_t i = 0; i < dets->size(); ++i) {
    TagDetection& t = (*dets)[i];
    std::vector<NeighbourTag> others;
    for (size_t j = 0; j < dets->size(); ++j) {
      if (j != i) {
        others.push_back({(*dets)[j].detector_corners});
      }
    }
    if (!RefineCornersByEdges(gray, Pattern(t.id), cells, &t, others, phased,
                              linear_demosaic ? &kernels : nullptr,
                              DistortingLens(options_))) {
      continue;
    }
    const TagDetection judged = t;  // every corner against the refined ones
    for (int k = 0; k < 4; ++k) {
      switch (JudgeCorner(judged, k, options_)) {
        case CornerSource::kRefined:
          t.refined[k] = true;
          break;
        case CornerSource::kDetector:
          t.corners[k] = t.detector_corners[k];
          break;
        case CornerSource::kNeither:
          t.corners[k] = t.detector_corners[k];
          t.usable[k] = false;
          break;
      }
    }
  }
}

std::vector<std::unique_ptr<AprilTagDetector>> CameraDetectors(
    const Rig& rig, const AprilTagOptions& options) {
  std::vector<std::unique_ptr<AprilTagDetector>> detectors;
  for (const Camera& camera : rig.cameras) {
    AprilTagOptions o = options;
    o.lens = camera.intrinsics;
    detectors.push_back(std::make_unique<AprilTagDetector>(o));
  }
  return detectors;
}

std::vector<TagDetection> AprilTagDetector::Detect(const cv::Mat& gray) {
  return DetectInRegion(gray, cv::Rect(0, 0, gray.cols, gray.rows));
}

std::vector<TagDetection> AprilTagDetector::DetectInRegion(const cv::Mat& gray,
                                                           cv::Rect roi) {
  if (gray.type() != CV_8UC1) {
    throw InputError("apriltag detector: expected an 8-bit gray image");
  }
  const std::optional<CameraIntrinsics>& lens = options_.lens;
  if (lens && lens->width > 0 &&
      (lens->width != gray.cols || lens->height != gray.rows)) {
    std::ostringstream os;
    os << "apriltag detector: the image is " << gray.cols << "x" << gray.rows
       << " px, camera '" << lens->name << "' " << lens->width << "x"
       << lens->height << ": the image is not that camera's (check the "
       << "rig's camera order and resolution)";
    throw InputError(os.str());
  }
  roi &= cv::Rect(0, 0, gray.cols, gray.rows);
  std::vector<TagDetection> out;
  if (roi.width < 16 || roi.height < 16) return out;
  const cv::Mat crop = gray(roi);
  // libapriltag reads the image through its stride and does not write it.
  image_u8_t im{crop.cols, crop.rows, static_cast<int32_t>(crop.step[0]),
                const_cast<uint8_t*>(crop.ptr<uint8_t>(0))};
  zarray_t* dets = apriltag_detector_detect(impl_->td, &im);
  for (int i = 0; i < zarray_size(dets); ++i) {
    apriltag_detection_t* d = nullptr;
    zarray_get(dets, i, &d);
    if (d->decision_margin < options_.min_decision_margin) continue;
    TagDetection t;
    t.id = d->id;
    t.hamming = d->hamming;
    t.decision_margin = d->decision_margin;
    // libapriltag's (0, 0) is the top-left pixel's corner: -0.5 px.
    const Eigen::Vector2d offset(roi.x - 0.5, roi.y - 0.5);
    for (int k = 0; k < 4; ++k) {
      t.corners[k] = Eigen::Vector2d(d->p[k][0], d->p[k][1]) + offset;
    }
    t.center = Eigen::Vector2d(d->c[0], d->c[1]) + offset;
    t.detector_corners = t.corners;
    out.push_back(t);
  }
  apriltag_detections_destroy(dets);
  switch (options_.refinement) {
    case CornerRefinement::kNone:
      break;
    case CornerRefinement::kCornerSubPix:
      for (TagDetection& t : out) {
        if (RefineCornersBySubPix(gray, &t))
          t.refined = {true, true, true, true};
      }
      break;
    case CornerRefinement::kEdges:
      RefineByEdges(gray, &out);
      break;
  }
  std::sort(out.begin(), out.end(),
            [](const TagDetection& a, const TagDetection& b) {
              if (a.id != b.id) return a.id < b.id;
              return a.center.x() < b.center.x();
            });
  return out;
}

namespace {

// image_from_template homography (h33 = 1) from the four corners: template
// coordinates in texels of TagImage, the detected square spanning
// [start, start + cells] (corner order of the header: 0 bottom-left).
Eigen::Matrix3d ImageFromTemplate(const std::array<Eigen::Vector2d, 4>& c,
                                  double start, double cells) {
  const double lo = start, hi = start + cells;
  const std::array<Eigen::Vector2d, 4> t = {
      Eigen::Vector2d(lo, hi), Eigen::Vector2d(hi, hi), Eigen::Vector2d(hi, lo),
      Eigen::Vector2d(lo, lo)};
  Eigen::Matrix<double, 8, 8> A;
  Eigen::Matrix<double, 8, 1> b;
  for (int i = 0; i < 4; ++i) {
    const double x = t[i].x(), y = t[i].y(), u = c[i].x(), v = c[i].y();
    A.row(2 * i) << x, y, 1, 0, 0, 0, -u * x, -u * y;
    A.row(2 * i + 1) << 0, 0, 0, x, y, 1, -v * x, -v * y;
    b(2 * i) = u;
    b(2 * i + 1) = v;
  }
  const Eigen::Matrix<double, 8, 1> h = A.fullPivLu().solve(b);
  Eigen::Matrix3d H;
  H << h(0), h(1), h(2), h(3), h(4), h(5), h(6), h(7), 1.0;
  return H;
}

// The printed pattern seen through a homography: class 0 black, 1 white,
// 2 outside the tag, at an image point.
struct PatternView {
  const cv::Mat* image;  // TagImage
  Eigen::Matrix3d template_from_image;
  int ClassAt(const Eigen::Vector2d& q) const {
    const Eigen::Vector3d t = template_from_image * q.homogeneous();
    if (!(t.z() > 0)) return 2;
    const double x = t.x() / t.z(), y = t.y() / t.z();
    if (!(x >= 0 && y >= 0 && x < image->cols && y < image->rows)) return 2;
    return image->at<uint8_t>(static_cast<int>(y), static_cast<int>(x)) > 127
               ? 1
               : 0;
  }
};

// The pattern along q(o) = p + o n for o in [lo, hi]: breaks found on a
// `step` px scan (shorter than any cell: the refinement needs cells of 1.5
// px), each refined by bisection to 1e-3 px.
void PatternAlong(const PatternView& view, const Eigen::Vector2d& p,
                  const Eigen::Vector2d& n, double lo, double hi,
                  EdgeProfile* profile, double step = 0.1) {
  profile->breaks.clear();
  profile->classes.clear();
  int prev = view.ClassAt(p + lo * n);
  profile->classes.push_back(prev);
  for (double o = lo + step; o <= hi; o += step) {
    const int c = view.ClassAt(p + o * n);
    if (c == prev) continue;
    double a = o - step, b = o;
    while (b - a > 1e-3) {
      const double m = 0.5 * (a + b);
      if (view.ClassAt(p + m * n) == prev) {
        a = m;
      } else {
        b = m;
      }
    }
    profile->breaks.push_back(0.5 * (a + b));
    profile->classes.push_back(c);
    prev = c;
  }
}

// Whether the segment ab comes within one cell (+ 1 px) of another tag's
// quad: its white border and black square would enter the profile.
bool NearOtherTag(const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                  const std::vector<NeighbourTag>& others, double cells) {
  for (const NeighbourTag& t : others) {
    const auto& o = t.corners;
    double side = 0;
    for (int m = 0; m < 4; ++m) side += (o[(m + 1) % 4] - o[m]).norm() / 4;
    const double reach = side / cells + 1.0;
    for (int m = 0; m < 4; ++m) {
      if (SegmentsDistance(a, b, o[m], o[(m + 1) % 4]) < reach) return true;
    }
  }
  return false;
}

// Profiles across one side (corner a to b, outward normal n) at sample
// points along its middle 80 %, each with its pattern; samples near the
// image border are skipped, and unless too few would remain, those reaching
// another tag and those whose pattern changes within along_px along the
// side (a data bit's edge, the square's corner: the blur mixes the
// neighbouring pattern into the line's profile). When too few clear ones
// would remain (cells of a few blur widths, where the pattern changes
// within the blur's reach on most of the side) and along_sigma > 0, the
// varying profiles are kept with the lines beside them mixed into their
// model (MixAlongSide, EdgeProfile::mixture).
struct SideProfiles {
  std::vector<Eigen::Vector2d> base;
  std::vector<EdgeProfile> profiles;
  int near_other_tag = 0;
  double cell = 0;
};

// Whether two profiles' patterns agree: the same classes, each break
// within `tolerance_px`.
bool SamePattern(const EdgeProfile& a, const EdgeProfile& b,
                 double tolerance_px) {
  if (a.classes != b.classes) return false;
  for (size_t i = 0; i < a.breaks.size(); ++i) {
    if (std::abs(a.breaks[i] - b.breaks[i]) > tolerance_px) return false;
  }
  return true;
}

// How far outward of the side a demosaiced image's profile reads, in
// cells: to the white border's outer edge. Beyond it lies what the printed
// pattern does not know (the paper's margin, the holder, a neighbouring
// tag's border a fraction of a cell away), which the model takes as one
// flat level; a demosaic's kernels carry it into the window. Measured on
// the BH-7 side-light renders (four tags 0.55 cell apart, docs/VISION.md):
// the 1.5 cells the other profiles read left corners 0.0088 px inward on
// average and the bundle's robot 1.7x the gray images' (1.3x now).
constexpr double kDemosaicedOuterReachCells = 1.0;

// A demosaiced image's profile: the pixels whose centres lie in the strip
// across the side at p (|along| < half_width, -reach <= offset <=
// outer_reach), each at its own offset with its Bayer phase, unsorted. Read
// at pixel centres, not interpolated: interpolation would mix the phases'
// blurs into one.
void PixelProfile(const cv::Mat& gray, const Eigen::Vector2d& p,
                  const Eigen::Vector2d& n, const Eigen::Vector2d& dir,
                  double reach, double outer_reach, double half_width,
                  EdgeProfile* prof) {
  const double rx = reach * std::abs(n.x()) + half_width * std::abs(dir.x());
  const double ry = reach * std::abs(n.y()) + half_width * std::abs(dir.y());
  for (int y = static_cast<int>(std::ceil(p.y() - ry));
       y <= static_cast<int>(std::floor(p.y() + ry)); ++y) {
    for (int x = static_cast<int>(std::ceil(p.x() - rx));
         x <= static_cast<int>(std::floor(p.x() + rx)); ++x) {
      const Eigen::Vector2d d = Eigen::Vector2d(x, y) - p;
      const double along = dir.dot(d), o = n.dot(d);
      if (along < -half_width || along >= half_width || o < -reach ||
          o > outer_reach) {
        continue;
      }
      prof->offsets.push_back(o);
      prof->values.push_back(gray.at<uint8_t>(y, x));
      prof->phases.push_back((x & 1) + 2 * (y & 1));
    }
  }
  prof->box_px = std::max(std::abs(n.x()), std::abs(n.y()));
}

// The patterns of the lines beside the one at p (along the side, within
// 2.5 along_sigma), each weighted by a Gaussian blur along the side of
// along_sigma: what the image at p mixes in where the pattern changes
// along the side. Lines whose patterns agree (breaks within 0.05 px) are
// merged, their weights summed.
void MixAlongSide(const PatternView& view, const Eigen::Vector2d& p,
                  const Eigen::Vector2d& n, const Eigen::Vector2d& dir,
                  double reach, double along_sigma, EdgeProfile* prof) {
  prof->mixture.clear();
  const int half = static_cast<int>(std::ceil(2.5 * along_sigma / 0.4));
  const double step = 2.5 * along_sigma / std::max(1, half);
  double total = 0;
  for (int j = -half; j <= half; ++j) {
    const double s = j * step;
    EdgeProfile line;
    PatternAlong(view, p + s * dir, n, -reach - 6.0, reach + 6.0, &line);
    const double w = std::exp(-0.5 * s * s / (along_sigma * along_sigma));
    total += w;
    bool merged = false;
    for (PatternLine& m : prof->mixture) {
      if (m.classes != line.classes) continue;
      bool same = true;
      for (size_t i = 0; i < m.breaks.size() && same; ++i) {
        same = std::abs(m.breaks[i] - line.breaks[i]) <= 0.05;
      }
      if (!same) continue;
      m.weight += w;
      merged = true;
      break;
    }
    if (!merged) prof->mixture.push_back({line.breaks, line.classes, w});
  }
  for (PatternLine& m : prof->mixture) m.weight /= total;
  if (prof->mixture.size() == 1) prof->mixture.clear();
}

SideProfiles ProfilesOfSide(const cv::Mat& gray, const PatternView& view,
                            const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                            const Eigen::Vector2d& n, double cell, double cells,
                            double along_px, double along_sigma,
                            const std::vector<NeighbourTag>& others,
                            bool phased) {
  SideProfiles out;
  out.cell = cell;
  const double len = (b - a).norm();
  const Eigen::Vector2d dir = (b - a) / len;
  // The window reaches one cell past the edge on both sides (the black
  // ring and the white border) plus 2 px for the blur, at most 1.5 cells.
  const double reach = std::max(2.0, std::min(1.5 * cell, cell + 2.0));
  const double step = std::clamp(cell / 8.0, 0.25, 1.0);
  const int samples = std::clamp(static_cast<int>(len * 0.8), 6, 32);
  std::vector<bool> near, varied;
  for (int s = 0; s < samples; ++s) {
    const double t = 0.1 + 0.8 * (s + 0.5) / samples;
    const Eigen::Vector2d p = a + t * len * dir;
    const Eigen::Vector2d lo = p - reach * n, hi = p + reach * n;
    if (!Inside(gray, lo, 1.0) || !Inside(gray, hi, 1.0)) continue;
    EdgeProfile prof;
    if (phased) {
      PixelProfile(gray, p, n, dir, reach,
                   std::min(reach, kDemosaicedOuterReachCells * cell),
                   std::max(0.5, 0.5 * 0.8 * len / samples), &prof);
    } else {
      for (double o = -reach; o <= reach + 1e-9; o += step) {
        const Eigen::Vector2d q = p + o * n;
        prof.offsets.push_back(o);
        prof.values.push_back(Bilinear(gray, q.x(), q.y()));
      }
    }
    // Pattern beyond the window as far as a wide blur reaches into it.
    PatternAlong(view, p, n, -reach - 6.0, reach + 6.0, &prof);
    // The model is the pattern along this one line: where the pattern
    // changes within the blur's reach along the side (a data bit's edge,
    // the square's corner), the image mixes the neighbouring pattern in.
    bool varies = false;
    EdgeProfile here;
    PatternAlong(view, p, n, -reach - 1.0, reach + 1.0, &here, 0.5);
    for (const double s_px : {-along_px, along_px}) {
      EdgeProfile beside;
      PatternAlong(view, p + s_px * dir, n, -reach - 1.0, reach + 1.0, &beside,
                   0.5);
      varies = varies || !SamePattern(here, beside, 0.25 * cell);
    }
    near.push_back(NearOtherTag(lo, hi, others, cells) || varies);
    varied.push_back(varies);
    out.near_other_tag += near.back() && !varies ? 1 : 0;
    out.base.push_back(p);
    out.profiles.push_back(std::move(prof));
  }
  int left_out = 0;
  for (const bool b : near) left_out += b ? 1 : 0;
  const int clear = static_cast<int>(out.base.size()) - left_out;
  if (left_out > 0 && clear >= std::max(4, samples / 3)) {
    SideProfiles kept = out;
    kept.base.clear();
    kept.profiles.clear();
    for (size_t i = 0; i < near.size(); ++i) {
      if (near[i]) continue;
      kept.base.push_back(out.base[i]);
      kept.profiles.push_back(std::move(out.profiles[i]));
    }
    return kept;
  }
  // Too few clear samples (cells under a few blur widths): the varying
  // ones stay, with the lines beside them mixed into their model.
  if (along_sigma > 0 && !phased) {
    for (size_t i = 0; i < varied.size(); ++i) {
      if (!varied[i]) continue;
      MixAlongSide(view, out.base[i], n, dir, reach, along_sigma,
                   &out.profiles[i]);
    }
  }
  return out;
}

// The side's blur: the sigma that fits eight of its profiles best
// (golden section on log sigma in [0.3, 3] px, 8 steps: to 2 %). With
// `phased` (profiles read at pixel centres with their Bayer phases), then
// each phase's own sigma in turn, the others held (within 0.5-2x the
// shared one, 7 steps: to 4 %).
PhaseSigmas SideBlur(const std::vector<EdgeProfile>& profiles, bool phased) {
  if (profiles.empty()) return {1.0, 1.0, 1.0, 1.0};
  size_t stride = std::max<size_t>(1, profiles.size() / 8);
  const auto cost = [&](const PhaseSigmas& sigma) {
    double sum = 0;
    for (size_t i = 0; i < profiles.size(); i += stride) {
      const EdgeProfileFit f = FitEdgeProfile(profiles[i], sigma, 3);
      sum += f.ok ? f.rms * f.rms : 1e6;
    }
    return sum;
  };
  const GoldenSectionResult r = GoldenSectionMinimize(
      [&](double log_sigma) {
        const double s = std::exp(log_sigma);
        return cost({s, s, s, s});
      },
      std::log(0.3), std::log(3.0), 8);
  const double shared = std::exp(0.5 * (r.lo + r.hi));
  PhaseSigmas sigma = {shared, shared, shared, shared};
  if (!phased) return sigma;
  stride = 1;
  for (int phase = 0; phase < 4; ++phase) {
    const GoldenSectionResult rp = GoldenSectionMinimize(
        [&](double log_sigma) {
          PhaseSigmas s = sigma;
          s[phase] = std::exp(log_sigma);
          return cost(s);
        },
        std::log(0.5 * shared), std::log(2.0 * shared), 7);
    sigma[phase] = std::exp(0.5 * (rp.lo + rp.hi));
  }
  return sigma;
}

// Each side's blur (SideBlur). Demosaiced: a phase's blur depends on the
// edge's direction (a demosaic's kernels are not round), so opposite sides,
// nearly parallel, share their per-phase blurs, fitted on both sides'
// profiles: twice the pixels for the four widths.
std::array<PhaseSigmas, 4> SidesBlur(const std::array<SideProfiles, 4>& sides,
                                     bool phased) {
  std::array<PhaseSigmas, 4> sigma;
  if (!phased) {
    for (int k = 0; k < 4; ++k) sigma[k] = SideBlur(sides[k].profiles, false);
    return sigma;
  }
  for (int k = 0; k < 2; ++k) {
    std::vector<EdgeProfile> both = sides[k].profiles;
    both.insert(both.end(), sides[k + 2].profiles.begin(),
                sides[k + 2].profiles.end());
    sigma[k] = sigma[k + 2] = SideBlur(both, true);
  }
  return sigma;
}

// The cell of quad `c` (its shortest side over the `cells` across it), 0
// when the quad is too small to refine (a side under 8 px or cells under
// 1.5 px).
double RefinableCell(const std::array<Eigen::Vector2d, 4>& c, int cells) {
  double shortest = 1e9;
  for (int j = 0; j < 4; ++j) {
    shortest = std::min(shortest, (c[(j + 1) % 4] - c[j]).norm());
  }
  const double cell = shortest / cells;
  return shortest < 8.0 || cell < 1.5 ? 0.0 : cell;
}

// The outward unit normal of side k (corner k to k + 1) of quad `c`.
Eigen::Vector2d OutwardNormal(const std::array<Eigen::Vector2d, 4>& c, int k) {
  const Eigen::Vector2d a = c[k], b = c[(k + 1) % 4];
  const Eigen::Vector2d dir = (b - a).normalized();
  const Eigen::Vector2d centroid = (c[0] + c[1] + c[2] + c[3]) / 4.0;
  Eigen::Vector2d n(-dir.y(), dir.x());
  return n.dot((a + b) / 2 - centroid) < 0 ? Eigen::Vector2d(-n) : n;
}

// Whether a side of blur sigma and cells of `cell` px takes the area rule
// (FitSide): sharp (sigma < 0.8 px) with its neighbouring edges 2.5 sigma
// clear of the rule's window of +-min(0.45 cell, 3 px).
bool AreaRuleApplies(double sigma, double cell) {
  return sigma < 0.8 && std::min(0.45 * cell, 3.0) >= 0.8 &&
         0.55 * cell >= 2.5 * sigma;
}

// With a linear demosaic's kernels: one (optical) blur per pair of
// opposite sides, the demosaic's own blur being in the kernels.
std::array<PhaseSigmas, 4> DemosaicedSidesBlur(
    const std::array<SideProfiles, 4>& sides,
    const std::array<Eigen::Vector2d, 4>& normals,
    const DemosaicKernels& kernels) {
  std::array<PhaseSigmas, 4> sigma;
  for (int k = 0; k < 2; ++k) {
    const double s = DemosaicedBlur({{&sides[k].profiles, normals[k]},
                                     {&sides[k + 2].profiles, normals[k + 2]}},
                                    kernels);
    sigma[k] = sigma[k + 2] = {s, s, s, s};
  }
  return sigma;
}

// Edge points of one side: the profiles' shifts along the normal.
// `demosaic`: the profiles are fitted with a linear demosaic's kernels and
// the blur sigmas[0].
bool FitSide(const cv::Mat& gray, const SideProfiles& side,
             const Eigen::Vector2d& n, const PhaseSigmas& sigmas, bool phased,
             const CameraIntrinsics* lens, Line2* line, TagSideQuality* quality,
             const DemosaicKernels* demosaic = nullptr) {
  const double sigma = sigmas[0];
  std::vector<Eigen::Vector2d> pts;
  std::vector<double> contrast, fit_rms;
  const double w = std::min(0.45 * side.cell, 3.0);
  for (size_t i = 0; i < side.profiles.size(); ++i) {
    const EdgeProfile& prof = side.profiles[i];
    const EdgeProfileFit f =
        demosaic ? FitDemosaicedProfile(prof, n, *demosaic, sigma)
                 : FitEdgeProfile(prof, sigmas);
    if (!f.ok) continue;
    double shift = f.shift_px;
    // A sharp side (sigma < 0.8 px, its neighbouring edges one cell away):
    // the area rule, referenced to the model. The area under a step is the
    // same under any symmetric blur and under pixel integration, which the
    // Gaussian model is not for a sharp edge; the tails of the neighbouring
    // edges (the white border's outer edge, the data bits) that reach the
    // window are in the model's area as in the image's, so they cancel:
    //   e = e_model + rule(image) - rule(model)
    // with rule() the area rule over [e_model - w, e_model + w], each with
    // its own plateaus read at the window's ends (the image sampled at
    // 0.25 px: the trapezoid rule is then exact on the bilinear interpolant
    // of a pixel-integrated step; the model's area in closed form). The rule
    // alone read the white plateau darkened by the border's outer edge and
    // pulled every side inwards: a tag-scale bias.
    if (!phased && prof.mixture.empty() && AreaRuleApplies(sigma, side.cell)) {
      EdgeProfile fine;
      for (double o = shift - w - 0.25; o <= shift + w + 0.25; o += 0.25) {
        const Eigen::Vector2d q = side.base[i] + o * n;
        if (!Inside(gray, q, 1.0)) break;
        fine.offsets.push_back(o);
        fine.values.push_back(Bilinear(gray, q.x(), q.y()));
      }
      if (fine.offsets.size() < 8 || fine.offsets.back() < shift + w) {
        continue;
      }
      const size_t m = fine.values.size();
      const double inside = 0.5 * (fine.values[0] + fine.values[1]);
      const double outside = 0.5 * (fine.values[m - 1] + fine.values[m - 2]);
      if (std::abs(outside - inside) < 5.0) continue;
      // The model's plateaus where the image's were read, and its area.
      const std::vector<double> ends =
          EdgeProfileModel(prof,
                           {fine.offsets[0], fine.offsets[1],
                            fine.offsets[m - 2], fine.offsets[m - 1]},
                           f.shift_px, sigma, f.levels);
      const double model_inside = 0.5 * (ends[0] + ends[1]);
      const double model_outside = 0.5 * (ends[2] + ends[3]);
      if (std::abs(model_outside - model_inside) < 5.0) continue;
      const double model_area = EdgeProfileModelArea(
          prof, shift - w, shift + w, f.shift_px, sigma, f.levels);
      shift = f.shift_px + AreaRuleShift(fine, inside, outside, shift, w) -
              AreaRuleShiftFromArea(model_area, model_inside, model_outside,
                                    shift, w);
      if (std::abs(shift - f.shift_px) > 0.5) continue;
    }
    pts.push_back(side.base[i] + shift * n);
    contrast.push_back(std::abs(f.levels[1] - f.levels[0]));
    fit_rms.push_back(f.rms);
  }
  if (pts.size() < 4) return false;
  // Where the side is straight: the lens's pinhole image.
  if (lens) {
    for (Eigen::Vector2d& q : pts) q = PinholePixel(*lens, q);
  }
  *line = FitLine(pts);
  // Drop points far from the line (another edge, a glint) and refit.
  std::vector<double> res;
  for (const auto& q : pts) res.push_back(std::abs(line->n.dot(q) - line->c));
  const double limit = std::max(3.0 * 1.4826 * UpperMedian(res), 0.05);
  std::vector<Eigen::Vector2d> kept;
  for (size_t i = 0; i < pts.size(); ++i) {
    if (res[i] <= limit) kept.push_back(pts[i]);
  }
  if (kept.size() < 4) return false;
  if (kept.size() < pts.size()) *line = FitLine(kept);
  double ss = 0;
  for (const auto& q : kept) {
    const double r = line->n.dot(q) - line->c;
    ss += r * r;
  }
  quality->line_rms_px = std::sqrt(ss / kept.size());
  quality->blur_px =
      phased ? 0.25 * (sigmas[0] + sigmas[1] + sigmas[2] + sigmas[3]) : sigma;
  quality->contrast = UpperMedian(contrast);
  quality->fit_rms = UpperMedian(fit_rms);
  quality->points = static_cast<int>(kept.size());
  quality->near_other_tag = side.near_other_tag;
  return true;
}

}  // namespace

// Edge refinement by the pattern model (vision/edge_profile.h): for each
// side, profiles across it at sample points along its middle 80 % are
// fitted with the tag's own printed pattern along that line (its data bits,
// black ring, white border and the outside), blurred by a Gaussian whose
// width the side's profiles choose, with black, white and outside levels
// per profile; the shifts give edge points, a total least-squares line per
// side (3 MAD outliers dropped) and the corners as intersections. Two
// passes: the second places the pattern by the first's corners. Samples
// whose window reaches another detected tag are left out (while enough
// remain), not the whole side; where too few would remain, the second pass
// keeps them with the patterns of the lines beside mixed into their model
// by a Gaussian along the side as wide as the neighbouring sides' blur
// (the blur along a side is the blur across its neighbours; exact for a
// Gaussian, which separates). A sharp side (sigma < 0.8 px, its
// neighbouring edges 2.5 sigma clear of the window) takes the area rule
// with the plateaus at the window's ends instead (edge_profile.h).
bool RefineCornersByEdges(const cv::Mat& gray, const cv::Mat& tag_image,
                          int cells, TagDetection* det,
                          const std::vector<NeighbourTag>& others, bool phased,
                          const DemosaicKernels* demosaic,
                          const CameraIntrinsics* lens) {
  const double start = 0.5 * (tag_image.cols - cells);
  std::array<Eigen::Vector2d, 4> c = det->corners;
  std::array<TagSideQuality, 4> quality{};
  std::array<PhaseSigmas, 4> sigma{};
  for (int pass = 0; pass < 2; ++pass) {
    PatternView view{&tag_image, ImageFromTemplate(c, start, cells).inverse()};
    const double cell = RefinableCell(c, cells);
    if (cell == 0) return false;
    std::array<SideProfiles, 4> sides;
    std::array<Eigen::Vector2d, 4> normals;
    for (int k = 0; k < 4; ++k) {
      const Eigen::Vector2d a = c[k], b = c[(k + 1) % 4];
      const Eigen::Vector2d n = OutwardNormal(c, k);
      normals[k] = n;
      // The blur along side k: the blur across its neighbours. Sides that
      // take the area rule keep their own line's pattern (the rule, exact
      // for a sharp pixel-integrated edge, serves them better than the
      // model; measured: corner_bench's blur 0.5 scenes).
      const double along_sigma =
          pass == 0 || phased || AreaRuleApplies(sigma[k][0], cell)
              ? 0.0
              : 0.5 * (sigma[(k + 1) % 4][0] + sigma[(k + 3) % 4][0]);
      sides[k] = ProfilesOfSide(
          gray, view, a, b, n, cell, cells,
          pass == 0 ? 1.0
                    : std::max(1.0, 2.0 * *std::max_element(sigma[k].begin(),
                                                            sigma[k].end())),
          along_sigma, others, phased);
    }
    if (pass == 0) {
      sigma = phased && demosaic
                  ? DemosaicedSidesBlur(sides, normals, *demosaic)
                  : SidesBlur(sides, phased);
    }
    std::array<Line2, 4> lines;
    for (int k = 0; k < 4; ++k) {
      if (!FitSide(gray, sides[k], normals[k], sigma[k], phased, lens,
                   &lines[k], &quality[k], phased ? demosaic : nullptr)) {
        return false;
      }
    }
    std::array<Eigen::Vector2d, 4> refined;
    for (int k = 0; k < 4; ++k) {
      // Corner k joins side k-1 (from corner k-1 to k) and side k.
      if (!Intersect(lines[(k + 3) % 4], lines[k], &refined[k])) return false;
      if (lens) refined[k] = DistortedPixel(*lens, refined[k]);
      if (!((refined[k] - det->corners[k]).norm() <= 3.0)) return false;
    }
    c = refined;
  }
  det->corners = c;
  det->sides = quality;
  // Centre: intersection of the diagonals.
  Line2 d0, d1;
  d0.n = Eigen::Vector2d(-(c[2] - c[0]).y(), (c[2] - c[0]).x()).normalized();
  d0.c = d0.n.dot(c[0]);
  d1.n = Eigen::Vector2d(-(c[3] - c[1]).y(), (c[3] - c[1]).x()).normalized();
  d1.c = d1.n.dot(c[1]);
  Eigen::Vector2d center;
  if (Intersect(d0, d1, &center)) det->center = center;
  return true;
}

namespace {

// Pass 0 of RefineCornersByEdges for a demosaiced image: the profiles of
// the four sides placed by `corners`, and their outward normals.
bool DemosaicedSides(const cv::Mat& gray, const cv::Mat& tag_image, int cells,
                     const std::array<Eigen::Vector2d, 4>& c,
                     const std::vector<NeighbourTag>& others,
                     std::array<SideProfiles, 4>* sides,
                     std::array<Eigen::Vector2d, 4>* normals) {
  const double start = 0.5 * (tag_image.cols - cells);
  PatternView view{&tag_image, ImageFromTemplate(c, start, cells).inverse()};
  const double cell = RefinableCell(c, cells);
  if (cell == 0) return false;
  for (int k = 0; k < 4; ++k) {
    const Eigen::Vector2d a = c[k], b = c[(k + 1) % 4];
    const Eigen::Vector2d n = OutwardNormal(c, k);
    (*normals)[k] = n;
    (*sides)[k] = ProfilesOfSide(gray, view, a, b, n, cell, cells, 1.0, 0.0,
                                 others, true);
  }
  return true;
}

// Sum of squared residual RMS of the sides' profiles that both fits take,
// with the linear demosaic (one blur per side pair) and with the blur per
// phase; their count.
void CompareDemosaicFits(const std::array<SideProfiles, 4>& sides,
                         const std::array<Eigen::Vector2d, 4>& normals,
                         const DemosaicKernels& kernels, double* model_ss,
                         double* phase_ss, int* profiles) {
  const std::array<PhaseSigmas, 4> model_sigma =
      DemosaicedSidesBlur(sides, normals, kernels);
  const std::array<PhaseSigmas, 4> phase_sigma = SidesBlur(sides, true);
  for (int k = 0; k < 4; ++k) {
    for (const EdgeProfile& p : sides[k].profiles) {
      const EdgeProfileFit m =
          FitDemosaicedProfile(p, normals[k], kernels, model_sigma[k][0]);
      const EdgeProfileFit f = FitEdgeProfile(p, phase_sigma[k]);
      if (!m.ok || !f.ok) continue;
      *model_ss += m.rms * m.rms;
      *phase_ss += f.rms * f.rms;
      ++*profiles;
    }
  }
}

}  // namespace

TagsDemosaicFit FitTagsDemosaic(const cv::Mat& gray,
                                const std::vector<const cv::Mat*>& tag_images,
                                int cells,
                                const std::vector<TagDetection>& dets,
                                int max_tags) {
  // The largest tags first: most pixels across their edges.
  std::vector<std::pair<double, size_t>> by_size;
  for (size_t i = 0; i < dets.size(); ++i) {
    double perimeter = 0;
    for (int k = 0; k < 4; ++k) {
      perimeter += (dets[i].corners[(k + 1) % 4] - dets[i].corners[k]).norm();
    }
    by_size.emplace_back(-perimeter, i);
  }
  std::sort(by_size.begin(), by_size.end());
  std::vector<std::array<SideProfiles, 4>> tags;
  std::vector<std::array<Eigen::Vector2d, 4>> normals;
  for (const auto& [size, i] : by_size) {
    if (static_cast<int>(tags.size()) == max_tags) break;
    std::vector<NeighbourTag> others;
    for (size_t j = 0; j < dets.size(); ++j) {
      if (j != i) others.push_back({dets[j].corners});
    }
    std::array<SideProfiles, 4> sides;
    std::array<Eigen::Vector2d, 4> n;
    if (DemosaicedSides(gray, *tag_images[i], cells, dets[i].corners, others,
                        &sides, &n)) {
      tags.push_back(std::move(sides));
      normals.push_back(n);
    }
  }
  TagsDemosaicFit out;
  if (tags.empty()) return out;
  std::vector<std::vector<DemosaicSide>> groups;
  for (size_t t = 0; t < tags.size(); ++t) {
    groups.emplace_back();
    for (int k = 0; k < 4; ++k) {
      groups.back().push_back({&tags[t][k].profiles, normals[t][k]});
    }
  }
  out.model = FitBilinearDemosaic(groups).model;
  double model_ss = 0, phase_ss = 0;
  for (size_t t = 0; t < tags.size(); ++t) {
    CompareDemosaicFits(tags[t], normals[t], out.model.Kernels(), &model_ss,
                        &phase_ss, &out.profiles);
  }
  if (out.profiles == 0) return out;
  out.model_rms = std::sqrt(model_ss / out.profiles);
  out.phase_rms = std::sqrt(phase_ss / out.profiles);
  out.better = out.profiles >= 16 && out.model_rms < out.phase_rms;
  return out;
}

bool RefineCornersBySubPix(const cv::Mat& gray, TagDetection* det) {
  double min_side = 1e9;
  for (int k = 0; k < 4; ++k) {
    min_side = std::min(min_side,
                        (det->corners[(k + 1) % 4] - det->corners[k]).norm());
  }
  const int half = static_cast<int>(std::min(0.6 * min_side / 8.0, 5.0));
  if (half < 2) return false;
  std::vector<cv::Point2f> pts;
  for (const auto& p : det->corners) {
    pts.emplace_back(static_cast<float>(p.x()), static_cast<float>(p.y()));
  }
  for (const auto& p : pts) {
    if (p.x < half + 1 || p.y < half + 1 || p.x > gray.cols - half - 2 ||
        p.y > gray.rows - half - 2) {
      return false;
    }
  }
  cv::cornerSubPix(
      gray, pts, cv::Size(half, half), cv::Size(-1, -1),
      cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 40,
                       0.001));
  for (int k = 0; k < 4; ++k) {
    const Eigen::Vector2d p(pts[k].x, pts[k].y);
    if ((p - det->corners[k]).norm() > 3.0) return false;
  }
  for (int k = 0; k < 4; ++k) det->corners[k] = {pts[k].x, pts[k].y};
  return true;
}

}  // namespace kincal
