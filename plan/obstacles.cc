#include "plan/obstacles.h"

#include <Eigen/Geometry>
#include <cmath>

#include "data/atomic_file.h"
#include "data/yaml_util.h"

namespace kincal {
namespace {

constexpr double kMaxCoordinateMm = 1e5;  // 100 m: beyond any cell
constexpr double kMaxClearanceMm = 1e4;

Eigen::Vector3d Position(const YamlReader& r, const YAML::Node& node,
                         const std::string& what) {
  const std::vector<double> v = r.Numbers(node, what, 3, 3);
  for (double x : v) {
    if (std::abs(x) > kMaxCoordinateMm) {
      r.Fail(node, what + ": coordinates are in mm, beyond 100 m is absurd");
    }
  }
  return Eigen::Vector3d(v[0], v[1], v[2]);
}

double Clearance(const YamlReader& r, const YAML::Node& map,
                 const std::string& what) {
  const double c = r.NumberOr(map, "clearance_mm", 0.0, what + ".clearance_mm");
  if (!(c >= 0 && c <= kMaxClearanceMm)) {
    r.Fail(
        map["clearance_mm"],
        what + ".clearance_mm: expected 0 to 10000 mm, got " + FormatDouble(c));
  }
  return c;
}

ObstaclePlane ParsePlane(const YamlReader& r, const YAML::Node& node,
                         const std::string& what) {
  r.ExpectMap(node, what);
  r.CheckKeys(node, {"name", "point", "normal", "clearance_mm"}, what);
  ObstaclePlane plane;
  plane.name = node["name"] ? r.String(node["name"], what + ".name") : what;
  plane.point = Position(r, r.Required(node, "point", what), what + ".point");
  const YAML::Node normal = r.Required(node, "normal", what);
  const std::vector<double> n = r.Numbers(normal, what + ".normal", 3, 3);
  const Eigen::Vector3d v(n[0], n[1], n[2]);
  if (!(v.norm() > 1e-9)) {
    r.Fail(normal, what + ".normal: expected a non-zero direction");
  }
  plane.normal = v.normalized();
  plane.clearance_mm = Clearance(r, node, what);
  return plane;
}

ObstacleBox ParseBox(const YamlReader& r, const YAML::Node& node,
                     const std::string& what) {
  r.ExpectMap(node, what);
  r.CheckKeys(node, {"name", "center", "size", "rpy_deg", "clearance_mm"},
              what);
  ObstacleBox box;
  box.name = node["name"] ? r.String(node["name"], what + ".name") : what;
  box.center = Position(r, r.Required(node, "center", what), what + ".center");
  const YAML::Node size = r.Required(node, "size", what);
  const std::vector<double> s = r.Numbers(size, what + ".size", 3, 3);
  for (double x : s) {
    if (!(x > 0 && x <= kMaxCoordinateMm)) {
      r.Fail(size, what +
                       ".size: expected edge lengths in (0, 100000] mm, "
                       "got " +
                       FormatDouble(x));
    }
  }
  box.size = Eigen::Vector3d(s[0], s[1], s[2]);
  if (node["rpy_deg"]) {
    const std::vector<double> rpy =
        r.Numbers(node["rpy_deg"], what + ".rpy_deg", 3, 3);
    for (double a : rpy) {
      if (std::abs(a) > 360) {
        r.Fail(node["rpy_deg"],
               what + ".rpy_deg: expected angles within [-360, 360] deg");
      }
    }
    const double k = M_PI / 180;
    box.base_from_box =
        (Eigen::AngleAxisd(rpy[2] * k, Eigen::Vector3d::UnitZ()) *
         Eigen::AngleAxisd(rpy[1] * k, Eigen::Vector3d::UnitY()) *
         Eigen::AngleAxisd(rpy[0] * k, Eigen::Vector3d::UnitX()))
            .toRotationMatrix();
  }
  box.clearance_mm = Clearance(r, node, what);
  return box;
}

}  // namespace

Obstacles ParseObstaclesYaml(const std::string& text, const std::string& file) {
  const YamlReader r(file);
  const YAML::Node root = r.Load(text);
  r.ExpectMap(root, "obstacle file");
  r.CheckKeys(root, {"kincal_obstacles", "planes", "boxes"}, "obstacle file");
  const YAML::Node version =
      r.Required(root, "kincal_obstacles", "obstacle file");
  if (r.Integer(version, "kincal_obstacles") != 1) {
    r.Fail(version, "kincal_obstacles: unsupported format version " +
                        version.as<std::string>() + " (expected 1)");
  }
  Obstacles out;
  if (root["planes"] && !root["planes"].IsNull()) {
    r.ExpectSequence(root["planes"], "planes");
    for (size_t i = 0; i < root["planes"].size(); ++i) {
      out.planes.push_back(ParsePlane(r, root["planes"][i],
                                      "planes[" + std::to_string(i) + "]"));
    }
  }
  if (root["boxes"] && !root["boxes"].IsNull()) {
    r.ExpectSequence(root["boxes"], "boxes");
    for (size_t i = 0; i < root["boxes"].size(); ++i) {
      out.boxes.push_back(
          ParseBox(r, root["boxes"][i], "boxes[" + std::to_string(i) + "]"));
    }
  }
  return out;
}

Obstacles ReadObstaclesYaml(const std::string& path) {
  return ParseObstaclesYaml(ReadFile(path), path);
}

}  // namespace kincal
