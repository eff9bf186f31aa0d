#ifndef KINCAL_VISION_IMAGE_LINES_H_
#define KINCAL_VISION_IMAGE_LINES_H_

// Small 2-D helpers of the tag corner refinement (vision/apriltag_detector.cc)
// and of the bench's copy of the earlier refinement (bench/corner_bench.cc):
// bilinear sampling, a robust centre, total-least-squares lines and segment
// distances. Pixel convention: OpenCV, (0, 0) = centre of the top-left pixel.

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <opencv2/core.hpp>
#include <vector>

namespace kincal::image_lines {

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

// A line n . x = c with |n| = 1.
struct Line2 {
  Eigen::Vector2d n;
  double c;
};

// Total least squares line through points.
inline Line2 FitLine(const std::vector<Eigen::Vector2d>& pts) {
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (const auto& p : pts) mean += p;
  mean /= static_cast<double>(pts.size());
  Eigen::Matrix2d cov = Eigen::Matrix2d::Zero();
  for (const auto& p : pts) cov += (p - mean) * (p - mean).transpose();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> es(cov);
  const Eigen::Vector2d n = es.eigenvectors().col(0);  // smallest eigenvalue
  return {n, n.dot(mean)};
}

inline bool Intersect(const Line2& a, const Line2& b, Eigen::Vector2d* p) {
  Eigen::Matrix2d A;
  A.row(0) = a.n.transpose();
  A.row(1) = b.n.transpose();
  const double det = A.determinant();
  if (std::abs(det) < 1e-6) return false;
  *p = A.inverse() * Eigen::Vector2d(a.c, b.c);
  return true;
}

inline double SegmentDistance(const Eigen::Vector2d& p,
                              const Eigen::Vector2d& a,
                              const Eigen::Vector2d& b) {
  const Eigen::Vector2d ab = b - a;
  const double t = std::clamp((p - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
  return (p - (a + t * ab)).norm();
}
inline double SegmentsDistance(const Eigen::Vector2d& a,
                               const Eigen::Vector2d& b,
                               const Eigen::Vector2d& c,
                               const Eigen::Vector2d& d) {
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

}  // namespace kincal::image_lines

#endif  // KINCAL_VISION_IMAGE_LINES_H_
