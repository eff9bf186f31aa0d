#include "synth/render.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <memory>
#include <mutex>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <sstream>

#include "data/atomic_file.h"
#include "data/error.h"
#include "data/provenance.h"
#include "data/yaml_util.h"
#include "vision/apriltag_detector.h"

namespace kincal {

namespace {

// Fibonacci lattice: N = 89 points (k + 1/2) / N, ((55 k mod N) + 1/2) / N.
// Every sample has its own x and its own y, so an edge at any angle moves
// the coverage in steps of 1/89 px.
constexpr int kNumSamples = 89;
constexpr int kLatticeStep = 55;

struct SampleLattice {
  std::array<double, kNumSamples> x, y;
  SampleLattice() {
    for (int k = 0; k < kNumSamples; ++k) {
      x[k] = (k + 0.5) / kNumSamples;
      y[k] = ((k * kLatticeStep) % kNumSamples + 0.5) / kNumSamples;
    }
  }
};
const SampleLattice& Lattice() {
  static const SampleLattice lattice;
  return lattice;
}

// The ray at (u, v) in [0, 1]^2 within a pixel, bilinear between the rays
// at its corners (top-left, top-right, bottom-left, bottom-right).
inline Eigen::Vector2d RayWithinPixel(const Eigen::Vector2d& r00,
                                      const Eigen::Vector2d& r10,
                                      const Eigen::Vector2d& r01,
                                      const Eigen::Vector2d& r11, double u,
                                      double v) {
  return (1 - v) * ((1 - u) * r00 + u * r10) + v * ((1 - u) * r01 + u * r11);
}

// One plane as the camera sees it.
struct PlaneInCam {
  Eigen::Matrix3d R;  // plane_from_cam
  Eigen::Vector3d t;
  double x0, y0, texel_w, texel_h;
  int cols, rows;
  const cv::Mat* texture;
  const PlaneLight* light;
  cv::Rect bbox;  // pixels that can see it (inclusive margin)
};

// The plane's light at its point (x, y) (mm).
inline double LightAt(const PlaneLight& l, double x, double y) {
  double g = l.gain;
  if (l.shadow_gain != 1.0) {
    const double d =
        l.shadow_normal.x() * x + l.shadow_normal.y() * y - l.shadow_offset_mm;
    const double s = l.penumbra_mm > 0
                         ? std::clamp(0.5 + d / l.penumbra_mm, 0.0, 1.0)
                         : (d > 0 ? 1.0 : 0.0);
    g *= 1.0 + (l.shadow_gain - 1.0) * s;
  }
  return g;
}

// Where the normalized ray (x, y, 1) meets the plane, in its (x, y) mm.
inline Eigen::Vector2d HitOnPlane(const PlaneInCam& pl, double x, double y) {
  const Eigen::Vector3d q = pl.R * Eigen::Vector3d(x, y, 1.0);
  const double lambda = -pl.t.z() / q.z();
  return Eigen::Vector2d(lambda * q.x() + pl.t.x(), lambda * q.y() + pl.t.y());
}

constexpr int64_t kBackground = -1;

// Nearest hit along normalized ray (x, y, 1): label (plane << 32 | texel)
// or kBackground.
inline int64_t Trace(const std::vector<PlaneInCam>& planes,
                     const std::vector<int>& candidates, double x, double y) {
  int64_t label = kBackground;
  double best = std::numeric_limits<double>::infinity();
  for (int p : candidates) {
    const PlaneInCam& pl = planes[p];
    const Eigen::Vector3d q = pl.R * Eigen::Vector3d(x, y, 1.0);
    if (q.z() <= 1e-12) continue;
    const double lambda = -pl.t.z() / q.z();
    if (lambda <= 0) continue;
    const double px = lambda * q.x() + pl.t.x();
    const double py = lambda * q.y() + pl.t.y();
    const double cu = (px - pl.x0) / pl.texel_w;
    const double cv = (py - pl.y0) / pl.texel_h;
    if (!(cu >= 0 && cv >= 0 && cu < pl.cols && cv < pl.rows)) continue;
    // Nearest wins; within a relative 1e-9 the later plane wins.
    if (lambda <= best * (1 + 1e-9)) {
      best = std::min(best, lambda);
      label = (static_cast<int64_t>(p) << 32) |
              (static_cast<int64_t>(cv) * pl.cols + static_cast<int64_t>(cu));
    }
  }
  return label;
}

inline double Radiance(const std::vector<PlaneInCam>& planes, int64_t label,
                       const RenderOptions& o) {
  if (label == kBackground) return o.background;
  const PlaneInCam& pl = planes[label >> 32];
  const int texel = static_cast<int>(label & 0xffffffff);
  const double v =
      pl.texture
          ->data[(texel / pl.cols) * pl.texture->step[0] + texel % pl.cols];
  return o.black + (o.white - o.black) * v / 255.0;
}

// Radiance of the label seen along ray (x, y), lit by its plane's light.
inline double LitRadiance(const std::vector<PlaneInCam>& planes, int64_t label,
                          double x, double y, const RenderOptions& o) {
  const double r = Radiance(planes, label, o);
  if (label == kBackground) return r;
  const PlaneInCam& pl = planes[label >> 32];
  if (pl.light->Uniform()) return r;
  const Eigen::Vector2d h = HitOnPlane(pl, x, y);
  return r * LightAt(*pl.light, h.x(), h.y());
}

// Distance from p to segment ab.
inline double SegmentDistance(const Eigen::Vector2d& p,
                              const Eigen::Vector2d& a,
                              const Eigen::Vector2d& b, double* s) {
  const Eigen::Vector2d ab = b - a;
  const double len2 = ab.squaredNorm();
  double t = len2 > 0 ? (p - a).dot(ab) / len2 : 0.0;
  t = std::clamp(t, 0.0, 1.0);
  *s = t;
  return (p - (a + t * ab)).norm();
}

// The plane `p` as `camera` sees it, with the pixel box that can see it;
// nothing when the plane is seen from behind or falls outside the image.
std::optional<PlaneInCam> PlaneInCamera(const TexturedPlane& p,
                                        const Camera& camera, int width,
                                        int height) {
  if (p.texture.empty() || p.texture.type() != CV_8UC1) {
    throw InputError("render: a plane's texture is not an 8-bit gray image");
  }
  const CameraIntrinsics& K = camera.intrinsics;
  const Rigid3 cam_from_plane = camera.cam_from_rig * p.rig_from_plane;
  const Rigid3 plane_from_cam = cam_from_plane.Inverse();
  if (plane_from_cam.t.z() >= 0) return std::nullopt;  // seen from behind
  PlaneInCam pc;
  pc.R = plane_from_cam.R;
  pc.t = plane_from_cam.t;
  pc.x0 = p.top_left_mm.x();
  pc.y0 = p.top_left_mm.y();
  pc.cols = p.texture.cols;
  pc.rows = p.texture.rows;
  pc.texel_w = p.size_mm.x() / pc.cols;
  pc.texel_h = p.size_mm.y() / pc.rows;
  pc.texture = &p.texture;
  pc.light = &p.light;
  // Bounding box from points along the border (distortion bends edges).
  double u0 = 1e18, v0 = 1e18, u1 = -1e18, v1 = -1e18;
  bool behind = false;
  const int n = 16;
  for (int side = 0; side < 4 && !behind; ++side) {
    for (int k = 0; k <= n; ++k) {
      const double s = static_cast<double>(k) / n;
      double x = 0, y = 0;
      switch (side) {
        case 0:
          x = s;
          y = 0;
          break;
        case 1:
          x = 1;
          y = s;
          break;
        case 2:
          x = 1 - s;
          y = 1;
          break;
        default:
          x = 0;
          y = 1 - s;
          break;
      }
      const Eigen::Vector3d p_in_plane(pc.x0 + x * p.size_mm.x(),
                                       pc.y0 + y * p.size_mm.y(), 0.0);
      const Eigen::Vector3d p_in_cam = cam_from_plane * p_in_plane;
      if (p_in_cam.z() <= 1e-6) {
        behind = true;
        break;
      }
      const Eigen::Vector2d uv = Project(K, p_in_cam);
      u0 = std::min(u0, uv.x());
      v0 = std::min(v0, uv.y());
      u1 = std::max(u1, uv.x());
      v1 = std::max(v1, uv.y());
    }
  }
  if (behind) {
    pc.bbox = cv::Rect(0, 0, width, height);
    return pc;
  }
  const double margin = 3.0;
  const double lo_u = std::max(u0 - margin, -1.0);
  const double lo_v = std::max(v0 - margin, -1.0);
  const double hi_u = std::min(u1 + margin, width + 1.0);
  const double hi_v = std::min(v1 + margin, height + 1.0);
  if (lo_u > hi_u || lo_v > hi_v) return std::nullopt;
  pc.bbox = cv::Rect(cv::Point(static_cast<int>(std::floor(lo_u)),
                               static_cast<int>(std::floor(lo_v))),
                     cv::Point(static_cast<int>(std::ceil(hi_u)) + 1,
                               static_cast<int>(std::ceil(hi_v)) + 1));
  return pc;
}

// The label (plane and texel, or background) at every pixel corner: corner
// (i, j) is pixel position (i - .5, j - .5), its ray in `corner_rays`.
std::vector<int64_t> LabelCorners(const std::vector<PlaneInCam>& in_cam,
                                  const std::vector<Eigen::Vector2d>& rays,
                                  int width, int height) {
  const int gw = width + 1;
  std::vector<int64_t> labels(static_cast<size_t>(gw) * (height + 1),
                              kBackground);
  cv::parallel_for_(cv::Range(0, height + 1), [&](const cv::Range& range) {
    std::vector<int> candidates;
    for (int j = range.start; j < range.end; ++j) {
      for (int i = 0; i <= width; ++i) {
        candidates.clear();
        for (size_t p = 0; p < in_cam.size(); ++p) {
          const cv::Rect& b = in_cam[p].bbox;
          if (i >= b.x && i <= b.x + b.width && j >= b.y &&
              j <= b.y + b.height) {
            candidates.push_back(static_cast<int>(p));
          }
        }
        if (candidates.empty()) continue;
        const Eigen::Vector2d& r = rays[static_cast<size_t>(j) * gw + i];
        labels[static_cast<size_t>(j) * gw + i] =
            Trace(in_cam, candidates, r.x(), r.y());
      }
    }
  });
  return labels;
}

// Pixel radiance: a pixel whose four corners agree takes that label's
// value, the others the mean over the sample lattice.
cv::Mat ShadePixels(const std::vector<PlaneInCam>& in_cam,
                    const std::vector<int64_t>& labels,
                    const std::vector<Eigen::Vector2d>& rays, int width,
                    int height, const RenderOptions& options) {
  const int gw = width + 1;
  cv::Mat radiance(height, width, CV_64FC1);
  const SampleLattice& lat = Lattice();
  cv::parallel_for_(cv::Range(0, height), [&](const cv::Range& range) {
    std::vector<int> candidates;
    for (int y = range.start; y < range.end; ++y) {
      double* row = radiance.ptr<double>(y);
      for (int x = 0; x < width; ++x) {
        const size_t c00 = static_cast<size_t>(y) * gw + x;
        const int64_t l00 = labels[c00], l10 = labels[c00 + 1];
        const int64_t l01 = labels[c00 + gw], l11 = labels[c00 + gw + 1];
        if (l00 == l10 && l00 == l01 && l00 == l11) {
          // Lit as at the pixel's centre.
          const Eigen::Vector2d c =
              0.25 *
              (rays[c00] + rays[c00 + 1] + rays[c00 + gw] + rays[c00 + gw + 1]);
          row[x] = LitRadiance(in_cam, l00, c.x(), c.y(), options);
          continue;
        }
        candidates.clear();
        for (size_t p = 0; p < in_cam.size(); ++p) {
          const cv::Rect& b = in_cam[p].bbox;
          if (x + 1 >= b.x && x <= b.x + b.width && y + 1 >= b.y &&
              y <= b.y + b.height) {
            candidates.push_back(static_cast<int>(p));
          }
        }
        const Eigen::Vector2d& r00 = rays[c00];
        const Eigen::Vector2d& r10 = rays[c00 + 1];
        const Eigen::Vector2d& r01 = rays[c00 + gw];
        const Eigen::Vector2d& r11 = rays[c00 + gw + 1];
        double sum = 0;
        for (int k = 0; k < kNumSamples; ++k) {
          const double sx = lat.x[k], sy = lat.y[k];
          const Eigen::Vector2d r = RayWithinPixel(r00, r10, r01, r11, sx, sy);
          sum += LitRadiance(in_cam, Trace(in_cam, candidates, r.x(), r.y()),
                             r.x(), r.y(), options);
        }
        row[x] = sum / kNumSamples;
      }
    }
  });
  return radiance;
}

// Paints a needle over `radiance`: the coverage of a thick polyline along
// the projected cylinder axis, blended to the needle's gray.
void DrawNeedle(const Needle& needle, const Camera& camera, cv::Mat* radiance) {
  const CameraIntrinsics& K = camera.intrinsics;
  const int width = radiance->cols, height = radiance->rows;
  const SampleLattice& lat = Lattice();
  const Eigen::Vector3d a = camera.cam_from_rig * needle.base_in_rig;
  const Eigen::Vector3d b = camera.cam_from_rig * needle.tip_in_rig;
  const int m = 48;
  std::vector<Eigen::Vector2d> pts;
  std::vector<double> half_width;
  for (int k = 0; k <= m; ++k) {
    const Eigen::Vector3d p = a + (b - a) * (static_cast<double>(k) / m);
    if (p.z() <= 1e-3) continue;
    pts.push_back(Project(K, p));
    half_width.push_back(needle.radius_mm * K.fx / p.z());
  }
  cv::Mat coverage(height, width, CV_64FC1, cv::Scalar(0));
  for (size_t k = 0; k + 1 < pts.size(); ++k) {
    const double w = std::max(half_width[k], half_width[k + 1]);
    const int x0 = std::max(
        0, static_cast<int>(
               std::floor(std::min(pts[k].x(), pts[k + 1].x()) - w - 1)));
    const int y0 = std::max(
        0, static_cast<int>(
               std::floor(std::min(pts[k].y(), pts[k + 1].y()) - w - 1)));
    const int x1 =
        std::min(width - 1, static_cast<int>(std::ceil(
                                std::max(pts[k].x(), pts[k + 1].x()) + w + 1)));
    const int y1 = std::min(height - 1,
                            static_cast<int>(std::ceil(
                                std::max(pts[k].y(), pts[k + 1].y()) + w + 1)));
    for (int y = y0; y <= y1; ++y) {
      for (int x = x0; x <= x1; ++x) {
        int inside = 0;
        for (int s = 0; s < kNumSamples; ++s) {
          const Eigen::Vector2d p(x - 0.5 + lat.x[s], y - 0.5 + lat.y[s]);
          double t;
          const double d = SegmentDistance(p, pts[k], pts[k + 1], &t);
          const double hw = (1 - t) * half_width[k] + t * half_width[k + 1];
          if (d < hw) ++inside;
        }
        double& c = coverage.at<double>(y, x);
        c = std::max(c, static_cast<double>(inside) / kNumSamples);
      }
    }
  }
  *radiance = radiance->mul(1.0 - coverage) + coverage * needle.gray;
}

// Disk of radius `radius_px`, anti-aliased by 8x8 supersampling per kernel
// cell, normalised to sum 1.
// OpenCV's VNG demosaic shifts its output up by two rows in versions
// before 4.12 (opencv/opencv#5089, #27225): the rows a test mosaic's
// horizontal edge moves by against the bilinear demosaic (0 once fixed).
int VngRowShift() {
  static const int shift = [] {
    cv::Mat raw(32, 16, CV_8UC1, cv::Scalar(40));
    raw.rowRange(16, 32).setTo(220);
    cv::Mat bilinear, bgr, vng;
    cv::cvtColor(raw, bilinear, cv::COLOR_BayerBG2GRAY);
    cv::cvtColor(raw, bgr, cv::COLOR_BayerBG2BGR_VNG);
    cv::cvtColor(bgr, vng, cv::COLOR_BGR2GRAY);
    const auto edge_row = [](const cv::Mat& g) {
      int y = 4;
      while (y < 28 && g.at<uint8_t>(y, 8) < 130) ++y;
      return y;
    };
    return edge_row(vng) - edge_row(bilinear);
  }();
  return shift;
}

// VNG's gray image with its rows where the scene has them.
cv::Mat VngToGray(const cv::Mat& mosaic) {
  cv::Mat bgr, gray;
  cv::cvtColor(mosaic, bgr, cv::COLOR_BayerBG2BGR_VNG);
  cv::cvtColor(bgr, gray, cv::COLOR_BGR2GRAY);
  const int s = VngRowShift();
  if (s == 0) return gray;
  // out(y) = gray(y + s), the rows beyond the image repeated.
  cv::Mat out;
  const cv::Mat m = (cv::Mat_<double>(2, 3) << 1, 0, 0, 0, 1, s);
  cv::warpAffine(gray, out, m, gray.size(),
                 cv::INTER_NEAREST | cv::WARP_INVERSE_MAP,
                 cv::BORDER_REPLICATE);
  return out;
}

cv::Mat DefocusKernel(double radius_px) {
  const double R = radius_px;
  const int h = static_cast<int>(std::ceil(R));
  cv::Mat k(2 * h + 1, 2 * h + 1, CV_64FC1, cv::Scalar(0));
  for (int y = -h; y <= h; ++y) {
    for (int x = -h; x <= h; ++x) {
      int in = 0;
      for (int sy = 0; sy < 8; ++sy) {
        for (int sx = 0; sx < 8; ++sx) {
          const double px = x - 0.5 + (sx + 0.5) / 8;
          const double py = y - 0.5 + (sy + 0.5) / 8;
          in += px * px + py * py <= R * R ? 1 : 0;
        }
      }
      k.at<double>(y + h, x + h) = in;
    }
  }
  k /= cv::sum(k)[0];
  return k;
}

// A line segment of length `length_px` at `angle_deg` (box profile), drawn
// with 32 bilinear samples per px, normalised to sum 1.
cv::Mat MotionKernel(double length_px, double angle_deg) {
  const double L = length_px;
  const double a = angle_deg * M_PI / 180.0;
  const int h = static_cast<int>(std::ceil(L / 2)) + 1;
  cv::Mat k(2 * h + 1, 2 * h + 1, CV_64FC1, cv::Scalar(0));
  const int n = std::max(2, static_cast<int>(32 * L));
  for (int i = 0; i < n; ++i) {
    const double t = (i + 0.5) / n - 0.5;
    const double x = t * L * std::cos(a) + h, y = t * L * std::sin(a) + h;
    const int x0 = static_cast<int>(std::floor(x)),
              y0 = static_cast<int>(std::floor(y));
    const double fx = x - x0, fy = y - y0;
    k.at<double>(y0, x0) += (1 - fx) * (1 - fy);
    k.at<double>(y0, x0 + 1) += fx * (1 - fy);
    k.at<double>(y0 + 1, x0) += (1 - fx) * fy;
    k.at<double>(y0 + 1, x0 + 1) += fx * fy;
  }
  k /= cv::sum(k)[0];
  return k;
}

// Exposure: the image's gain jitter, vignetting and light gradient.
void Expose(const RenderOptions& options, std::mt19937_64* rng,
            cv::Mat* radiance) {
  const int width = radiance->cols, height = radiance->rows;
  double gain = 1.0;
  if (options.exposure_jitter > 0) {
    std::normal_distribution<double> g(1.0, options.exposure_jitter);
    gain = std::clamp(g(*rng), 0.5, 1.5);
  }
  *radiance *= gain;
  if (options.vignetting > 0 || options.light_gradient != 0) {
    const double cx = 0.5 * (width - 1), cy = 0.5 * (height - 1);
    const double r2max = cx * cx + cy * cy;
    for (int y = 0; y < height; ++y) {
      double* row = radiance->ptr<double>(y);
      for (int x = 0; x < width; ++x) {
        const double r2 = (x - cx) * (x - cx) + (y - cy) * (y - cy);
        row[x] *= (1.0 - options.vignetting * r2 / r2max) *
                  (1.0 + options.light_gradient *
                             (static_cast<double>(x) / width - 0.5));
      }
    }
  }
}

// The optics (defocus, motion, Gaussian blur) on an image `scale` times
// finer than the camera's pixels.
void ApplyOptics(const RenderOptions& options, double scale,
                 cv::Mat* radiance) {
  if (options.defocus_px > 0) {
    cv::filter2D(*radiance, *radiance, -1,
                 DefocusKernel(scale * options.defocus_px), cv::Point(-1, -1),
                 0, cv::BORDER_REPLICATE);
  }
  if (options.motion_px > 0) {
    cv::filter2D(
        *radiance, *radiance, -1,
        MotionKernel(scale * options.motion_px, options.motion_angle_deg),
        cv::Point(-1, -1), 0, cv::BORDER_REPLICATE);
  }
  if (options.blur_sigma_px > 0) {
    const double sigma = scale * options.blur_sigma_px;
    cv::GaussianBlur(*radiance, *radiance, cv::Size(0, 0), sigma, sigma,
                     cv::BORDER_REPLICATE);
  }
}

bool HasOptics(const RenderOptions& options) {
  return options.defocus_px > 0 || options.motion_px > 0 ||
         options.blur_sigma_px > 0;
}

// The sensor: the Bayer mosaic, noise, 8-bit rounding, the demosaic and
// JPEG, on the light the pixels integrated.
cv::Mat Record(cv::Mat radiance, const RenderOptions& options,
               std::mt19937_64* rng) {
  const int width = radiance.cols, height = radiance.rows;
  if (options.bayer) {
    // RGGB photosites: R at (even x, even y), B at (odd x, odd y).
    for (int y = 0; y < height; ++y) {
      double* row = radiance.ptr<double>(y);
      for (int x = 0; x < width; ++x) {
        const int channel = (x % 2 == 0 && y % 2 == 0)   ? 0
                            : (x % 2 == 1 && y % 2 == 1) ? 2
                                                         : 1;
        row[x] *= options.bayer_gains[channel];
      }
    }
  }
  if (options.noise_sigma > 0) {
    std::normal_distribution<double> noise(0.0, options.noise_sigma);
    for (int y = 0; y < height; ++y) {
      double* row = radiance.ptr<double>(y);
      for (int x = 0; x < width; ++x) row[x] += noise(*rng);
    }
  }
  cv::Mat out;
  radiance.convertTo(out, CV_8UC1);  // rounds and saturates
  if (options.bayer && !options.bayer_raw) {
    // OpenCV names a mosaic by its second row's pattern: RGGB is "BG".
    cv::Mat gray, bgr;
    switch (options.demosaic) {
      case RenderOptions::Demosaic::kBilinear:
        cv::cvtColor(out, gray, cv::COLOR_BayerBG2GRAY);
        break;
      case RenderOptions::Demosaic::kVng:
        gray = VngToGray(out);
        break;
      case RenderOptions::Demosaic::kEdgeAware:
        cv::cvtColor(out, bgr, cv::COLOR_BayerBG2BGR_EA);
        cv::cvtColor(bgr, gray, cv::COLOR_BGR2GRAY);
        break;
    }
    out = gray;
  }
  if (options.jpeg_quality > 0) {
    std::vector<uchar> buf;
    cv::imencode(".jpg", out, buf,
                 {cv::IMWRITE_JPEG_QUALITY, options.jpeg_quality});
    out = cv::imdecode(buf, cv::IMREAD_GRAYSCALE);
  }
  return out;
}

}  // namespace

void RenderOptions::Check() const {
  auto in_range = [](const char* what, double v, double lo, double hi) {
    if (!(v >= lo && v <= hi)) {
      std::ostringstream os;
      os << "render option " << what << " = " << v << " (expected " << lo
         << ".." << hi << ")";
      throw InputError(os.str());
    }
  };
  in_range("background", background, 0, 255);
  in_range("black", black, 0, 255);
  in_range("white", white, 0, 255);
  in_range("blur_sigma_px", blur_sigma_px, 0, 20);
  in_range("noise_sigma", noise_sigma, 0, 100);
  in_range("exposure_jitter", exposure_jitter, 0, 0.5);
  in_range("needle_radius_mm", needle_radius_mm, 0, 100);
  in_range("needle_gray", needle_gray, 0, 255);
  in_range("defocus_px", defocus_px, 0, 20);
  in_range("motion_px", motion_px, 0, 50);
  in_range("motion_angle_deg", motion_angle_deg, -360, 360);
  in_range("vignetting", vignetting, 0, 0.9);
  in_range("light_gradient", light_gradient, -1, 1);
  in_range("jpeg_quality", jpeg_quality, 0, 100);
  in_range("ambient", ambient, 0, 1);
  in_range("shadow_gain", shadow_gain, 0, 1);
  in_range("shadow_offset", shadow_offset, -1, 1);
  for (double g : tag_gain) in_range("tag_gain", g, 0, 10);
  for (double g : bayer_gains) in_range("bayer_gains", g, 0.05, 2);
  if (bayer_raw && !bayer) {
    throw InputError("render option bayer_raw needs bayer (a colour sensor)");
  }
  if (!light_in_rig.allFinite()) {
    throw InputError("render option light_in_rig is not finite");
  }
}

TexturedPlane TagPlane(const std::string& family, int id, double size_mm,
                       const Rigid3& rig_from_tag) {
  TexturedPlane plane;
  plane.texture = TagImage(family, id);
  const double cell = size_mm / TagBlackSquareCells(family);
  const double half = 0.5 * cell * plane.texture.cols;
  plane.rig_from_plane = rig_from_tag;
  plane.top_left_mm = Eigen::Vector2d(-half, -half);
  plane.size_mm = Eigen::Vector2d(2 * half, 2 * half);
  return plane;
}

std::vector<TexturedPlane> TargetPlanes(const Target& target,
                                        const Rigid3& rig_from_tool) {
  std::vector<TexturedPlane> planes;
  for (const auto& tag : target.tags) {
    planes.push_back(TagPlane(target.family, tag.id, tag.size_mm,
                              rig_from_tool * tag.tool_from_tag));
  }
  return planes;
}

struct ViewRenderer::FineView {
  std::once_flag once;
  std::unique_ptr<ViewRenderer> view;
};

ViewRenderer::ViewRenderer(const Camera& camera)
    : camera_(camera),
      width_(camera.intrinsics.width),
      height_(camera.intrinsics.height),
      fine_(std::make_shared<FineView>()) {
  if (width_ <= 0 || height_ <= 0) {
    throw InputError("render: camera '" + camera.intrinsics.name +
                     "' has no image size");
  }
  corner_rays_.resize(static_cast<size_t>(width_ + 1) * (height_ + 1));
  const bool distorted = std::any_of(camera.intrinsics.distortion.begin(),
                                     camera.intrinsics.distortion.end(),
                                     [](double d) { return d != 0.0; });
  const CameraIntrinsics& K = camera.intrinsics;
  cv::parallel_for_(cv::Range(0, height_ + 1), [&](const cv::Range& range) {
    for (int j = range.start; j < range.end; ++j) {
      for (int i = 0; i <= width_; ++i) {
        const Eigen::Vector2d px(i - 0.5, j - 0.5);
        corner_rays_[static_cast<size_t>(j) * (width_ + 1) + i] =
            distorted ? UndistortPixel(K, px)
                      : Eigen::Vector2d((px.x() - K.cx) / K.fx,
                                        (px.y() - K.cy) / K.fy);
      }
    }
  });
}

ViewRenderer::ViewRenderer(const Camera& fine, const ViewRenderer& coarse)
    : camera_(fine),
      width_(fine.intrinsics.width),
      height_(fine.intrinsics.height),
      fine_(std::make_shared<FineView>()) {
  // The fine corners' rays interpolated between the coarse corners', as the
  // coarse renderer reads its sub-pixel samples (RayWithinPixel).
  const int f = width_ / coarse.width_;
  const size_t gw = coarse.width_ + 1;
  corner_rays_.resize(static_cast<size_t>(width_ + 1) * (height_ + 1));
  cv::parallel_for_(cv::Range(0, height_ + 1), [&](const cv::Range& range) {
    for (int j = range.start; j < range.end; ++j) {
      const int cj = std::min(j / f, coarse.height_ - 1);
      const double v = static_cast<double>(j - cj * f) / f;
      for (int i = 0; i <= width_; ++i) {
        const int ci = std::min(i / f, coarse.width_ - 1);
        const double u = static_cast<double>(i - ci * f) / f;
        const auto& r = coarse.corner_rays_;
        const size_t c00 = cj * gw + ci;
        corner_rays_[static_cast<size_t>(j) * (width_ + 1) + i] =
            RayWithinPixel(r[c00], r[c00 + 1], r[c00 + gw], r[c00 + gw + 1], u,
                           v);
      }
    }
  });
}

const ViewRenderer& ViewRenderer::Fine() const {
  std::call_once(fine_->once, [this] {
    // The same rays kFineOptics times finer: a pixel corner u - 0.5 of the
    // fine grid is at (u - 0.5) / kFineOptics - 0.5 in this camera's pixels.
    Camera fine = camera_;
    CameraIntrinsics& K = fine.intrinsics;
    const double s = kFineOptics;
    K.width *= kFineOptics;
    K.height *= kFineOptics;
    K.fx *= s;
    K.fy *= s;
    K.cx = (K.cx + 0.5) * s - 0.5;
    K.cy = (K.cy + 0.5) * s - 0.5;
    fine_->view.reset(new ViewRenderer(fine, *this));
  });
  return *fine_->view;
}

cv::Mat ViewRenderer::Radiance(const std::vector<TexturedPlane>& planes,
                               const std::vector<Needle>& needles,
                               const RenderOptions& options) const {
  std::vector<PlaneInCam> in_cam;
  for (const TexturedPlane& p : planes) {
    std::optional<PlaneInCam> pc = PlaneInCamera(p, camera_, width_, height_);
    if (pc) in_cam.push_back(*pc);
  }
  const std::vector<int64_t> labels =
      LabelCorners(in_cam, corner_rays_, width_, height_);
  cv::Mat radiance =
      ShadePixels(in_cam, labels, corner_rays_, width_, height_, options);
  for (const Needle& needle : needles) DrawNeedle(needle, camera_, &radiance);
  return radiance;
}

cv::Mat ViewRenderer::Render(const std::vector<TexturedPlane>& planes,
                             const std::vector<Needle>& needles,
                             const RenderOptions& options,
                             std::mt19937_64* rng) const {
  options.Check();
  cv::Mat radiance;
  if (options.fine_optics && HasOptics(options)) {
    // Blurred before the pixels integrate it.
    cv::Mat fine = Fine().Radiance(planes, needles, options);
    ApplyOptics(options, kFineOptics, &fine);
    cv::resize(fine, radiance, cv::Size(width_, height_), 0, 0, cv::INTER_AREA);
    Expose(options, rng, &radiance);
  } else {
    radiance = Radiance(planes, needles, options);
    Expose(options, rng, &radiance);
    ApplyOptics(options, 1.0, &radiance);
  }
  return Record(radiance, options, rng);
}

std::vector<TagTruth> ProjectTargetCorners(const Camera& camera,
                                           const Target& target,
                                           const Rigid3& rig_from_tool) {
  std::vector<TagTruth> out;
  const CameraIntrinsics& K = camera.intrinsics;
  for (const auto& tag : target.tags) {
    TagTruth t;
    t.id = tag.id;
    const Rigid3 cam_from_tag =
        camera.cam_from_rig * rig_from_tool * tag.tool_from_tag;
    const bool front = cam_from_tag.Inverse().t.z() < 0;
    bool inside = true;
    for (int k = 0; k < 4; ++k) {
      const Eigen::Vector3d p = cam_from_tag * TagCornerInTag(k, tag.size_mm);
      t.corners[k] = Project(K, p);
      const Eigen::Vector2d& c = t.corners[k];
      inside = inside && p.z() > 0 && c.allFinite() && c.x() >= 3 &&
               c.y() >= 3 && c.x() <= K.width - 4 && c.y() <= K.height - 4;
    }
    t.visible = front && inside;
    out.push_back(t);
  }
  return out;
}

void LightTags(const RenderOptions& o, const Target& target,
               std::vector<TexturedPlane>* planes) {
  const double light_norm = o.light_in_rig.norm();
  for (size_t i = 0; i < planes->size() && i < target.tags.size(); ++i) {
    TexturedPlane& p = (*planes)[i];
    if (light_norm > 0) {
      // The printed face looks along -z: lit when the light travels along
      // +z of the tag.
      const double cos = std::max(
          0.0, p.rig_from_plane.R.col(2).dot(o.light_in_rig / light_norm));
      p.light.gain = o.ambient + (1.0 - o.ambient) * cos;
    }
    if (i < o.tag_gain.size()) p.light.gain *= o.tag_gain[i];
    if (static_cast<int>(i) == o.shadow_tag) {
      const double a = o.shadow_angle_deg * M_PI / 180;
      p.light.shadow_gain = o.shadow_gain;
      p.light.shadow_normal = Eigen::Vector2d(std::cos(a), std::sin(a));
      p.light.shadow_offset_mm = o.shadow_offset * target.tags[i].size_mm;
    }
  }
}

StereoRenderer::StereoRenderer(const Rig& rig, const Target& target,
                               const RenderOptions& options)
    : rig_(rig), target_(target), options_(options) {
  options_.Check();
  for (const Camera& cam : rig_.cameras) views_.emplace_back(cam);
}

StereoFrameTruth StereoRenderer::Render(const Rigid3& rig_from_tool,
                                        std::mt19937_64* rng) const {
  StereoFrameTruth frame;
  frame.rig_from_tool = rig_from_tool;
  frame.tip_in_rig = rig_from_tool * target_.tip_in_tool;
  std::vector<TexturedPlane> planes = TargetPlanes(target_, rig_from_tool);
  LightTags(options_, target_, &planes);
  std::vector<Needle> needles;
  if (options_.draw_needle) {
    Needle n;
    n.base_in_rig = rig_from_tool * options_.needle_base_in_tool;
    n.tip_in_rig = frame.tip_in_rig;
    n.radius_mm = options_.needle_radius_mm;
    n.gray = options_.needle_gray;
    needles.push_back(n);
  }
  for (size_t c = 0; c < views_.size(); ++c) {
    ViewTruth view;
    view.image = views_[c].Render(planes, needles, options_, rng);
    view.tags = ProjectTargetCorners(rig_.cameras[c], target_, rig_from_tool);
    view.tip_px = Project(rig_.cameras[c].intrinsics,
                          rig_.cameras[c].cam_from_rig * frame.tip_in_rig);
    frame.views.push_back(std::move(view));
  }
  return frame;
}

TruthTables::TruthTables(const std::string& header, uint64_t seed) {
  truth_ << header << "# seed " << seed
         << "; rig_from_tool (R row-major, t mm), tip in rig (mm)\n"
         << "frame,r00,r01,r02,r10,r11,r12,r20,r21,r22,tx,ty,tz,tip_x,tip_y,"
            "tip_z\n";
  corners_ << header
           << "# tag corners in px (OpenCV pixel centres, libapriltag order)\n"
           << "frame,camera,tag,corner,u,v,visible\n";
}

void TruthTables::Add(size_t frame_index, const StereoFrameTruth& frame,
                      const std::vector<std::string>& camera_labels) {
  for (size_t c = 0; c < frame.views.size(); ++c) {
    for (const TagTruth& t : frame.views[c].tags) {
      for (int k = 0; k < 4; ++k) {
        corners_ << frame_index << "," << camera_labels.at(c) << "," << t.id
                 << "," << k << "," << FormatDouble(t.corners[k].x()) << ","
                 << FormatDouble(t.corners[k].y()) << "," << (t.visible ? 1 : 0)
                 << "\n";
      }
    }
  }
  truth_ << frame_index;
  for (int i = 0; i < 9; ++i) {
    truth_ << "," << FormatDouble(frame.rig_from_tool.R(i / 3, i % 3));
  }
  for (int i = 0; i < 3; ++i) {
    truth_ << "," << FormatDouble(frame.rig_from_tool.t(i));
  }
  for (int i = 0; i < 3; ++i) {
    truth_ << "," << FormatDouble(frame.tip_in_rig(i));
  }
  truth_ << "\n";
}

namespace {
std::string CameraLabel(const Rig& rig, size_t c) {
  const std::string& name = rig.cameras[c].intrinsics.name;
  return name.empty() ? "cam" + std::to_string(c) : name;
}
}  // namespace

int RenderSession(const Rig& rig, const Target& target,
                  const std::vector<Rigid3>& rig_from_tool,
                  const RenderOptions& options, uint64_t seed,
                  const std::string& folder) {
  options.Check();
  if (rig.cameras.empty()) throw InputError("render: the rig has no camera");
  std::error_code ec;
  std::filesystem::create_directories(folder, ec);
  if (ec) {
    throw InputError(folder + ": cannot create the folder: " + ec.message());
  }
  StereoRenderer renderer(rig, target, options);
  std::mt19937_64 rng(seed);
  std::vector<std::string> labels;
  for (size_t c = 0; c < rig.cameras.size(); ++c) {
    labels.push_back(CameraLabel(rig, c));
  }
  TruthTables tables(
      "# written by " + ToolVersion() + ": " + CommandLine() + "\n", seed);
  for (size_t f = 0; f < rig_from_tool.size(); ++f) {
    const StereoFrameTruth frame = renderer.Render(rig_from_tool[f], &rng);
    char index[32];
    std::snprintf(index, sizeof(index), "%06zu", f);
    for (size_t c = 0; c < frame.views.size(); ++c) {
      std::vector<uchar> png;
      cv::imencode(".png", frame.views[c].image, png);
      WriteFileAtomic(folder + "/" + labels[c] + "_" + index + ".png",
                      std::string(png.begin(), png.end()));
    }
    tables.Add(f, frame, labels);
  }
  WriteFileAtomic(folder + "/truth.csv", tables.TruthCsv());
  WriteFileAtomic(folder + "/corners.csv", tables.CornersCsv());
  WriteRigYaml(folder + "/rig.yaml", rig);
  WriteTargetYaml(folder + "/target.yaml", target);
  return static_cast<int>(rig_from_tool.size());
}

Target AprilGrid::AsTarget() const {
  Target t;
  t.family = family;
  const double pitch = tag_size_mm * (1 + spacing_ratio);
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      TargetTag tag;
      // Row r counts from the top in the board frame; Kalibr numbers the
      // rows from the bottom.
      tag.id = first_id + (rows - 1 - r) * cols + c;
      tag.size_mm = tag_size_mm;
      tag.tool_from_tag.t = Eigen::Vector3d(c * pitch + tag_size_mm / 2,
                                            r * pitch + tag_size_mm / 2, 0);
      t.tags.push_back(tag);
    }
  }
  return t;
}

