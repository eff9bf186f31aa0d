#include "plan/link_geometry.h"

#include <console_bridge/console.h>
#include <urdf_parser/urdf_parser.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cctype>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <map>
#include <mutex>
#include <sstream>

#include "data/atomic_file.h"
#include "data/error.h"

namespace kincal {
namespace {

constexpr double kMetresToMm = 1000.0;

// Drops urdfdom's console messages (the file was validated when the robot
// was read).
class Silent : public console_bridge::OutputHandler {
 public:
  void log(const std::string&, console_bridge::LogLevel, const char*,
           int) override {}
};

Eigen::Isometry3d ToIsometry(const urdf::Pose& pose) {
  Eigen::Isometry3d m = Eigen::Isometry3d::Identity();
  m.translation() =
      kMetresToMm *
      Eigen::Vector3d(pose.position.x, pose.position.y, pose.position.z);
  m.linear() = Eigen::Quaterniond(pose.rotation.w, pose.rotation.x,
                                  pose.rotation.y, pose.rotation.z)
                   .normalized()
                   .toRotationMatrix();
  return m;
}

// Reads the vertices of an STL (binary or ASCII) or OBJ mesh, metres;
// empty when the file cannot be read.
std::vector<Eigen::Vector3d> ReadMeshVertices(const std::string& path) {
  std::vector<Eigen::Vector3d> vertices;
  std::ifstream in(path, std::ios::binary);
  if (!in) return vertices;
  const std::string data((std::istreambuf_iterator<char>(in)),
                         std::istreambuf_iterator<char>());
  std::string lower = path;
  std::transform(lower.begin(), lower.end(), lower.begin(), ::tolower);
  const auto ends_with = [&](const char* ext) {
    const size_t n = std::strlen(ext);
    return lower.size() >= n && lower.compare(lower.size() - n, n, ext) == 0;
  };
  // Binary STL: 80-byte header, little-endian triangle count, 50 bytes per
  // triangle (normal, three vertices as float32, attribute count).
  if (ends_with(".stl") && data.size() >= 84) {
    uint32_t triangles = 0;
    std::memcpy(&triangles, data.data() + 80, 4);
    if (data.size() == 84 + 50ull * triangles) {  // binary
      for (uint32_t t = 0; t < triangles; ++t) {
        for (int v = 0; v < 3; ++v) {
          float xyz[3];
          std::memcpy(xyz, data.data() + 84 + 50ull * t + 12 + 12 * v, 12);
          vertices.emplace_back(xyz[0], xyz[1], xyz[2]);
        }
      }
      return vertices;
    }
  }
  const bool obj = ends_with(".obj");
  if (!obj && !ends_with(".stl")) return vertices;
  std::istringstream lines(data);
  std::string word;
  while (lines >> word) {
    if ((obj && word == "v") || (!obj && word == "vertex")) {
      Eigen::Vector3d p;
      if (lines >> p.x() >> p.y() >> p.z()) vertices.push_back(p);
    }
  }
  return vertices;
}

// The capsule (in the geometry's frame) enclosing a box of full edges
// `size` centred at `centre`.
LinkCapsule BoxCapsule(const Eigen::Vector3d& centre,
                       const Eigen::Vector3d& size) {
  int axis = 0;
  size.maxCoeff(&axis);
  Eigen::Vector3d half_axis = Eigen::Vector3d::Zero();
  half_axis[axis] = 0.5 * size[axis];
  Eigen::Vector3d others = size;
  others[axis] = 0;
  LinkCapsule c;
  c.a = centre - half_axis;
  c.b = centre + half_axis;
  c.radius_mm = 0.5 * others.norm();
  return c;
}

// The enclosing capsule of one collision element in the geometry frame;
// false (with `why`) when a mesh cannot be read.
bool GeometryCapsule(const urdf::Geometry& geometry, const std::string& dir,
                     LinkCapsule* capsule, std::string* why) {
  switch (geometry.type) {
    case urdf::Geometry::SPHERE: {
      const auto& s = static_cast<const urdf::Sphere&>(geometry);
      capsule->radius_mm = kMetresToMm * s.radius;
      return true;
    }
    case urdf::Geometry::CYLINDER: {
      const auto& c = static_cast<const urdf::Cylinder&>(geometry);
      capsule->a = Eigen::Vector3d(0, 0, -0.5 * kMetresToMm * c.length);
      capsule->b = -capsule->a;
      capsule->radius_mm = kMetresToMm * c.radius;
      return true;
    }
    case urdf::Geometry::BOX: {
      const auto& b = static_cast<const urdf::Box&>(geometry);
      *capsule =
          BoxCapsule(Eigen::Vector3d::Zero(),
                     kMetresToMm * Eigen::Vector3d(b.dim.x, b.dim.y, b.dim.z));
      return true;
    }
    case urdf::Geometry::MESH: {
      const auto& m = static_cast<const urdf::Mesh&>(geometry);
      std::string file = m.filename;
      if (file.rfind("file://", 0) == 0) file = file.substr(7);
      if (file.find("://") != std::string::npos) {
        *why = "mesh '" + m.filename +
               "' (a package path kincal cannot "
               "resolve)";
        return false;
      }
      if (!file.empty() && file[0] != '/') file = dir + "/" + file;
      const std::vector<Eigen::Vector3d> vertices = ReadMeshVertices(file);
      if (vertices.empty()) {
        *why = "mesh '" + m.filename + "' (not a readable STL or OBJ file)";
        return false;
      }
      const Eigen::Vector3d scale(m.scale.x, m.scale.y, m.scale.z);
      Eigen::Vector3d lo = Eigen::Vector3d::Constant(
                          std::numeric_limits<double>::infinity()),
                      hi = -lo;
      for (const Eigen::Vector3d& v : vertices) {
        const Eigen::Vector3d p = kMetresToMm * v.cwiseProduct(scale);
        lo = lo.cwiseMin(p);
        hi = hi.cwiseMax(p);
      }
      *capsule = BoxCapsule(0.5 * (lo + hi), hi - lo);
      return true;
    }
  }
  return false;
}

// Adds the collision capsules of `link` (pose frame_from_link in `frame`)
// and of the links below it reached through joints not in the chain.
void CollectLink(const urdf::ModelInterface& model, const urdf::Link& link,
                 int frame, const Eigen::Isometry3d& frame_from_link,
                 const std::map<std::string, int>& chain_joint,
                 const std::string& dir, LinkGeometry* out,
                 std::vector<std::string>* unreadable) {
  for (const auto& collision : link.collision_array) {
    if (!collision || !collision->geometry) continue;
    LinkCapsule capsule;
    std::string why;
    if (!GeometryCapsule(*collision->geometry, dir, &capsule, &why)) {
      unreadable->push_back("link '" + link.name + "': " + why);
      continue;
    }
    const Eigen::Isometry3d frame_from_geometry =
        frame_from_link * ToIsometry(collision->origin);
    capsule.link = link.name;
    capsule.frame = frame;
    capsule.a = frame_from_geometry * capsule.a;
    capsule.b = frame_from_geometry * capsule.b;
    out->capsules.push_back(capsule);
  }
  for (const auto& joint : link.child_joints) {
    if (chain_joint.count(joint->name)) continue;  // its own frame
    const urdf::LinkConstSharedPtr child =
        model.getLink(joint->child_link_name);
    if (!child) continue;
    CollectLink(
        model, *child, frame,
        frame_from_link * ToIsometry(joint->parent_to_joint_origin_transform),
        chain_joint, dir, out, unreadable);
  }
}

}  // namespace

LinkGeometry ParseUrdfLinkGeometry(const std::string& xml,
                                   const std::string& urdf_dir,
                                   const Robot& robot,
                                   const std::string& root_link) {
  urdf::ModelInterfaceSharedPtr model;
  {
    static std::mutex mutex;  // console_bridge's handler is process-wide
    std::lock_guard<std::mutex> lock(mutex);
    Silent silent;
    console_bridge::useOutputHandler(&silent);
    try {
      model = urdf::parseURDF(xml);
    } catch (const std::exception&) {
      model.reset();
    }
    console_bridge::restorePreviousOutputHandler();
  }
  LinkGeometry out;
  if (!model) {
    out.warnings.push_back(
        "the URDF could not be read for its collision "
        "geometry");
    return out;
  }
  std::map<std::string, int> chain_joint;
  for (size_t j = 0; j < robot.joints.size(); ++j) {
    chain_joint[robot.joints[j].name] = static_cast<int>(j);
  }
  // The base frame is the root link's.
  std::vector<std::string> unreadable;
  const urdf::LinkConstSharedPtr root =
      root_link.empty() ? model->getRoot() : model->getLink(root_link);
  if (root) {
    CollectLink(*model, *root, -1, Eigen::Isometry3d::Identity(), chain_joint,
                urdf_dir, &out, &unreadable);
  }
  for (const auto& [name, j] : chain_joint) {
    const urdf::JointConstSharedPtr joint = model->getJoint(name);
    const urdf::LinkConstSharedPtr child =
        joint ? model->getLink(joint->child_link_name) : nullptr;
    if (!child) continue;
    CollectLink(*model, *child, j, Eigen::Isometry3d::Identity(), chain_joint,
                urdf_dir, &out, &unreadable);
  }
  std::stable_sort(out.capsules.begin(), out.capsules.end(),
                   [](const LinkCapsule& x, const LinkCapsule& y) {
                     return x.frame < y.frame;
                   });
  if (!unreadable.empty()) {
    out.capsules.clear();
    std::string list;
    for (const std::string& u : unreadable)
      list += (list.empty() ? "" : "; ") + u;
    out.warnings.push_back("URDF collision geometry not used: " + list +
                           "; the links are capsules of --link-radius");
  } else if (out.capsules.empty()) {
    out.warnings.push_back(
        "the URDF has no <collision> geometry on the chain's links; the "
        "links are capsules of --link-radius");
  }
  return out;
}

LinkGeometry ReadUrdfLinkGeometry(const std::string& path, const Robot& robot,
                                  const std::string& root_link) {
  const size_t slash = path.find_last_of('/');
  return ParseUrdfLinkGeometry(
      ReadFile(path), slash == std::string::npos ? "." : path.substr(0, slash),
      robot, root_link);
}

}  // namespace kincal
