#ifndef KINCAL_PLAN_SAFETY_H_
#define KINCAL_PLAN_SAFETY_H_

// Safety of a planned pose: the robot's links as capsules (a segment and a
// radius) must keep clear of obstacle planes and boxes and of each other.
//
// The capsules: the points base origin, the origin of every joint's frame
// (calib/chain.h JointAxesInBase: the frame in which joint j moves) and the
// tip, joined in order; segments shorter than 1 mm are dropped (coincident
// DH origins). All capsules share one radius (--link-radius, default 40 mm,
// a UR10's or Panda's forearm); the last one (the tool up to the tip) too.
//
// Rules:
// - plane: the signed distance of a segment to the plane (its endpoint
//   nearest the wrong side) must be at least radius + clearance;
// - box: the distance between the segment and the box at least
//   radius + clearance;
// - self: two capsules at least two apart in the list (not sharing a joint)
//   at least 2 radius apart.
// The base capsules (up to the origin of the second joint's frame: they turn
// about the first axis only, the column the robot stands on) are not checked
// against a plane that passes within radius + clearance of the base origin
// (or has the base origin on its wrong side): that is the table the robot
// stands on. Every later capsule is.

#include <Eigen/Core>
#include <string>
#include <vector>

#include "calib/chain.h"
#include "plan/obstacles.h"

namespace kincal {

struct Segment {
  Eigen::Vector3d a = Eigen::Vector3d::Zero(), b = Eigen::Vector3d::Zero();
};

// Signed distance of the segment's point nearest the plane's wrong side
// (negative: that point is behind the plane). Clearance not included.
double SegmentPlaneDistance(const Segment& s, const ObstaclePlane& plane);
// Distance between the segment and the solid box (0 when they meet).
double SegmentBoxDistance(const Segment& s, const ObstacleBox& box);
// Distance between two segments.
double SegmentSegmentDistance(const Segment& s, const Segment& t);

struct LinkCapsules {
  std::vector<Segment> segments;  // base to tip
  int base_count = 0;             // the first ones turn about axis 1 only
};
// The capsules' segments for joint values q (internal units).
LinkCapsules LinkSegments(const Chain& chain, const std::vector<double>& q);

struct SafetyOptions {
  Obstacles obstacles;
  double link_radius_mm = 40;
  bool self_collision = true;
};

// What a pose meets first (kind kNone: nothing).
struct Contact {
  enum Kind { kNone, kPlane, kBox, kSelf };
  Kind kind = kNone;
  int obstacle = -1;  // index into planes or boxes
  int link = -1, other_link = -1;
  std::string Describe(const SafetyOptions& options) const;
};
Contact FindContact(const Chain& chain, const std::vector<double>& q,
                    const SafetyOptions& options);

}  // namespace kincal

#endif  // KINCAL_PLAN_SAFETY_H_
