#include "plan/safety.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <random>
#include <utility>

#include "data/minimize.h"

namespace kincal {
namespace {

constexpr double kShortSegmentMm = 1.0;

// Distance from a point (box frame) to the axis-aligned box of half edges h.
double PointBoxDistance(const Eigen::Vector3d& p, const Eigen::Vector3d& h) {
  const Eigen::Vector3d outside = (p.cwiseAbs() - h).cwiseMax(0.0);
  return outside.norm();
}

}  // namespace

double SegmentPlaneDistance(const Segment& s, const ObstaclePlane& plane) {
  return std::min(plane.normal.dot(s.a - plane.point),
                  plane.normal.dot(s.b - plane.point));
}

// The distance from the point s(t) to the convex box is a convex function
// of t, so a golden-section search on [0, 1] finds its minimum.
double SegmentBoxDistance(const Segment& s, const ObstacleBox& box) {
  const Eigen::Matrix3d box_from_base = box.base_from_box.transpose();
  const Eigen::Vector3d a = box_from_base * (s.a - box.center);
  const Eigen::Vector3d b = box_from_base * (s.b - box.center);
  const Eigen::Vector3d h = 0.5 * box.size;
  auto f = [&](double t) { return PointBoxDistance(a + t * (b - a), h); };
  // 58 iterations: the bracket to 1e-12 of the segment.
  const GoldenSectionResult m = GoldenSectionMinimize(f, 0.0, 1.0, 58);
  return std::min({f(0.0), f(1.0), m.f});
}

// Closest points of two segments (Ericson, Real-Time Collision Detection,
// 5.1.9): minimise |p(s) - q(t)| over s, t in [0, 1].
double SegmentSegmentDistance(const Segment& s1, const Segment& s2) {
  const Eigen::Vector3d d1 = s1.b - s1.a, d2 = s2.b - s2.a, r = s1.a - s2.a;
  const double a = d1.squaredNorm(), e = d2.squaredNorm(), f = d2.dot(r);
  const double eps = 1e-12;
  double s = 0, t = 0;
  if (a <= eps && e <= eps) return r.norm();
  if (a <= eps) {
    t = std::clamp(f / e, 0.0, 1.0);
  } else {
    const double c = d1.dot(r);
    if (e <= eps) {
      s = std::clamp(-c / a, 0.0, 1.0);
    } else {
      const double b = d1.dot(d2), denom = a * e - b * b;
      s = denom > eps * a * e ? std::clamp((b * f - c * e) / denom, 0.0, 1.0)
                              : 0.0;
      t = (b * s + f) / e;
      if (t < 0) {
        t = 0;
        s = std::clamp(-c / a, 0.0, 1.0);
      } else if (t > 1) {
        t = 1;
        s = std::clamp((b - c) / a, 0.0, 1.0);
      }
    }
  }
  return ((s1.a + s * d1) - (s2.a + t * d2)).norm();
}

LinkCapsules LinkSegments(const Chain& chain, const std::vector<double>& q) {
  std::vector<Eigen::Vector3d> origins, axes;
  JointAxesInBase(chain, q, &origins, &axes);
  std::vector<Eigen::Vector3d> points{Eigen::Vector3d::Zero()};
  points.insert(points.end(), origins.begin(), origins.end());
  points.push_back(BaseFromTipAt(chain, q).block<3, 1>(0, 3));
  // points[k] for k <= 2 (base, joint 1's and joint 2's frame origins) turn
  // about the first axis only.
  LinkCapsules out;
  Eigen::Vector3d from = points[0];
  for (size_t k = 1; k < points.size(); ++k) {
    if ((points[k] - from).norm() < kShortSegmentMm) continue;
    out.segments.push_back({from, points[k]});
    if (k <= 2) out.base_count = static_cast<int>(out.segments.size());
    from = points[k];
  }
  return out;
}

std::vector<Eigen::Matrix4d> BaseFromLinkFrames(const Chain& chain,
                                                const std::vector<double>& q) {
  std::vector<Eigen::Matrix4d> frames{Eigen::Matrix4d::Identity()};
  for (int j = 0; j < chain.num_joints(); ++j) {
    const ChainRow& row = chain.rows[j];
    frames.push_back(frames.back() * RowTransform<double>(chain.convention, row,
                                                          row.p.data(), q[j]));
  }
  return frames;
}

std::vector<PlacedCapsule> PlaceCapsules(const Chain& chain,
                                         const std::vector<double>& q,
                                         const SafetyOptions& options) {
  std::vector<PlacedCapsule> placed;
  if (options.links.empty()) {
    const LinkCapsules links = LinkSegments(chain, q);
    for (size_t k = 0; k < links.segments.size(); ++k) {
      placed.push_back({links.segments[k], options.link_radius_mm,
                        static_cast<int>(k),
                        static_cast<int>(k) < links.base_count});
    }
    return placed;
  }
  const std::vector<Eigen::Matrix4d> frames = BaseFromLinkFrames(chain, q);
  for (const LinkCapsule& c : options.links.capsules) {
    const Eigen::Matrix4d& m = frames[c.frame + 1];
    const Eigen::Matrix3d r = m.block<3, 3>(0, 0);
    const Eigen::Vector3d t = m.block<3, 1>(0, 3);
    placed.push_back(
        {{r * c.a + t, r * c.b + t}, c.radius_mm, c.frame, c.frame <= 0});
  }
  return placed;
}

namespace {

bool AlwaysTouching(const SafetyOptions& options, int i, int k) {
  const auto& pairs = options.links.always_touching;
  return std::find(pairs.begin(), pairs.end(), std::make_pair(i, k)) !=
         pairs.end();
}

}  // namespace

void MarkAlwaysTouching(const Chain& chain, const Robot& robot,
                        LinkGeometry* links, int samples) {
  links->always_touching.clear();
  const int n = static_cast<int>(links->capsules.size());
  if (n == 0) return;
  SafetyOptions options;
  options.links = *links;
  std::mt19937 rng(1);
  std::vector<std::vector<int>> touching(n, std::vector<int>(n, 0));
  for (int s = 0; s < samples; ++s) {
    std::vector<double> q;
    for (int j = 0; j < chain.num_joints(); ++j) {
      const RobotRow& row = robot.joints[j];
      const bool revolute = row.type == JointType::kRevolute;
      const double lo = row.HasLimits() ? row.lower : (revolute ? -180 : -1000);
      const double hi = row.HasLimits() ? row.upper : (revolute ? 180 : 1000);
      q.push_back(chain.ReadingToInternal(
          j, std::uniform_real_distribution<double>(lo, hi)(rng)));
    }
    const std::vector<PlacedCapsule> placed = PlaceCapsules(chain, q, options);
    for (int i = 0; i < n; ++i) {
      for (int k = i + 1; k < n; ++k) {
        if (std::abs(placed[i].frame - placed[k].frame) < 2) continue;
        touching[i][k] +=
            SegmentSegmentDistance(placed[i].segment, placed[k].segment) <
            placed[i].radius_mm + placed[k].radius_mm;
      }
    }
  }
  for (int i = 0; i < n; ++i) {
    for (int k = i + 1; k < n; ++k) {
      if (touching[i][k] == samples) links->always_touching.push_back({i, k});
    }
  }
}

Contact FindContact(const Chain& chain, const std::vector<double>& q,
                    const SafetyOptions& options) {
  const std::vector<PlacedCapsule> links = PlaceCapsules(chain, q, options);
  const int n = static_cast<int>(links.size());
  Contact contact;
  const std::vector<ObstaclePlane>& planes = options.obstacles.planes;
  for (size_t p = 0; p < planes.size(); ++p) {
    const double clearance = planes[p].clearance_mm;
    const bool stands_on = planes[p].normal.dot(-planes[p].point) <
                           options.link_radius_mm + clearance;  // base origin
    for (int k = 0; k < n; ++k) {
      if (stands_on && links[k].base) continue;
      if (SegmentPlaneDistance(links[k].segment, planes[p]) <
          links[k].radius_mm + clearance) {
        contact.kind = Contact::kPlane;
        contact.obstacle = static_cast<int>(p);
        contact.link = k;
        return contact;
      }
    }
  }
  const std::vector<ObstacleBox>& boxes = options.obstacles.boxes;
  for (size_t b = 0; b < boxes.size(); ++b) {
    for (int k = 0; k < n; ++k) {
      if (SegmentBoxDistance(links[k].segment, boxes[b]) <
          links[k].radius_mm + boxes[b].clearance_mm) {
        contact.kind = Contact::kBox;
        contact.obstacle = static_cast<int>(b);
        contact.link = k;
        return contact;
      }
    }
  }
  if (!options.self_collision) return contact;
  for (int i = 0; i < n; ++i) {
    for (int k = i + 1; k < n; ++k) {
      if (std::abs(links[i].frame - links[k].frame) < 2 ||
          AlwaysTouching(options, i, k)) {
        continue;
      }
      if (SegmentSegmentDistance(links[i].segment, links[k].segment) <
          links[i].radius_mm + links[k].radius_mm) {
        contact.kind = Contact::kSelf;
        contact.link = i;
        contact.other_link = k;
        return contact;
      }
    }
  }
  return contact;
}

std::string Contact::Describe(const SafetyOptions& options) const {
  switch (kind) {
    case kNone:
      return "no contact";
    case kPlane:
      return "plane '" + options.obstacles.planes[obstacle].name + "'";
    case kBox:
      return "box '" + options.obstacles.boxes[obstacle].name + "'";
    case kSelf:
      return "self-collision";
  }
  return "";
}

}  // namespace kincal
