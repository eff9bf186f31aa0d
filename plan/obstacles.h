#ifndef KINCAL_PLAN_OBSTACLES_H_
#define KINCAL_PLAN_OBSTACLES_H_

// Obstacles around the robot for `kincal plan --obstacles OBST.yaml`: planes
// (a table, a wall) and boxes (a camera stand, a fixture), all in the robot
// base frame, millimetres and degrees:
//
//   kincal_obstacles: 1
//   planes:
//     - {name: table, point: [0, 0, 0], normal: [0, 0, 1], clearance_mm: 20}
//   boxes:
//     - {name: stand, center: [900, 0, 600], size: [200, 200, 1200],
//        rpy_deg: [0, 0, 0], clearance_mm: 20}
//
// The robot must stay on the side a plane's normal points to; a box is
// centred at `center`, `size` its full edge lengths along its own axes,
// turned by rpy_deg (R = Rz(yaw) Ry(pitch) Rx(roll), as in URDF). name and
// clearance_mm (default 0) are optional. Errors name file:line:column.

#include <Eigen/Core>
#include <string>
#include <vector>

namespace kincal {

struct ObstaclePlane {
  std::string name;
  Eigen::Vector3d point = Eigen::Vector3d::Zero();    // mm, base frame
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  // unit, free side
  double clearance_mm = 0;
};

struct ObstacleBox {
  std::string name;
  Eigen::Vector3d center = Eigen::Vector3d::Zero();  // mm, base frame
  Eigen::Vector3d size = Eigen::Vector3d::Zero();    // full edges, mm
  Eigen::Matrix3d base_from_box = Eigen::Matrix3d::Identity();
  double clearance_mm = 0;
};

struct Obstacles {
  std::vector<ObstaclePlane> planes;
  std::vector<ObstacleBox> boxes;
  bool empty() const { return planes.empty() && boxes.empty(); }
};

// Throws InputError (file:line:column) on syntax errors, unknown keys,
// non-finite or absurd values (coordinates beyond 100 m, a zero normal,
// box edges not in (0, 100 m], clearance not in [0, 10 m]).
Obstacles ParseObstaclesYaml(const std::string& text, const std::string& file);
Obstacles ReadObstaclesYaml(const std::string& path);

}  // namespace kincal

#endif  // KINCAL_PLAN_OBSTACLES_H_
