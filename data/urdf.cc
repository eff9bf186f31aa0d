#include "data/urdf.h"

#include <console_bridge/console.h>
#include <tinyxml2.h>
#include <urdf_parser/urdf_parser.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstring>
#include <map>
#include <mutex>
#include <regex>
#include <sstream>
#include <vector>

#include "data/atomic_file.h"
#include "data/error.h"

// Who does what (docs/URDF.md):
//  - urdfdom (liburdfdom, what ROS's urdf package and check_urdf use) decides
//    what a URDF means: joint types, default axis (1, 0, 0), limits required
//    on revolute/prismatic joints, mimic, <inertial>, unique names, the tree
//    and its root, rpy. kincal accepts and rejects what ROS does.
//  - tinyxml2 runs first and gives locations: urdfdom reports no line
//    numbers, and it accepts a few things kincal must refuse (a zero axis on
//    a movable joint, a negative mass, an <inertial> it could not read, which
//    it drops with a log message). Its checks keep today's messages.
//  - This file turns the model into kincal's serial chain: fixed joints
//    folded, inertials lumped, floating/planar and mimic joints on the chain
//    refused.

namespace kincal {
namespace {

constexpr double kRadToDeg = 180.0 / M_PI;
constexpr double kMaxLengthM = 100.0;  // a robot link is shorter than 100 m
constexpr double kMaxMassKg = 1e4;

// ---- locations -------------------------------------------------------------

// 1-based column of `needle` in line `line` of `text`, 0 when not found.
int ColumnOf(const std::string& text, int line, const std::string& needle) {
  if (line <= 0) return 0;
  size_t start = 0;
  for (int l = 1; l < line; ++l) {
    start = text.find('\n', start);
    if (start == std::string::npos) return 0;
    ++start;
  }
  const size_t end = text.find('\n', start);
  const std::string row = text.substr(
      start, end == std::string::npos ? std::string::npos : end - start);
  const size_t at = row.find(needle);
  return at == std::string::npos ? 0 : static_cast<int>(at) + 1;
}

struct Locator {
  const std::string& text;
  const std::string& file;
  [[noreturn]] void Fail(const tinyxml2::XMLElement* el,
                         const std::string& needle,
                         const std::string& message) const {
    const int line = el ? el->GetLineNum() : 0;
    throw InputError(file, line, ColumnOf(text, line, needle), message);
  }
};

// ---- tinyxml2 pre-pass: locations and kincal's own checks -------------------

bool ParseNumbers(const char* text, int n, double* out) {
  std::istringstream is(text ? text : "");
  is.imbue(std::locale::classic());
  for (int i = 0; i < n; ++i) {
    if (!(is >> out[i]) || !std::isfinite(out[i])) return false;
  }
  std::string rest;
  return !(is >> rest);
}

Eigen::Vector3d Triple(const Locator& loc, const tinyxml2::XMLElement* el,
                       const char* attr, const std::string& what) {
  const char* text = el->Attribute(attr);
  std::istringstream is(text ? text : "");
  Eigen::Vector3d v;
  if (!(is >> v.x() >> v.y() >> v.z()) || !v.allFinite()) {
    loc.Fail(el, std::string(attr) + "=",
             what + ": expected three numbers, got '" +
                 std::string(text ? text : "") + "'");
  }
  std::string rest;
  if (is >> rest)
    loc.Fail(el, std::string(attr) + "=", what + ": more than three numbers");
  return v;
}

void CheckOrigin(const Locator& loc, const tinyxml2::XMLElement* parent,
                 const std::string& what) {
  const auto* o = parent->FirstChildElement("origin");
  if (!o) return;
  if (o->Attribute("xyz")) {
    const Eigen::Vector3d xyz = Triple(loc, o, "xyz", what + " origin xyz");
    if (!(xyz.cwiseAbs().maxCoeff() <= kMaxLengthM)) {
      loc.Fail(o, "xyz=",
               what + " origin xyz: expected each coordinate within +-100 m");
    }
  }
  if (o->Attribute("rpy")) Triple(loc, o, "rpy", what + " origin rpy");
}

void CheckNumberAttr(const Locator& loc, const tinyxml2::XMLElement* el,
                     const char* attr, const std::string& what) {
  if (!el->Attribute(attr)) return;
  double v;
  if (!ParseNumbers(el->Attribute(attr), 1, &v)) {
    loc.Fail(el, std::string(attr) + "=",
             what + " " + attr + ": expected a number, got '" +
                 el->Attribute(attr) + "'");
  }
}

bool IsXacro(const tinyxml2::XMLElement* el) {
  for (const auto* a = el->FirstAttribute(); a; a = a->Next()) {
    if (std::string(a->Name()).rfind("xmlns:xacro", 0) == 0) return true;
    if (std::string(a->Value()).find("${") != std::string::npos) return true;
  }
  return std::string(el->Name()).rfind("xacro:", 0) == 0;
}

struct Lines {
  std::map<std::string, const tinyxml2::XMLElement*> joints, links;
  const tinyxml2::XMLElement* robot = nullptr;
};

// urdfdom passes names and values it complains about to console_bridge as
// part of a printf format: a '%' there (a material named "or%nge" with a bad
// colour) is read as a conversion and crashed the parser (fuzz finding). No
// URDF name or number contains '%', so the file is refused before urdfdom
// sees it.
void RejectPercent(const Locator& loc, const tinyxml2::XMLElement* el) {
  for (const tinyxml2::XMLAttribute* a = el->FirstAttribute(); a;
       a = a->Next()) {
    if (std::strchr(a->Value(), '%')) {
      loc.Fail(el, std::string(a->Name()) + "=",
               std::string("<") + el->Name() + "> attribute " + a->Name() +
                   ": '%' is not allowed in URDF names and values");
    }
  }
  if (el->GetText() && std::strchr(el->GetText(), '%')) {
    loc.Fail(el, std::string("<") + el->Name(),
             std::string("<") + el->Name() +
                 "> text: '%' is not allowed in URDF names and values");
  }
  for (auto* c = el->FirstChildElement(); c; c = c->NextSiblingElement())
    RejectPercent(loc, c);
}

void PrePass(const Locator& loc, const tinyxml2::XMLDocument& doc,
             Lines* lines) {
  const tinyxml2::XMLElement* robot_el = doc.FirstChildElement("robot");
  if (!robot_el) {
    throw InputError(loc.file, 0, 0, "expected a <robot> element");
  }
  lines->robot = robot_el;
  RejectPercent(loc, robot_el);
  if (IsXacro(robot_el)) {
    loc.Fail(robot_el, "<robot",
             "this is a xacro file, not URDF: expand it first (xacro in.xacro "
             "> robot.urdf)");
  }
  for (auto* el = robot_el->FirstChildElement(); el;
       el = el->NextSiblingElement()) {
    if (IsXacro(el)) {
      loc.Fail(el, "<",
               std::string("unexpanded xacro element <") + el->Name() +
                   ">: expand the file first (xacro in.xacro > robot.urdf)");
    }
  }
  for (auto* l = robot_el->FirstChildElement("link"); l;
       l = l->NextSiblingElement("link")) {
    const char* name = l->Attribute("name");
    if (!name) loc.Fail(l, "<link", "<link> without name");
    lines->links[name] = l;
    const std::string what = std::string("link '") + name + "'";
    for (auto* in = l->FirstChildElement("inertial"); in;
         in = in->NextSiblingElement("inertial")) {
      CheckOrigin(loc, in, what + " inertial");
      const auto* m = in->FirstChildElement("mass");
      if (!m) loc.Fail(in, "<inertial", what + ": <inertial> without <mass>");
      double mass = 0.0;
      if (!ParseNumbers(m->Attribute("value"), 1, &mass) ||
          !(mass >= 0.0 && mass <= kMaxMassKg)) {
        loc.Fail(m, "value=",
                 what + " mass: expected a value in kg, 0..10000, got '" +
                     std::string(m->Attribute("value") ? m->Attribute("value")
                                                       : "") +
                     "'");
      }
      if (!in->FirstChildElement("inertia")) {
        loc.Fail(in, "<inertial",
                 what + ": <inertial> without <inertia> (urdfdom drops it)");
      }
    }
  }
  std::map<std::string, std::string> parent_of;  // child link -> parent link
  std::vector<const tinyxml2::XMLElement*> joint_els;
  for (auto* j = robot_el->FirstChildElement("joint"); j;
       j = j->NextSiblingElement("joint")) {
    const char* name = j->Attribute("name");
    const char* type_c = j->Attribute("type");
    if (!name || !type_c) loc.Fail(j, "<joint", "<joint> needs name and type");
    lines->joints[name] = j;
    const std::string type = type_c;
    const std::string what = std::string("joint '") + name + "'";
    if (type != "revolute" && type != "continuous" && type != "prismatic" &&
        type != "fixed" && type != "floating" && type != "planar") {
      loc.Fail(j, "type=",
               what + ": type '" + type +
                   "' is not a URDF joint type (revolute, continuous, "
                   "prismatic, fixed, floating, planar)");
    }
    const auto* parent = j->FirstChildElement("parent");
    const auto* child = j->FirstChildElement("child");
    if (!parent || !child || !parent->Attribute("link") ||
        !child->Attribute("link")) {
      loc.Fail(j, "<joint", what + ": needs <parent link> and <child link>");
    }
    if (!parent_of.emplace(child->Attribute("link"), parent->Attribute("link"))
             .second) {
      loc.Fail(j, "<joint",
               std::string("link '") + child->Attribute("link") +
                   "' has two parent joints");
    }
    joint_els.push_back(j);
    CheckOrigin(loc, j, what);
    // ROS semantics: the axis of a fixed (and floating) joint is ignored;
    // ROS-Industrial files carry <axis xyz="0 0 0"/> on flange and tool0.
    const auto* a = j->FirstChildElement("axis");
    if (a && type != "fixed" && type != "floating") {
      const Eigen::Vector3d axis = Triple(loc, a, "xyz", what + " axis xyz");
      if (!std::isfinite(axis.norm())) {
        loc.Fail(a, "xyz=", what + ": axis length overflows");
      }
      if (!(axis.norm() >= 1e-12)) {
        loc.Fail(a, "xyz=", what + ": axis must not be zero");
      }
    }
    if (const auto* lim = j->FirstChildElement("limit")) {
      for (const char* attr : {"lower", "upper", "effort", "velocity"}) {
        CheckNumberAttr(loc, lim, attr, what + " limit");
      }
    }
    if (const auto* mim = j->FirstChildElement("mimic")) {
      if (!mim->Attribute("joint")) {
        loc.Fail(mim, "<mimic", what + ": <mimic> needs a joint attribute");
      }
      CheckNumberAttr(loc, mim, "multiplier", what + " mimic");
      CheckNumberAttr(loc, mim, "offset", what + " mimic");
    }
  }
  // A URDF is a tree. urdfdom 3.0.1 accepts a joint whose child is its own
  // ancestor (a loop cut off from the root), which would leave links with
  // no way down from the root.
  for (const auto* j : joint_els) {
    const std::string child = j->FirstChildElement("child")->Attribute("link");
    std::string up = j->FirstChildElement("parent")->Attribute("link");
    for (size_t steps = 0; steps <= parent_of.size(); ++steps) {
      if (up == child) {
        loc.Fail(j, "<joint",
                 std::string("joint '") + j->Attribute("name") +
                     "' closes a loop (link '" + child +
                     "' is its own ancestor): a URDF describes a tree");
      }
      const auto it = parent_of.find(up);
      if (it == parent_of.end()) break;
      up = it->second;
    }
  }
}

// ---- urdfdom ---------------------------------------------------------------

// Collects urdfdom's console_bridge messages instead of printing them.
class Capture : public console_bridge::OutputHandler {
 public:
  void log(const std::string& text, console_bridge::LogLevel level, const char*,
           int) override {
    if (level >= console_bridge::CONSOLE_BRIDGE_LOG_ERROR) {
      errors_.push_back(text);
    }
  }
  const std::vector<std::string>& errors() const { return errors_; }

