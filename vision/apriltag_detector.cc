#include "vision/apriltag_detector.h"

extern "C" {
#include <apriltag/apriltag.h>
}

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "data/error.h"
#include "vision/tag_family.h"

namespace kincal {

namespace {

// Bilinear intensity at (x, y) in OpenCV pixel convention; the caller keeps
// (x, y) at least one pixel inside the image.
inline double Bilinear(const cv::Mat& gray, double x, double y) {
  const int x0 = static_cast<int>(std::floor(x));
  const int y0 = static_cast<int>(std::floor(y));
  const double fx = x - x0;
  const double fy = y - y0;
  const uint8_t* r0 = gray.ptr<uint8_t>(y0) + x0;
  const uint8_t* r1 = gray.ptr<uint8_t>(y0 + 1) + x0;
  return (1 - fy) * ((1 - fx) * r0[0] + fx * r0[1]) +
         fy * ((1 - fx) * r1[0] + fx * r1[1]);
}

inline bool Inside(const cv::Mat& gray, const Eigen::Vector2d& p,
                   double margin) {
  return p.x() >= margin && p.y() >= margin &&
         p.x() <= gray.cols - 1 - margin && p.y() <= gray.rows - 1 - margin;
}

double Median(std::vector<double> v) {
  if (v.empty()) return 0;
  const size_t mid = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + mid, v.end());
  return v[mid];
}

// A line n . x = c with |n| = 1.
struct Line2 {
  Eigen::Vector2d n;
  double c;
};

// Total least squares line through points.
Line2 FitLine(const std::vector<Eigen::Vector2d>& pts) {
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (const auto& p : pts) mean += p;
  mean /= static_cast<double>(pts.size());
  Eigen::Matrix2d cov = Eigen::Matrix2d::Zero();
  for (const auto& p : pts) cov += (p - mean) * (p - mean).transpose();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> es(cov);
  const Eigen::Vector2d n = es.eigenvectors().col(0);  // smallest eigenvalue
  return {n, n.dot(mean)};
}

bool Intersect(const Line2& a, const Line2& b, Eigen::Vector2d* p) {
  Eigen::Matrix2d A;
  A.row(0) = a.n.transpose();
  A.row(1) = b.n.transpose();
  const double det = A.determinant();
  if (std::abs(det) < 1e-6) return false;
  *p = A.inverse() * Eigen::Vector2d(a.c, b.c);
  return true;
}

}  // namespace

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
};

AprilTagDetector::AprilTagDetector(const Options& options) : options_(options) {
  options_.Check();
  impl_ = std::make_unique<Impl>(options_);
}

AprilTagDetector::~AprilTagDetector() = default;

std::vector<TagDetection> AprilTagDetector::Detect(const cv::Mat& gray) {
  return DetectInRegion(gray, cv::Rect(0, 0, gray.cols, gray.rows));
}

std::vector<TagDetection> AprilTagDetector::DetectInRegion(const cv::Mat& gray,
                                                           cv::Rect roi) {
  if (gray.type() != CV_8UC1) {
    throw InputError("apriltag detector: expected an 8-bit gray image");
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
    switch (options_.refinement) {
      case CornerRefinement::kNone:
        break;
      case CornerRefinement::kCornerSubPix:
        if (RefineCornersBySubPix(gray, &t))
          t.refined = {true, true, true, true};
        break;
      case CornerRefinement::kEdges: {
        std::array<double, 4> side_rms{};
        if (RefineCornersByEdges(gray, &t, &side_rms)) {
          for (int k = 0; k < 4; ++k) {
            // Corner k joins side k-1 and side k.
            const bool sides_ok =
                side_rms[k] <= options_.max_edge_rms_px &&
                side_rms[(k + 3) % 4] <= options_.max_edge_rms_px;
            const bool near = (t.corners[k] - t.detector_corners[k]).norm() <=
                              options_.max_refine_shift_px;
            t.refined[k] = sides_ok && near;
            if (!t.refined[k]) t.corners[k] = t.detector_corners[k];
          }
        }
        break;
      }
    }
    out.push_back(t);
  }
  apriltag_detections_destroy(dets);
  if (options_.refinement == CornerRefinement::kEdges) {
    RevertCornersNearOtherTags(&out);
  }
  std::sort(out.begin(), out.end(),
            [](const TagDetection& a, const TagDetection& b) {
              if (a.id != b.id) return a.id < b.id;
              return a.center.x() < b.center.x();
            });
  return out;
}