std::vector<TexturedPlane> AprilGrid::Planes(
    const Rigid3& rig_from_board) const {
  std::vector<TexturedPlane> planes;
  const double gap = spacing_ratio * tag_size_mm;
  const double pitch = tag_size_mm + gap;
  const double w = cols * pitch - gap, h = rows * pitch - gap;
  TexturedPlane board;
  board.texture = cv::Mat(1, 1, CV_8UC1, cv::Scalar(255));
  board.rig_from_plane = rig_from_board;
  board.top_left_mm =
      Eigen::Vector2d(-gap - tag_size_mm / 8, -gap - tag_size_mm / 8);
  board.size_mm = Eigen::Vector2d(w + 2 * (gap + tag_size_mm / 8),
                                  h + 2 * (gap + tag_size_mm / 8));
  planes.push_back(board);
  const Target t = AsTarget();
  for (const auto& tag : t.tags) {
    planes.push_back(TagPlane(family, tag.id, tag.size_mm,
                              rig_from_board * tag.tool_from_tag));
  }
  if (corner_squares) {
    for (int r = 0; r <= rows; ++r) {
      for (int c = 0; c <= cols; ++c) {
        TexturedPlane sq;
        sq.texture = cv::Mat(1, 1, CV_8UC1, cv::Scalar(0));
        sq.rig_from_plane = rig_from_board;
        sq.top_left_mm = Eigen::Vector2d(c * pitch - gap, r * pitch - gap);
        sq.size_mm = Eigen::Vector2d(gap, gap);
        planes.push_back(sq);
      }
    }
  }
  return planes;
}