 private:
  std::vector<std::string> errors_;
};

// The element a urdfdom message is about: the joint or link it names.
const tinyxml2::XMLElement* Subject(const Lines& lines,
                                    const std::string& message,
                                    std::string* needle) {
  static const std::regex joint_re(R"([Jj]oint\s+(?:\[([^\]]*)\]|'([^']*)'))");
  static const std::regex link_re(R"([Ll]ink\s+(?:\[([^\]]*)\]|'([^']*)'))");
  static const std::regex any_re(R"(\[([^\]]*)\])");
  std::smatch m;
  auto name_of = [&](const std::smatch& s) {
    return s[1].matched ? s[1].str() : s[2].str();
  };
  if (std::regex_search(message, m, joint_re)) {
    const auto it = lines.joints.find(name_of(m));
    if (it != lines.joints.end()) {
      *needle = "<joint";
      return it->second;
    }
  }
  if (std::regex_search(message, m, link_re)) {
    const auto it = lines.links.find(name_of(m));
    if (it != lines.links.end()) {
      *needle = "<link";
      return it->second;
    }
  }
  if (std::regex_search(message, m, any_re)) {
    const std::string name = m[1].str();
    if (lines.links.count(name)) {
      *needle = "<link";
      return lines.links.at(name);
    }
    if (lines.joints.count(name)) {
      *needle = "<joint";
      return lines.joints.at(name);
    }
  }
  *needle = "<robot";
  return lines.robot;
}

urdf::ModelInterfaceSharedPtr ParseWithUrdfdom(const Locator& loc,
                                               const Lines& lines) {
  // console_bridge's handler is process-wide.
  static std::mutex mutex;
  std::lock_guard<std::mutex> lock(mutex);
  Capture capture;
  console_bridge::useOutputHandler(&capture);
  urdf::ModelInterfaceSharedPtr model;
  std::string thrown;
  try {
    model = urdf::parseURDF(loc.text);
  } catch (const std::exception& e) {
    thrown = e.what();
  }
  console_bridge::restorePreviousOutputHandler();
  std::vector<std::string> errors = capture.errors();
  if (!thrown.empty()) errors.push_back(thrown);
  if (model && errors.empty()) return model;
  if (errors.empty()) errors.push_back("not a valid URDF");
  std::string message = "URDF rejected (urdfdom): ";
  for (size_t i = 0; i < errors.size(); ++i) {
    message += (i ? "; " : "") + errors[i];
  }
  std::string needle;
  const tinyxml2::XMLElement* el = Subject(lines, errors.front(), &needle);
  loc.Fail(el, needle, message);
}

// ---- model -> chain
// ----------------------------------------------------------

Eigen::Isometry3d ToIsometry(const urdf::Pose& p) {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.linear() =
      Eigen::Quaterniond(p.rotation.w, p.rotation.x, p.rotation.y, p.rotation.z)
          .normalized()
          .toRotationMatrix();
  t.translation() = Eigen::Vector3d(p.position.x, p.position.y, p.position.z);
  return t;
}

// Inverse of R = Rz(yaw) Ry(pitch) Rx(roll) (URDF rpy).
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

std::string JoinLeaves(const urdf::ModelInterface& model,
                       const std::string& from) {
  std::vector<std::string> leaves;
  std::vector<std::string> stack = {from};
  while (!stack.empty()) {
    const auto link = model.getLink(stack.back());
    stack.pop_back();
    if (link->child_links.empty()) leaves.push_back(link->name);
    for (const auto& c : link->child_links) stack.push_back(c->name);
  }
  std::string out;
  for (size_t i = 0; i < leaves.size() && i < 8; ++i) {
    out += (i ? ", " : "") + leaves[i];
  }
  if (leaves.size() > 8) out += ", ...";
  return out;
}

// True when the link's subtree (the link's own parent joint excluded) holds a
// joint that is not fixed.
bool HasMovableJoint(const urdf::ModelInterface& model,
                     const std::string& from) {
  std::vector<std::string> stack = {from};
  while (!stack.empty()) {
    const auto link = model.getLink(stack.back());
    stack.pop_back();
    for (const auto& j : link->child_joints) {
      if (j->type != urdf::Joint::FIXED) return true;
    }
    for (const auto& c : link->child_links) stack.push_back(c->name);
  }
  return false;
}

// Number of leaf links named `name` below `from`.
int LeafCount(const urdf::ModelInterface& model, const std::string& from,
              const std::string& name) {
  int count = 0;
  std::vector<std::string> stack = {from};
  while (!stack.empty()) {
    const auto link = model.getLink(stack.back());
    stack.pop_back();
    if (link->child_links.empty() && link->name == name) ++count;
    for (const auto& c : link->child_links) stack.push_back(c->name);
  }
  return count;
}

const char* TypeName(int type) {
  switch (type) {
    case urdf::Joint::FLOATING:
      return "floating";
    case urdf::Joint::PLANAR:
      return "planar";
    default:
      return "unknown";
  }
}

// The tip when none is named: down from the root; at a branch, follow the
// one child whose subtree holds a movable joint (a ROS-Industrial `base`
// frame beside link_1 does not count).
std::string DefaultTip(const urdf::ModelInterface& model,
                       const std::string& root, const std::string& file) {
  std::string tip = root;
  for (auto link = model.getLink(tip); !link->child_links.empty();
       link = model.getLink(tip)) {
    std::vector<std::string> moving;
    for (const auto& c : link->child_links) {
      if (c->parent_joint->type != urdf::Joint::FIXED ||
          HasMovableJoint(model, c->name)) {
        moving.push_back(c->name);
      }
    }
    if (link->child_links.size() == 1) {
      tip = link->child_links[0]->name;
    } else if (moving.size() == 1) {
      tip = moving[0];
    } else if (moving.empty() && LeafCount(model, tip, "tool0") == 1) {
      // Only fixed frames left (ROS-I: flange, tool0, ee_link): tool0 is
      // REP 199's attachment frame.
      tip = "tool0";
      break;
    } else {
      throw InputError(file, 0, 0,
                       "link '" + tip +
                           "' branches: name the tip link with --tip (leaf "
                           "links: " +
                           JoinLeaves(model, tip) + ")");
    }
  }
  return tip;
}

// The joints from the root to the tip.
std::vector<urdf::JointConstSharedPtr> ChainPath(
    const urdf::ModelInterface& model, const std::string& root,
    const std::string& tip, const std::string& file) {
  std::vector<urdf::JointConstSharedPtr> path;
  for (auto link = model.getLink(tip); link->name != root;) {
    if (!link->parent_joint) {
      throw InputError(file, 0, 0,
                       "link '" + tip + "' is not below '" + root + "'");
    }
    path.insert(path.begin(), link->parent_joint);
    link = model.getLink(link->parent_joint->parent_link_name);
  }
  return path;
}

// One robot.yaml row per movable joint of `path`, fixed joints folded into
// the next row (the rest into robot->tool); returns each movable joint's
// row index.
std::map<std::string, int> ChainRows(
    const Locator& loc, const Lines& lines,
    const std::vector<urdf::JointConstSharedPtr>& path, Robot* robot) {
  auto joint_el = [&](const std::string& name) {
    return lines.joints.count(name) ? lines.joints.at(name) : lines.robot;
  };
  std::map<std::string, int> row_of_joint;
  Eigen::Isometry3d pending = Eigen::Isometry3d::Identity();
  for (const auto& j : path) {
    const Eigen::Isometry3d origin =
        ToIsometry(j->parent_to_joint_origin_transform);
    if (j->type == urdf::Joint::FIXED) {
      pending = pending * origin;
      continue;
    }
    if (j->type == urdf::Joint::FLOATING || j->type == urdf::Joint::PLANAR) {
      loc.Fail(joint_el(j->name), "type=",
               "joint '" + j->name + "' is " + TypeName(j->type) +
                   ": kincal models serial chains of revolute, continuous, "
                   "prismatic and fixed joints (choose --root below it)");
    }
    if (j->mimic) {
      loc.Fail(joint_el(j->name), "<joint",
               "joint '" + j->name + "' mimics '" + j->mimic->joint_name +
                   "' (q = multiplier * q_master + offset): kincal's chain "
                   "has one reading per movable joint and cannot express "
                   "a coupled joint on the chain; choose --tip so the chain "
                   "avoids it");
    }
    RobotRow row;
    row.name = j->name;
    row.type = j->type == urdf::Joint::PRISMATIC ? JointType::kPrismatic
                                                 : JointType::kRevolute;
    SetOrigin(pending * origin, &row);
    row.axis = Eigen::Vector3d(j->axis.x, j->axis.y, j->axis.z).normalized();
    if (j->type != urdf::Joint::CONTINUOUS && j->limits &&
        j->limits->lower < j->limits->upper) {
      const double scale =
          row.type == JointType::kPrismatic ? 1000.0 : kRadToDeg;
      // Beyond +-1e5 (deg or mm; robot.yaml's range) a limit means "none".
      if (std::abs(j->limits->lower * scale) <= 1e5 &&
          std::abs(j->limits->upper * scale) <= 1e5) {
        row.lower = j->limits->lower * scale;
        row.upper = j->limits->upper * scale;
      }
    }
    row_of_joint[j->name] = static_cast<int>(robot->joints.size());
    robot->joints.push_back(row);
    pending = Eigen::Isometry3d::Identity();
  }
  robot->tool.name = "tool";
  robot->tool.type = JointType::kFixed;
  SetOrigin(pending, &robot->tool);
  return row_of_joint;
}

// Inertials: every link whose way up to the root meets a movable joint of
// the chain rides on that joint's row. Its mass is lumped into the row (sum
// of masses, mass-weighted centre of mass in the frame after the row = that
// joint's child link). Joints off the chain (a gripper's fingers) count at
// their zero position; links that reach the root without a movable chain
// joint (the base) carry no row and are left out.
void LumpInertials(const urdf::ModelInterface& model, const std::string& root,
                   const std::map<std::string, int>& row_of_joint,
                   Robot* robot) {
  const size_t rows = robot->joints.size();
  std::vector<double> mass(rows, 0.0);
  std::vector<Eigen::Vector3d> moment(rows, Eigen::Vector3d::Zero());
  std::vector<bool> has(rows, false);
  std::vector<urdf::LinkSharedPtr> links;
  model.getLinks(links);
  for (const auto& link : links) {
    if (!link->inertial) continue;
    Eigen::Vector3d com = ToIsometry(link->inertial->origin).translation();
    int row = -1;
    for (urdf::LinkConstSharedPtr l = link; l && l->parent_joint;
         l = model.getLink(l->parent_joint->parent_link_name)) {
      const auto it = row_of_joint.find(l->parent_joint->name);
      if (it != row_of_joint.end()) {
        row = it->second;
        break;
      }
      if (l->name == root) break;
      com = ToIsometry(l->parent_joint->parent_to_joint_origin_transform) * com;
    }
    if (row < 0) continue;
    mass[row] += link->inertial->mass;
    moment[row] += link->inertial->mass * com;
    has[row] = true;
  }
  for (size_t r = 0; r < rows; ++r) {
    if (!has[r]) continue;
    robot->joints[r].mass_kg = mass[r];
    robot->joints[r].com_mm =
        mass[r] > 0 ? Eigen::Vector3d(moment[r] / mass[r] * 1000.0)
                    : Eigen::Vector3d::Zero();
  }
}

}  // namespace

Robot ParseUrdfChain(const std::string& xml, const std::string& file,
                     const std::string& root_link,
                     const std::string& tip_link) {
  const Locator loc{xml, file};
  tinyxml2::XMLDocument doc;
  if (doc.Parse(xml.c_str(), xml.size()) != tinyxml2::XML_SUCCESS) {
    throw InputError(file, doc.ErrorLineNum(), 0,
                     std::string("invalid XML: ") + doc.ErrorStr());
  }
  Lines lines;
  PrePass(loc, doc, &lines);
  const urdf::ModelInterfaceSharedPtr model = ParseWithUrdfdom(loc, lines);
  const std::string root =
      root_link.empty() ? model->getRoot()->name : root_link;
  if (!model->getLink(root)) {
    throw InputError(file, 0, 0, "no link named '" + root + "'");
  }
  const std::string tip =
      tip_link.empty() ? DefaultTip(*model, root, file) : tip_link;
  if (!model->getLink(tip)) {
    throw InputError(file, 0, 0, "no link named '" + tip + "'");
  }
  const std::vector<urdf::JointConstSharedPtr> path =
      ChainPath(*model, root, tip, file);

  Robot robot;
  robot.name = model->getName().empty() ? "urdf" : model->getName();
  robot.convention = Convention::kUrdf;
  // A URDF carries no admissible deviation. Its nominal values come from
  // CAD, and the tool at its end (a ball, a probe, a gripper finger) is
  // often mounted several millimetres off: MUKCa's Panda balls sit 7 mm
  // from the nominal one. 20 mm / 10 deg keeps the fit physical without
  // pinning such a tool to the bound.
  robot.bound_length_mm = 20.0;
  robot.bound_angle_deg = 10.0;
  const std::map<std::string, int> row_of_joint =
      ChainRows(loc, lines, path, &robot);
  if (robot.joints.empty()) {
    throw InputError(
        file, 0, 0,
        "no movable joint between '" + root + "' and '" + tip + "'");
  }
  LumpInertials(*model, root, row_of_joint, &robot);
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
