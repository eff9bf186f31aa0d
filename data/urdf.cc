#include "data/urdf.h"

#include <tinyxml2.h>

#include <Eigen/Geometry>
#include <cmath>
#include <map>
#include <sstream>

#include "data/atomic_file.h"
#include "data/error.h"

namespace kincal {
namespace {

constexpr double kRadToDeg = 180.0 / M_PI;

struct UrdfJoint {
  std::string name, type, parent, child;
  Eigen::Isometry3d origin = Eigen::Isometry3d::Identity();  // metres
  Eigen::Vector3d axis = Eigen::Vector3d::UnitX();           // URDF default
  double lower = NAN, upper = NAN;                           // m or rad
  int line = 0;
};

Eigen::Vector3d ParseTriple(const std::string& file, int line, const char* text,
                            const std::string& what) {
  std::istringstream is(text ? text : "");
  Eigen::Vector3d v;
  if (!(is >> v.x() >> v.y() >> v.z())) {
    throw InputError(file, line, 0,
                     what + ": expected three numbers, got '" +
                         std::string(text ? text : "") + "'");
  }
  std::string rest;
  if (is >> rest) {
    throw InputError(file, line, 0, what + ": more than three numbers");
  }
  return v;
}

Eigen::Matrix3d RpyToMatrix(const Eigen::Vector3d& rpy) {
  return (Eigen::AngleAxisd(rpy.z(), Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(rpy.y(), Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(rpy.x(), Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

// Inverse of RpyToMatrix (R = Rz(yaw) Ry(pitch) Rx(roll)).
Eigen::Vector3d MatrixToRpy(const Eigen::Matrix3d& r) {
  const double pitch = std::atan2(-r(2, 0), std::hypot(r(0, 0), r(1, 0)));
  const double roll = std::atan2(r(2, 1), r(2, 2));
  const double yaw = std::atan2(r(1, 0), r(0, 0));
  return Eigen::Vector3d(roll, pitch, yaw);
}

void SetOrigin(const Eigen::Isometry3d& origin_m, RobotRow* row) {
  row->xyz_mm = origin_m.translation() * 1000.0;
  row->rpy_deg = MatrixToRpy(origin_m.linear()) * kRadToDeg;
}

}  // namespace

Robot ParseUrdfChain(const std::string& xml, const std::string& file,
                     const std::string& root_link,
                     const std::string& tip_link) {
  tinyxml2::XMLDocument doc;
  if (doc.Parse(xml.c_str(), xml.size()) != tinyxml2::XML_SUCCESS) {
    throw InputError(file, doc.ErrorLineNum(), 0,
                     std::string("invalid XML: ") + doc.ErrorStr());
  }
  const tinyxml2::XMLElement* robot_el = doc.FirstChildElement("robot");
  if (!robot_el) throw InputError(file, 0, 0, "expected a <robot> element");

  std::map<std::string, UrdfJoint> by_child;
  std::map<std::string, std::vector<std::string>> children;  // link -> links
  std::map<std::string, bool> links;
  for (auto* l = robot_el->FirstChildElement("link"); l;
       l = l->NextSiblingElement("link")) {
    const char* name = l->Attribute("name");
    if (!name)
      throw InputError(file, l->GetLineNum(), 0, "<link> without name");
    links[name] = true;
  }
  for (auto* j = robot_el->FirstChildElement("joint"); j;
       j = j->NextSiblingElement("joint")) {
    UrdfJoint uj;
    uj.line = j->GetLineNum();
    const char* name = j->Attribute("name");
    const char* type = j->Attribute("type");
    if (!name || !type) {
      throw InputError(file, uj.line, 0, "<joint> needs name and type");
    }
    uj.name = name;
    uj.type = type;
    if (uj.type != "revolute" && uj.type != "continuous" &&
        uj.type != "prismatic" && uj.type != "fixed") {
      throw InputError(file, uj.line, 0,
                       "joint '" + uj.name + "': type '" + uj.type +
                           "' is not supported (revolute, continuous, "
                           "prismatic, fixed)");
    }
    const auto* parent = j->FirstChildElement("parent");
    const auto* child = j->FirstChildElement("child");
    if (!parent || !child || !parent->Attribute("link") ||
        !child->Attribute("link")) {
      throw InputError(
          file, uj.line, 0,
          "joint '" + uj.name + "': needs <parent link> and <child link>");
    }
    uj.parent = parent->Attribute("link");
    uj.child = child->Attribute("link");
    if (const auto* o = j->FirstChildElement("origin")) {
      Eigen::Vector3d xyz = Eigen::Vector3d::Zero(),
                      rpy = Eigen::Vector3d::Zero();
      if (o->Attribute("xyz"))
        xyz = ParseTriple(file, o->GetLineNum(), o->Attribute("xyz"),
                          "origin xyz");
      if (o->Attribute("rpy"))
        rpy = ParseTriple(file, o->GetLineNum(), o->Attribute("rpy"),
                          "origin rpy");
      if (!(xyz.cwiseAbs().maxCoeff() <= 100.0)) {
        throw InputError(file, o->GetLineNum(), 0,
                         "origin xyz: expected each coordinate within +-100 m");
      }
      uj.origin.linear() = RpyToMatrix(rpy);
      uj.origin.translation() = xyz;
    }
    // ROS semantics: the axis of a fixed joint is ignored (ROS-Industrial
    // files carry <axis xyz="0 0 0"/> on flange and tool0 joints).
    const auto* a = j->FirstChildElement("axis");
    if (a != nullptr && uj.type != "fixed") {
      uj.axis =
          ParseTriple(file, a->GetLineNum(), a->Attribute("xyz"), "axis xyz");
      if (uj.axis.norm() < 1e-12) {
        throw InputError(file, a->GetLineNum(), 0, "axis must not be zero");
      }
      uj.axis.normalize();
    }
    if (const auto* lim = j->FirstChildElement("limit")) {
      lim->QueryDoubleAttribute("lower", &uj.lower);
      lim->QueryDoubleAttribute("upper", &uj.upper);
    }
    if (by_child.count(uj.child)) {
      throw InputError(file, uj.line, 0,
                       "link '" + uj.child + "' has two parent joints");
    }
    children[uj.parent].push_back(uj.child);
    by_child[uj.child] = uj;
  }

  // Root: given, or the one link that is nobody's child.
  std::string root = root_link;
  if (root.empty()) {
    for (const auto& l : links) {
      if (!by_child.count(l.first)) {
        if (!root.empty()) {
          throw InputError(file, 0, 0,
                           "several root links ('" + root + "', '" + l.first +
                               "'): name one with --root");
        }
        root = l.first;
      }
    }
  }
  if (!links.count(root)) {
    throw InputError(file, 0, 0, "no link named '" + root + "'");
  }
  std::string tip = tip_link;
  if (tip.empty()) {
    tip = root;
    while (children.count(tip)) {
      if (children[tip].size() != 1) {
        throw InputError(file, 0, 0,
                         "link '" + tip + "' branches: name the tip link");
      }
      tip = children[tip][0];
    }
  }
  if (!links.count(tip))
    throw InputError(file, 0, 0, "no link named '" + tip + "'");

  // Walk back from the tip to the root.
  std::vector<UrdfJoint> path;
  for (std::string link = tip; link != root;) {
    auto it = by_child.find(link);
    if (it == by_child.end()) {
      throw InputError(file, 0, 0,
                       "link '" + tip + "' is not below '" + root + "'");
    }
    path.insert(path.begin(), it->second);
    link = it->second.parent;
  }

  Robot robot;
  robot.name =
      robot_el->Attribute("name") ? robot_el->Attribute("name") : "urdf";
  robot.convention = Convention::kUrdf;
  // A URDF carries no admissible deviation. Its nominal values come from
  // CAD, and the tool at its end (a ball, a probe, a gripper finger) is
  // often mounted several millimetres off: MUKCa's Panda balls sit 7 mm
  // from the nominal one. 20 mm / 10 deg keeps the fit physical without
  // pinning such a tool to the bound.
  robot.bound_length_mm = 20.0;
  robot.bound_angle_deg = 10.0;
  Eigen::Isometry3d pending = Eigen::Isometry3d::Identity();
  for (const UrdfJoint& uj : path) {
    if (uj.type == "fixed") {
      pending = pending * uj.origin;
      continue;
    }
    RobotRow row;
    row.name = uj.name;
    row.type =
        uj.type == "prismatic" ? JointType::kPrismatic : JointType::kRevolute;
    SetOrigin(pending * uj.origin, &row);
    row.axis = uj.axis;
    if (uj.type != "continuous" && uj.lower == uj.lower &&
        uj.upper == uj.upper && uj.lower < uj.upper) {
      const double scale =
          row.type == JointType::kPrismatic ? 1000.0 : kRadToDeg;
      row.lower = uj.lower * scale;
      row.upper = uj.upper * scale;
    }
    robot.joints.push_back(row);
    pending = Eigen::Isometry3d::Identity();
  }
  if (robot.joints.empty()) {
    throw InputError(
        file, 0, 0,
        "no movable joint between '" + root + "' and '" + tip + "'");
  }
  robot.tool.name = "tool";
  robot.tool.type = JointType::kFixed;
  SetOrigin(pending, &robot.tool);
  return robot;
}

Robot ReadUrdfChain(const std::string& path, const std::string& root_link,
                    const std::string& tip_link) {
  return ParseUrdfChain(ReadFile(path), path, root_link, tip_link);
}

Robot ReadRobot(const std::string& path, const std::string& root_link,
                const std::string& tip_link) {
  const std::string ext = ".urdf";
  if (path.size() >= ext.size() &&
      path.compare(path.size() - ext.size(), ext.size(), ext) == 0) {
    return ReadUrdfChain(path, root_link, tip_link);
  }
  return ReadRobotYaml(path);
}

}  // namespace kincal