Rigid3 AprilGrid::BoardFromTarget() const {
  Rigid3 board_from_target;
  board_from_target.R = Eigen::Vector3d(1, -1, -1).asDiagonal();
  board_from_target.t = Eigen::Vector3d(
      0, (rows - 1) * tag_size_mm * (1 + spacing_ratio) + tag_size_mm, 0);
  return board_from_target;
}

namespace {
Eigen::Matrix3d Rot(const Eigen::Vector3d& axis, double angle_deg) {
  return Eigen::AngleAxisd(angle_deg * M_PI / 180.0, axis.normalized())
      .toRotationMatrix();
}
}  // namespace

Rig ExampleStereoRig(int width, int height) {
  Rig rig;
  const double f = 1.40625 * width;  // 900 px at 640 px
  for (int c = 0; c < 2; ++c) {
    Camera cam;
    cam.intrinsics.name = c == 0 ? "left" : "right";
    cam.intrinsics.width = width;
    cam.intrinsics.height = height;
    cam.intrinsics.fx = f * (c == 0 ? 1.0 : 1.002);
    cam.intrinsics.fy = f * (c == 0 ? 1.0 : 1.001);
    cam.intrinsics.cx = (width - 1) / 2.0 + (c == 0 ? 2.5 : -3.0);
    cam.intrinsics.cy = (height - 1) / 2.0 + (c == 0 ? -1.5 : 2.0);
    cam.intrinsics.distortion =
        c == 0 ? std::vector<double>{-0.12, 0.08, 4e-4, -3e-4, 0.0}
               : std::vector<double>{-0.10, 0.05, -2e-4, 5e-4, 0.0};
    if (c == 1) {
      // Centre at (120, 0, 0) in rig, z axis turned 5 deg towards -x.
      cam.cam_from_rig.R = Rot(Eigen::Vector3d::UnitY(), 5.0);
      cam.cam_from_rig.t = -(cam.cam_from_rig.R * Eigen::Vector3d(120, 0, 0));
    }
    rig.cameras.push_back(cam);
  }
  return rig;
}

