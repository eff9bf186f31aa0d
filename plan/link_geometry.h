#ifndef KINCAL_PLAN_LINK_GEOMETRY_H_
#define KINCAL_PLAN_LINK_GEOMETRY_H_

// The robot's links as capsules fixed to the chain's frames, from a URDF's
// <collision> geometry, for plan's safety checks (plan/safety.h).
//
// Each collision element becomes the capsule that encloses it: a sphere is a
// capsule of length 0; a cylinder one along its axis with the cylinder's
// radius and length; a box one along its longest edge, of that edge's length
// and half the diagonal of the other two as radius; a mesh (STL or OBJ that
// can be read, the file relative to the URDF or file://) its axis-aligned
// bounding box in the mesh frame (scale applied), enclosed as a box.
//
// Links are carried by the chain's frames: the root link (and links fixed to
// it) by the base, the child link of the j-th movable joint of the chain
// (and links fixed to it) by frame j, the frame after joint j's motion (for
// a robot read from URDF exactly that link's frame). Links hanging off the
// chain through movable joints that are not in it (gripper fingers) are
// carried at those joints' zero.
//
// Links next to each other (frames j and j+1, or the same frame) are not
// checked against each other, nor are pairs that touch in every one of 100
// random poses inside the joint limits (MoveIt's "always in collision": they
// overlap by design at the joint between them).
//
// When the URDF has no <collision> on any link the chain carries, or a mesh
// cannot be read (package:// paths, other formats), the model is empty and
// `warnings` says why: plan then falls back to the generic capsules.

#include <Eigen/Core>
#include <string>
#include <utility>
#include <vector>

#include "data/robot.h"

namespace kincal {

struct LinkCapsule {
  std::string link;  // URDF link name
  int frame = -1;    // -1: base; j: after the chain's joint j
  Eigen::Vector3d a = Eigen::Vector3d::Zero(), b = Eigen::Vector3d::Zero();
  double radius_mm = 0;  // mm, in the frame
};

struct LinkGeometry {
  std::vector<LinkCapsule> capsules;
  // Index pairs (i < k) into capsules that are never checked against each
  // other beside the neighbouring frames: always in contact.
  std::vector<std::pair<int, int>> always_touching;
  std::vector<std::string> warnings;
  bool empty() const { return capsules.empty(); }
};

// The collision geometry of the URDF file `path` for `robot` (read from
// that file with ReadUrdfChain from `root_link`, empty = the tree's root:
// the robot's joints name the chain's movable joints).
LinkGeometry ReadUrdfLinkGeometry(const std::string& path, const Robot& robot,
                                  const std::string& root_link = "");
// The same from the URDF text; mesh paths are relative to `urdf_dir`.
LinkGeometry ParseUrdfLinkGeometry(const std::string& xml,
                                   const std::string& urdf_dir,
                                   const Robot& robot,
                                   const std::string& root_link = "");

}  // namespace kincal

#endif  // KINCAL_PLAN_LINK_GEOMETRY_H_
