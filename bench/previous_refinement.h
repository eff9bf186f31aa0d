#ifndef KINCAL_BENCH_PREVIOUS_REFINEMENT_H_
#define KINCAL_BENCH_PREVIOUS_REFINEMENT_H_

// The tag corner refinement before the pattern model (vision/edge_profile.h),
// kept only so that bench/corner_bench.cc can compare the two on the same
// images: per side the area rule over +-0.45 cell with the side's median
// levels half a cell either side, 0.3 px / 0.15 px checks, and the sides
// near another tag reverted to libapriltag's corners.

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <opencv2/core.hpp>
#include <vector>

#include "data/median.h"
#include "vision/apriltag_detector.h"
#include "vision/image_lines.h"

namespace kincal::previous {
namespace {
using image_lines::Bilinear;
using image_lines::FitLine;
using image_lines::Inside;
using image_lines::Intersect;
using image_lines::Line2;
using image_lines::SegmentsDistance;

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
bool AreaRuleRefinement(const cv::Mat& gray, TagDetection* det,
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
    const double i_dark = UpperMedian(dark);
    const double i_bright = UpperMedian(bright);
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
    const double mad = UpperMedian(res);
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

// As the detector's checks did: refined corners beyond 0.3 px of
// libapriltag's, or next to a side scattering over 0.15 px, fall back.
std::vector<TagDetection> Refine(const cv::Mat& gray,
                                 std::vector<TagDetection> dets) {
  for (TagDetection& t : dets) {
    t.corners = t.detector_corners;
    t.refined = {false, false, false, false};
    std::array<double, 4> side_rms{};
    if (!AreaRuleRefinement(gray, &t, &side_rms)) continue;
    for (int k = 0; k < 4; ++k) {
      const bool sides_ok =
          side_rms[k] <= 0.15 && side_rms[(k + 3) % 4] <= 0.15;
      const bool near = (t.corners[k] - t.detector_corners[k]).norm() <= 0.3;
      t.refined[k] = sides_ok && near;
      if (!t.refined[k]) t.corners[k] = t.detector_corners[k];
    }
  }
  RevertCornersNearOtherTags(&dets);
  return dets;
}

}  // namespace
}  // namespace kincal::previous

#endif  // KINCAL_BENCH_PREVIOUS_REFINEMENT_H_