Target ExampleTarget() {
  Target t;
  t.family = "tag36h11";
  const double x[4] = {-16.5, 16.5, -16.5, 16.5};
  const double y[4] = {-16.5, -16.5, 16.5, 16.5};
  for (int i = 0; i < 4; ++i) {
    TargetTag tag;
    tag.id = i;
    tag.size_mm = 25.0;
    // Left column turned +20 deg about y, right column -20 deg: a shallow V.
    const double angle = x[i] < 0 ? 20.0 : -20.0;
    tag.tool_from_tag.R = Rot(Eigen::Vector3d::UnitY(), angle);
    tag.tool_from_tag.t =
        Eigen::Vector3d(x[i] * std::cos(angle * M_PI / 180), y[i],
                        std::abs(x[i]) * std::sin(20.0 * M_PI / 180));
    t.tags.push_back(tag);
  }
  t.tip_in_tool = Eigen::Vector3d(0, 100, 10);
  return t;
}

Rigid3 ExampleToolPose(int i) {
  Rigid3 pose;
  const double a = 0.7 * i, b = 1.3 * i;
  pose.R =
      Rot(Eigen::Vector3d(std::sin(a), std::cos(b), 0.3), 12.0 * std::sin(b)) *
      Rot(Eigen::Vector3d::UnitX(), -15.0);
  pose.t = Eigen::Vector3d(60 + 25 * std::sin(a), -20 + 15 * std::cos(b),
                           450 + 40 * std::sin(0.5 * a));
  return pose;
}

}  // namespace kincal