namespace {
double SegmentDistance(const Eigen::Vector2d& p, const Eigen::Vector2d& a,
                       const Eigen::Vector2d& b) {
  const Eigen::Vector2d ab = b - a;
  const double t = std::clamp((p - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
  return (p - (a + t * ab)).norm();
}
double SegmentsDistance(const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                        const Eigen::Vector2d& c, const Eigen::Vector2d& d) {
  // Segments that cross have distance 0.
  auto cross = [](const Eigen::Vector2d& u, const Eigen::Vector2d& v) {
    return u.x() * v.y() - u.y() * v.x();
  };
  const double d1 = cross(b - a, c - a), d2 = cross(b - a, d - a);
  const double d3 = cross(d - c, a - c), d4 = cross(d - c, b - c);
  if (((d1 > 0) != (d2 > 0)) && ((d3 > 0) != (d4 > 0))) return 0.0;
  return std::min({SegmentDistance(a, c, d), SegmentDistance(b, c, d),
                   SegmentDistance(c, a, b), SegmentDistance(d, a, b)});
}
}  // namespace

// A side whose sampling reaches another tag's quad (its black square within
// one cell plus the window of the side) is measured on that tag's edges too:
// its corners fall back to libapriltag's.
void RevertCornersNearOtherTags(std::vector<TagDetection>* dets) {
  std::vector<std::array<bool, 4>> revert(dets->size(),
                                          {false, false, false, false});
  for (size_t i = 0; i < dets->size(); ++i) {
    const auto& c = (*dets)[i].detector_corners;
    for (int k = 0; k < 4; ++k) {
      const Eigen::Vector2d& a = c[k];
      const Eigen::Vector2d& b = c[(k + 1) % 4];
      const double cell = (b - a).norm() / 8.0;
      const double reach = 1.5 * cell + 1.0;
      for (size_t j = 0; j < dets->size(); ++j) {
        if (j == i) continue;
        const auto& o = (*dets)[j].detector_corners;
        for (int m = 0; m < 4 && !revert[i][k]; ++m) {
          if (SegmentsDistance(a, b, o[m], o[(m + 1) % 4]) < reach) {
            revert[i][k] = true;
          }
        }
      }
    }
  }
  for (size_t i = 0; i < dets->size(); ++i) {
    TagDetection& t = (*dets)[i];
    for (int k = 0; k < 4; ++k) {
      // Side k runs from corner k to corner k + 1.
      if (revert[i][k]) {
        for (int e : {k, (k + 1) % 4}) {
          t.corners[e] = t.detector_corners[e];
          t.refined[e] = false;
        }
      }
    }
  }
}

// Edge refinement. For each side (corner k to corner k+1) the outward normal
// n points from the black square into the white border. At sample points p
// along the middle 80 % of the side, the edge offset along n is found by the
// area rule on the intensity profile I(o) = I(p + o n), o in [-w, w]:
//   edge = w - integral_{-w}^{w} (I(o) - I_black) / (I_white - I_black) do,
// which is exact for any symmetric blur of a step (and for pixel
// integration), with I_black, I_white the side's median intensities half a
// cell inside and outside the edge. The window is re-centred once. A total
// least-squares line is fitted to the edge points (3 MAD outliers dropped),
// and adjacent lines intersect in the new corners.
bool RefineCornersByEdges(const cv::Mat& gray, TagDetection* det,
                          std::array<double, 4>* side_rms) {
  const auto& c = det->corners;
  std::array<double, 4> rms_of_side{};
  Eigen::Vector2d centroid = (c[0] + c[1] + c[2] + c[3]) / 4.0;
  std::array<Line2, 4> lines;
  for (int k = 0; k < 4; ++k) {
    const Eigen::Vector2d a = c[k];
    const Eigen::Vector2d b = c[(k + 1) % 4];
    const double len = (b - a).norm();
    if (len < 8.0) return false;
    const Eigen::Vector2d dir = (b - a) / len;
    Eigen::Vector2d n(-dir.y(), dir.x());
    if (n.dot((a + b) / 2 - centroid) < 0) n = -n;
    // Cells across the black square: 8 for tag36h11; the white border is one
    // cell wide. A conservative 8 keeps windows inside one cell for smaller
    // families too. The cell across this side is set by the sides that run
    // across it, which are shorter than this one when the tag is seen
    // obliquely: the shortest side bounds it.
    double shortest = len;
    for (int j = 0; j < 4; ++j) {
      shortest = std::min(shortest, (c[(j + 1) % 4] - c[j]).norm());
    }
    const double cell = shortest / 8.0;
    const double w = std::min(0.45 * cell, 3.0);
    if (w < 0.8) return false;
    const int samples = std::max(6, static_cast<int>(len * 0.8));
    const double margin = cell + 2.0;
    std::vector<double> dark, bright;
    std::vector<Eigen::Vector2d> base;
    for (int s = 0; s < samples; ++s) {
      const double t = 0.1 + 0.8 * (s + 0.5) / samples;
      const Eigen::Vector2d p = a + t * len * dir;
      if (!Inside(gray, p, margin)) continue;
      base.push_back(p);
      const Eigen::Vector2d p_dark = p - 0.5 * cell * n;
      const Eigen::Vector2d p_bright = p + 0.5 * cell * n;
      dark.push_back(Bilinear(gray, p_dark.x(), p_dark.y()));
      bright.push_back(Bilinear(gray, p_bright.x(), p_bright.y()));
    }
    if (base.size() < 4) return false;
    const double i_dark = Median(dark);
    const double i_bright = Median(bright);
    // Reversed-border families (tagStandard41h12) have the bright side
    // inside: the area rule only needs the two levels apart.
    if (std::abs(i_bright - i_dark) < 5.0) return false;
    const double inv = 1.0 / (i_bright - i_dark);
    const double h = 0.25;  // px between profile samples
    const int m = static_cast<int>(std::ceil(w / h));
    std::vector<Eigen::Vector2d> pts;
    std::vector<double> offsets;
    for (const Eigen::Vector2d& p : base) {
      double o0 = 0;
      bool ok = true;
      for (int iter = 0; iter < 2 && ok; ++iter) {
        // Trapezoid rule over o in [o0 - m h, o0 + m h].
        double area = 0;
        for (int j = -m; j <= m; ++j) {
          const Eigen::Vector2d q = p + (o0 + j * h) * n;
          const double v = (Bilinear(gray, q.x(), q.y()) - i_dark) * inv;
          area += (j == -m || j == m) ? 0.5 * v : v;
        }
        area *= h;
        const double o = o0 + m * h - area;
        if (std::abs(o) > w) ok = false;
        o0 = o;
      }
      if (!ok) continue;
      pts.push_back(p + o0 * n);
      offsets.push_back(o0);
    }
    if (pts.size() < 4) return false;
    Line2 line = FitLine(pts);
    // Drop points far from the line (another edge, a glint) and refit.
    std::vector<double> res;
    for (const auto& q : pts) res.push_back(std::abs(line.n.dot(q) - line.c));
    const double mad = Median(res);
    const double limit = std::max(3.0 * 1.4826 * mad, 0.05);
    std::vector<Eigen::Vector2d> kept;
    for (size_t i = 0; i < pts.size(); ++i) {
      if (res[i] <= limit) kept.push_back(pts[i]);
    }
    if (kept.size() < 4) return false;
    if (kept.size() < pts.size()) line = FitLine(kept);
    double ss = 0;
    for (const auto& q : kept) {
      const double r = line.n.dot(q) - line.c;
      ss += r * r;
    }
    rms_of_side[k] = std::sqrt(ss / kept.size());
    lines[k] = line;
  }
  std::array<Eigen::Vector2d, 4> refined;
  for (int k = 0; k < 4; ++k) {
    // Corner k joins side k-1 (from corner k-1 to k) and side k.
    if (!Intersect(lines[(k + 3) % 4], lines[k], &refined[k])) return false;
    if ((refined[k] - c[k]).norm() > 3.0) return false;
  }
  det->corners = refined;
  if (side_rms != nullptr) *side_rms = rms_of_side;
  // Centre: intersection of the diagonals.
  Line2 d0, d1;
  d0.n = Eigen::Vector2d(-(refined[2] - refined[0]).y(),
                         (refined[2] - refined[0]).x())
             .normalized();
  d0.c = d0.n.dot(refined[0]);
  d1.n = Eigen::Vector2d(-(refined[3] - refined[1]).y(),
                         (refined[3] - refined[1]).x())
             .normalized();
  d1.c = d1.n.dot(refined[1]);
  Eigen::Vector2d center;
  if (Intersect(d0, d1, &center)) det->center = center;
  return true;
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
