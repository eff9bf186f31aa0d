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
// For a robot given by URDF, plan/link_geometry.h's capsules from the
// URDF's <collision> geometry replace these (SafetyOptions::links): each with
// its own radius, carried by its chain frame; the base ones are those
// carried by the base and joint 1's frame, and two capsules are checked
// against each other when their frames are at least two apart and they do
// not touch in every pose (LinkGeometry::always_touching).
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
#include "data/robot.h"
#include "plan/link_geometry.h"
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
  // The URDF's collision capsules; empty: the generic capsules above.
  LinkGeometry links;
};

// The frames the chain carries links with, in the base frame, for joint
// values q (internal units): [0] the base (identity), [j + 1] the frame
// after joint j's motion.
std::vector<Eigen::Matrix4d> BaseFromLinkFrames(const Chain& chain,
                                                const std::vector<double>& q);

// One pose's capsules in the base frame.
struct PlacedCapsule {
  Segment segment;
  double radius_mm = 0;
  int frame = 0;      // capsules of frames at least two apart are checked
  bool base = false;  // turns about the first axis only
};
std::vector<PlacedCapsule> PlaceCapsules(const Chain& chain,
                                         const std::vector<double>& q,
                                         const SafetyOptions& options);

// Fills links->always_touching: the pairs of capsules (frames at least two
// apart) that meet in every one of `samples` random poses inside the
// robot's limits (a joint without limits: a full turn / +-1 m), seeded.
void MarkAlwaysTouching(const Chain& chain, const Robot& robot,
                        LinkGeometry* links, int samples = 100);

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
