#ifndef KINCAL_PLAN_ISO9283_CUBE_H_
#define KINCAL_PLAN_ISO9283_CUBE_H_

// The poses of ISO 9283's pose-accuracy and pose-repeatability test
// (`kincal plan --iso9283 --cube MM`): a cube of edge `cube_mm` in the
// working space, edges parallel to the robot's base axes; on its diagonal
// plane C1-C2-C7-C8 the five test positions
//
//   P1 = the cube's centre (where the plane's diagonals cross),
//   P2..P5 on the diagonals C1-C7 and C2-C8, 10 % of the diagonal's length
//   from the corners C1, C2, C7, C8,
//
// with corners (h = cube_mm / 2, c = centre, base frame)
//   C1 = c + h (-1, -1, -1), C2 = c + h (+1, -1, -1),
//   C7 = c + h (+1, +1, +1), C8 = c + h (-1, +1, +1)
// (the plane holds the bottom edge C1-C2 and the opposite top edge C8-C7)
// and P2 near C1, P3 near C2, P4 near C7, P5 near C8. Every cycle visits
// P5, P4, P3, P2, P1 (30 cycles by default); the robot starts at P1.
//
// The tool orientation is the same at every pose: arms with six or more
// joints solve pose inverse kinematics (position and that orientation),
// arms with fewer solve for the position only. All five poses come from one
// configuration: P1 is solved from a seed, P2..P5 from P1's solution, so the
// arm keeps its elbow and wrist branch. Every pose keeps `limit_margin` of
// each joint's range from both limits and its link capsules clear of the
// obstacles and of each other (plan/safety.h), and so do the joint-space
// moves between consecutive poses (checked at `path_checks` intermediate
// points per move). Revolute joints are then shifted, all five poses
// alike, by whole turns toward the middle of their ranges where the limits
// allow (the same tip poses and moves).
//
// Default centre and orientation: `samples` random feasible configurations
// (within the limits less the margin, no contact) are drawn; seeds are the
// feasible configurations whose tips lie nearest the median of their tips
// (the middle of the reachable workspace), nearest first. For each seed
// the centre is its tip (or the given centre) and the orientation its
// tip's orientation (or the given one); the first seed for which all five
// poses (and the moves between them) are feasible is taken. None: the cube
// does not fit, InputError naming the position that failed for the seed
// that got furthest, and why: "unreachable" (the solve misses it even
// without limits), "beyond a joint limit" (reached only without limits; the
// joint is named), "in collision" (what is met, at the pose or on a move).

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "data/robot.h"
#include "plan/safety.h"

namespace kincal {

struct IsoCubeOptions {
  double cube_mm = 0;  // edge length; required, > 0
  int cycles = 30;     // the standard's number of cycles for AP and RP
  // The cube's centre in the base frame (mm); default: searched (above).
  std::optional<Eigen::Vector3d> center_mm;
  // The tool orientation, base_from_tip as a rotation vector (deg); only
  // for arms with six or more joints; default: the seed's.
  std::optional<Eigen::Vector3d> orientation_deg;
  // Every pose keeps this fraction of each joint's range from both limits;
  // [0, 0.45].
  double limit_margin = 0.05;
  SafetyOptions safety;  // obstacles, link capsules, self-collision
  uint64_t seed = 1;     // the random configurations
  int samples = 400;     // random feasible configurations drawn
  int max_seeds = 60;    // of them, tried as the seed (nearest first)
  int path_checks = 20;  // intermediate points checked per move
  long max_draws = 200000;
};

// One test position and the joint readings that reach it.
struct IsoCubePose {
  std::string label;  // "P1".."P5"
  Eigen::Vector3d position_mm = Eigen::Vector3d::Zero();
  std::vector<double> joints;  // reading units (mm | deg)
};

struct IsoCubePlan {
  double cube_mm = 0;
  Eigen::Vector3d center_mm = Eigen::Vector3d::Zero();
  // True for arms with six or more joints: every pose has `rotation`.
  bool fixed_orientation = false;
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();  // base_from_tip
  std::array<IsoCubePose, 5> poses;                        // P1..P5
  int cycles = 0;
  // Rows in visiting order (all cycles): indices into `poses`.
  std::vector<int> rows;
  int seeds_tried = 0;
  long draws = 0;  // random configurations drawn
  double seconds = 0;
};

// The corners C1, C2, C7, C8 of the cube's test plane (see above).
std::array<Eigen::Vector3d, 4> IsoCubePlaneCorners(
    const Eigen::Vector3d& center_mm, double cube_mm);

// P1..P5 for a cube of edge `cube_mm` centred at `center_mm`.
std::array<Eigen::Vector3d, 5> IsoCubePositions(
    const Eigen::Vector3d& center_mm, double cube_mm);

// The visiting order of one cycle, as indices into P1..P5: P5 P4 P3 P2 P1.
std::array<int, 5> IsoCubeCycleOrder();

// Throws InputError on bad options (no limits, cube <= 0, cycles < 1,
// orientation on an arm with fewer than six joints) and when the cube does
// not fit (the message names the failing position and why).
IsoCubePlan PlanIsoCube(const Robot& robot, const IsoCubeOptions& options);

// POSES.csv: "# <command>", a comment with the cube, then
// pose,<joint names>,fixed_point and one row per visit (pose ids 0..n-1,
// fixed_point = P1..P5): an observations.csv once x,y,z are added.
std::string FormatIsoCubeCsv(const Robot& robot, const IsoCubePlan& plan);

}  // namespace kincal

#endif  // KINCAL_PLAN_ISO9283_CUBE_H_
