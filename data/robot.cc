#include "data/robot.h"

#include <algorithm>
#include <cmath>
#include <set>
#include <sstream>
#include <stdexcept>

#include "data/atomic_file.h"
#include "data/error.h"
#include "data/extension_kinds.h"
#include "data/provenance.h"
#include "data/yaml_util.h"

namespace kincal {

const char* ToString(JointType type) {
  switch (type) {
    case JointType::kRevolute:
      return "revolute";
    case JointType::kPrismatic:
      return "prismatic";
    case JointType::kFixed:
      return "fixed";
  }
  return "?";
}

const char* ToString(Convention convention) {
  switch (convention) {
    case Convention::kDh:
      return "dh";
    case Convention::kMdh:
      return "mdh";
    case Convention::kUrdf:
      return "urdf";
  }
  return "?";
}

int Robot::JointIndex(const std::string& joint_name) const {
  for (size_t i = 0; i < joints.size(); ++i) {
    if (joints[i].name == joint_name) return static_cast<int>(i);
  }
  return -1;
}

std::vector<std::string> Robot::JointNames() const {
  std::vector<std::string> names;
  for (const auto& j : joints) names.push_back(j.name);
  return names;
}

namespace {
// Copies the geometry fields of `from` into `to` (names, limits and masses
// stay `to`'s).
void CopyGeometry(const RobotRow& from, RobotRow* to) {
  to->theta_deg = from.theta_deg;
  to->d_mm = from.d_mm;
  to->a_mm = from.a_mm;
  to->alpha_deg = from.alpha_deg;
  to->beta_deg = from.beta_deg;
  to->xyz_mm = from.xyz_mm;
  to->rpy_deg = from.rpy_deg;
  to->axis = from.axis;
}
}  // namespace

Robot Robot::Nominal() const {
  if (!HasNominal()) throw std::logic_error("robot has no nominal rows");
  Robot out = *this;
  for (size_t i = 0; i < joints.size(); ++i) {
    CopyGeometry(nominal_joints[i], &out.joints[i]);
  }
  CopyGeometry(nominal_tool, &out.tool);
  out.extensions.clear();
  out.fitted_on = FitRecord{};
  return out;
}

void Robot::SetNominal(const Robot& nominal) {
  const Robot& source = nominal.HasNominal() ? nominal.Nominal() : nominal;
  nominal_joints = source.joints;
  nominal_tool = source.tool;
}

namespace {

// Fields every extension cause may carry (interface units, see robot.h).
const std::map<std::string, std::vector<std::string>>& ExtensionFields() {
  static const std::map<std::string, std::vector<std::string>> fields = {
      {"backlash", {"width"}},       {"compliance", {"per_torque"}},
      {"cyclic", {"cos", "sin"}},    {"gain", {"g"}},
      {"drift", {"vx", "vy", "vz"}}, {"elastostatic", {"per_knm"}},
      {"thermal", {"rate"}},         {"mount_compliance", {"iso"}},
      {"transmission", {"lo", "hi"}}};
  return fields;
}

// Fields a cause may carry in addition (higher harmonics of cyclic).
const std::vector<std::string>& OptionalFields(const std::string& cause) {
  static const std::vector<std::string> cyclic = {"cos2", "sin2", "cos3",
                                                  "sin3"};
  static const std::vector<std::string> mount = {"aniso_cos", "aniso_sin"};
  static const std::vector<std::string> none;
  static const std::vector<std::string> transmission = [] {
    // s1 .. s24: sine series over the travel; a1 .. a32, b1 .. b32: the
    // Fourier coefficients of a periodic error over the revolution.
    std::vector<std::string> v;
    for (int k = 1; k <= 24; ++k) v.push_back("s" + std::to_string(k));
    for (int k = 1; k <= 32; ++k) {
      v.push_back("a" + std::to_string(k));
      v.push_back("b" + std::to_string(k));
    }
    return v;
  }();
  if (cause == "mount_compliance") return mount;
  if (cause == "transmission") return transmission;
  return cause == "cyclic" ? cyclic : none;
}

// Physical ranges: a robot link is shorter than 100 m; angles are within
// one turn.
constexpr double kMaxLengthMm = 1e5;
constexpr double kMaxAngleDeg = 360.0;

void CheckRange(const YamlReader& r, const YAML::Node& at,
                const std::string& what, const std::vector<double>& values,
                double max_abs, const char* unit) {
  for (double v : values) {
    if (!(std::abs(v) <= max_abs)) {
      std::ostringstream os;
      os << what << ": expected values within +-" << max_abs << " " << unit
         << ", got " << v;
      r.Fail(at, os.str());
    }
  }
}

void ReadGeometry(const YamlReader& r, const YAML::Node& node,
                  Convention convention, const std::string& what,
                  RobotRow* row) {
  if (convention == Convention::kUrdf) {
    const auto xyz =
        r.Numbers(r.Required(node, "xyz", what), what + ".xyz", 3, 3);
    const auto rpy =
        r.Numbers(r.Required(node, "rpy", what), what + ".rpy", 3, 3);
    CheckRange(r, node["xyz"], what + ".xyz", xyz, kMaxLengthMm, "mm");
    CheckRange(r, node["rpy"], what + ".rpy", rpy, kMaxAngleDeg, "deg");
    row->xyz_mm = Eigen::Vector3d(xyz[0], xyz[1], xyz[2]);
    row->rpy_deg = Eigen::Vector3d(rpy[0], rpy[1], rpy[2]);
    if (row->type != JointType::kFixed) {
      const auto axis =
          r.Numbers(r.Required(node, "axis", what), what + ".axis", 3, 3);
      Eigen::Vector3d a(axis[0], axis[1], axis[2]);
      if (a.norm() < 1e-9)
        r.Fail(node["axis"], what + ".axis: must not be zero");
      row->axis = a.normalized();
    }
    return;
  }
  row->d_mm = r.Number(r.Required(node, "d", what), what + ".d");
  row->alpha_deg = r.Number(r.Required(node, "alpha", what), what + ".alpha");
  row->a_mm = r.Number(r.Required(node, "a", what), what + ".a");
  row->theta_deg = r.Number(r.Required(node, "theta", what), what + ".theta");
  row->beta_deg = r.NumberOr(node, "beta", 0.0, what);
  for (const char* key : {"d", "a"}) {
    CheckRange(r, node[key], what + "." + key, {r.Number(node[key], what)},
               kMaxLengthMm, "mm");
  }
  for (const char* key : {"alpha", "theta"}) {
    CheckRange(r, node[key], what + "." + key, {r.Number(node[key], what)},
               kMaxAngleDeg, "deg");
  }
  if (node["beta"]) {
    CheckRange(r, node["beta"], what + ".beta", {row->beta_deg}, kMaxAngleDeg,
               "deg");
  }
}

// The file's header keys: format version, name, convention, gravity.
void ReadRobotHeader(const YamlReader& r, const YAML::Node& root,
                     Robot* robot) {
  const YAML::Node version = r.Required(root, "kincal_robot", "robot file");
  if (r.Integer(version, "kincal_robot") != 1) {
    r.Fail(version, "kincal_robot: unsupported format version " +
                        version.Scalar() + " (this tool reads version 1)");
  }
  robot->name = root["name"] ? r.String(root["name"], "name") : "robot";
  const YAML::Node conv = root["convention"];
  if (conv) {
    const std::string c = r.String(conv, "convention");
    if (c == "dh")
      robot->convention = Convention::kDh;
    else if (c == "mdh")
      robot->convention = Convention::kMdh;
    else if (c == "urdf")
      robot->convention = Convention::kUrdf;
    else
      r.Fail(conv,
             "convention: expected 'dh', 'mdh' or 'urdf', got '" + c + "'");
  }
  if (root["gravity"]) {
    const auto g = r.Numbers(root["gravity"], "gravity", 3, 3);
    Eigen::Vector3d gv(g[0], g[1], g[2]);
    if (gv.norm() < 1e-12) r.Fail(root["gravity"], "gravity: must not be zero");
    robot->gravity = gv.normalized();
  }
}

// A joint's limits, mass and centre of mass.
void ReadJointExtras(const YamlReader& r, const YAML::Node& j,
                     const std::string& what, RobotRow* row) {
  if (j["limits"]) {
    const auto lim = r.Numbers(j["limits"], what + ".limits", 2, 2);
    CheckRange(r, j["limits"], what + ".limits", lim, kMaxLengthMm,
               "(mm or deg)");
    if (!(lim[0] < lim[1])) {
      r.Fail(j["limits"],
             what + ".limits: expected [lower, upper] with lower < upper");
    }
    row->lower = lim[0];
    row->upper = lim[1];
  }
  if (j["mass"]) {
    row->mass_kg = r.Number(j["mass"], what + ".mass");
    if (!(row->mass_kg >= 0.0 && row->mass_kg <= 1e4)) {
      r.Fail(j["mass"], what + ".mass: expected a link mass in kg, 0..10000");
    }
  }
  if (j["com"]) {
    if (!j["mass"]) r.Fail(j["com"], what + ".com: given without mass");
    const auto c = r.Numbers(j["com"], what + ".com", 3, 3);
    row->com_mm = Eigen::Vector3d(c[0], c[1], c[2]);
    if (!(row->com_mm.norm() <= 1e5)) {
      r.Fail(j["com"], what +
                           ".com: expected a centre of mass in mm, "
                           "within 100 m of the link frame");
    }
  }
}

// joints[i]; `names` collects the joint names so far.
RobotRow ReadJoint(const YamlReader& r, const YAML::Node& j, size_t i,
                   Convention convention, std::set<std::string>* names) {
  const std::string what = "joints[" + std::to_string(i) + "]";
  r.ExpectMap(j, what);
  r.CheckKeys(j,
              {"name", "type", "d", "alpha", "a", "theta", "beta", "xyz", "rpy",
               "axis", "limits", "mass", "com"},
              what);
  RobotRow row;
  row.name = r.String(r.Required(j, "name", what), what + ".name");
  if (row.name == "tool" || row.name == "frame" || row.name == "drift" ||
      row.name == "point") {
    r.Fail(j["name"], what + ".name: '" + row.name + "' is reserved");
  }
  if (!names->insert(row.name).second) {
    r.Fail(j["name"], what + ".name: duplicate joint name '" + row.name + "'");
  }
  const std::string type =
      r.String(r.Required(j, "type", what), what + ".type");
  if (type == "revolute")
    row.type = JointType::kRevolute;
  else if (type == "prismatic")
    row.type = JointType::kPrismatic;
  else
    r.Fail(
        j["type"],
        what + ".type: expected 'revolute' or 'prismatic', got '" + type + "'");
  ReadGeometry(r, j, convention, what, &row);
  ReadJointExtras(r, j, what, &row);
  return row;
}

// The tool row (fixed) and the admissible deviation bounds.
void ReadToolAndBounds(const YamlReader& r, const YAML::Node& root,
                       Robot* robot) {
  robot->tool.name = "tool";
  robot->tool.type = JointType::kFixed;
  if (root["tool"]) {
    const YAML::Node t = root["tool"];
    r.ExpectMap(t, "tool");
    r.CheckKeys(t, {"d", "alpha", "a", "theta", "beta", "xyz", "rpy"}, "tool");
    ReadGeometry(r, t, robot->convention, "tool", &robot->tool);
  }
  if (root["bounds"]) {
    const YAML::Node b = root["bounds"];
    r.ExpectMap(b, "bounds");
    r.CheckKeys(b, {"length", "angle"}, "bounds");
    robot->bound_length_mm = r.NumberOr(b, "length", 5.0, "bounds");
    robot->bound_angle_deg = r.NumberOr(b, "angle", 5.0, "bounds");
    robot->bounds_stated = true;
    if (!(robot->bound_length_mm > 0 && robot->bound_length_mm <= 1e4 &&
          robot->bound_angle_deg > 0 && robot->bound_angle_deg <= 180)) {
      r.Fail(b,
             "bounds: expected length in (0, 10000] mm and angle in "
             "(0, 180] deg");
    }
  }
}

// extensions[i]: a known cause, its joint, and exactly its fields.
Extension ReadExtension(const YamlReader& r, const YAML::Node& e, size_t i,
                        const Robot& robot) {
  const std::string what = "extensions[" + std::to_string(i) + "]";
  r.ExpectMap(e, what);
  Extension x;
  x.cause = r.String(r.Required(e, "cause", what), what + ".cause");
  const auto it = ExtensionFields().find(x.cause);
  if (it == ExtensionFields().end()) {
    r.Fail(e["cause"], what + ".cause: unknown cause '" + x.cause +
                           "' (expected backlash, compliance, cyclic, gain, "
                           "elastostatic, thermal, transmission, drift or "
                           "mount_compliance; axis tilt is a row's beta)");
  }
  if (x.cause != "drift" && x.cause != "mount_compliance") {
    x.joint = r.String(r.Required(e, "joint", what), what + ".joint");
    if (robot.JointIndex(x.joint) < 0) {
      r.Fail(e["joint"], what + ".joint: no joint named '" + x.joint + "'");
    }
  }
  for (const auto& kv : e) {
    const std::string key = kv.first.Scalar();
    if (key == "cause" || key == "joint") continue;
    bool known = false;
    for (const auto& f : it->second) known = known || f == key;
    for (const auto& f : OptionalFields(x.cause)) known = known || f == key;
    if (!known) {
      r.Fail(kv.first,
             what + ": unknown field '" + key + "' for cause " + x.cause);
    }
    x.values[key] = r.Number(kv.second, what + "." + key);
  }
  for (const auto& f : it->second) {
    if (!x.values.count(f)) r.Fail(e, what + ": missing field '" + f + "'");
  }
  if (x.cause == "transmission" && !(x.values.at("hi") > x.values.at("lo"))) {
    r.Fail(e["hi"], what + ": transmission travel needs hi > lo, got lo " +
                        FormatDouble(x.values.at("lo")) + ", hi " +
                        FormatDouble(x.values.at("hi")));
  }
  return x;
}

// nominal: {joints: [rows with the joints' names, in order], tool: {...}}.
void ReadNominal(const YamlReader& r, const YAML::Node& n, Robot* robot) {
  r.ExpectMap(n, "nominal");
  r.CheckKeys(n, {"joints", "tool"}, "nominal");
  const YAML::Node joints = r.Required(n, "joints", "nominal");
  r.ExpectSequence(joints, "nominal.joints");
  if (joints.size() != robot->joints.size()) {
    r.Fail(joints,
           "nominal.joints: expected " + std::to_string(robot->joints.size()) +
               " rows (one per joint), got " + std::to_string(joints.size()));
  }
  for (size_t i = 0; i < joints.size(); ++i) {
    const std::string what = "nominal.joints[" + std::to_string(i) + "]";
    const YAML::Node j = joints[i];
    r.ExpectMap(j, what);
    r.CheckKeys(
        j, {"name", "d", "alpha", "a", "theta", "beta", "xyz", "rpy", "axis"},
        what);
    RobotRow row = robot->joints[i];
    const std::string name =
        r.String(r.Required(j, "name", what), what + ".name");
    if (name != row.name) {
      r.Fail(j["name"], what + ".name: expected '" + row.name +
                            "' (the joints' order), got '" + name + "'");
    }
    ReadGeometry(r, j, robot->convention, what, &row);
    robot->nominal_joints.push_back(row);
  }
  robot->nominal_tool = robot->tool;
  const YAML::Node t = r.Required(n, "tool", "nominal");
  r.ExpectMap(t, "nominal.tool");
  r.CheckKeys(t, {"d", "alpha", "a", "theta", "beta", "xyz", "rpy"},
              "nominal.tool");
  ReadGeometry(r, t, robot->convention, "nominal.tool", &robot->nominal_tool);
}

// fitted_on: {poses, joints: {name: [lo, hi]}, temp_c: [lo, hi],
// thermal_input, heldout_rms_mm, systematic_rms_mm}.
void ReadFittedOn(const YamlReader& r, const YAML::Node& f, Robot* robot) {
  r.ExpectMap(f, "fitted_on");
  r.CheckKeys(f,
              {"poses", "joints", "gaps", "temp_c", "thermal_input", "frame",
               "series_frames", "heldout_rms_mm", "systematic_rms_mm"},
              "fitted_on");
  FitRecord& rec = robot->fitted_on;
  rec.poses = r.Integer(r.Required(f, "poses", "fitted_on"), "fitted_on.poses");
  if (rec.poses < 1) r.Fail(f["poses"], "fitted_on.poses: expected >= 1");
  if (f["joints"]) {
    const YAML::Node j = f["joints"];
    r.ExpectMap(j, "fitted_on.joints");
    rec.joint_range.assign(robot->joints.size(),
                           {std::numeric_limits<double>::quiet_NaN(),
                            std::numeric_limits<double>::quiet_NaN()});
    for (const auto& kv : j) {
      const std::string name = kv.first.Scalar();
      const int index = robot->JointIndex(name);
      if (index < 0) {
        r.Fail(kv.first, "fitted_on.joints: no joint named '" + name + "'");
      }
      const auto range = r.Numbers(kv.second, "fitted_on.joints." + name, 2, 2);
      if (!(range[1] >= range[0])) {
        r.Fail(kv.second, "fitted_on.joints." + name + ": expected [lo, hi]");
      }
      rec.joint_range[index] = {range[0], range[1]};
    }
  }
  if (f["gaps"]) {
    const YAML::Node g = f["gaps"];
    r.ExpectMap(g, "fitted_on.gaps");
    rec.joint_gap.assign(robot->joints.size(),
                         {std::numeric_limits<double>::quiet_NaN(),
                          std::numeric_limits<double>::quiet_NaN()});
    for (const auto& kv : g) {
      const std::string name = kv.first.Scalar();
      const int index = robot->JointIndex(name);
      if (index < 0) {
        r.Fail(kv.first, "fitted_on.gaps: no joint named '" + name + "'");
      }
      const auto gap = r.Numbers(kv.second, "fitted_on.gaps." + name, 2, 2);
      if (!(gap[1] > gap[0])) {
        r.Fail(kv.second, "fitted_on.gaps." + name + ": expected [from, to]");
      }
      rec.joint_gap[index] = {gap[0], gap[1]};
    }
  }
  if (f["temp_c"]) {
    const auto t = r.Numbers(f["temp_c"], "fitted_on.temp_c", 2, 2);
    rec.temp_lo_c = t[0];
    rec.temp_hi_c = t[1];
  }
  if (f["frame"]) {
    const auto v = r.Numbers(f["frame"], "fitted_on.frame", 6, 6);
    rec.has_frame = true;
    for (int k = 0; k < 6; ++k) rec.frame[k] = v[k];
  }
  if (f["series_frames"]) {
    const YAML::Node s = f["series_frames"];
    r.ExpectMap(s, "fitted_on.series_frames");
    for (const auto& kv : s) {
      const std::string name = kv.first.Scalar();
      const auto v =
          r.Numbers(kv.second, "fitted_on.series_frames." + name, 6, 6);
      std::array<double, 6> frame{};
      for (int k = 0; k < 6; ++k) frame[k] = v[k];
      rec.series_frames.emplace_back(name, frame);
    }
  }
  if (f["thermal_input"]) {
    rec.thermal_input = r.String(f["thermal_input"], "fitted_on.thermal_input");
    if (rec.thermal_input != "temp_c" && rec.thermal_input != "hours") {
      r.Fail(f["thermal_input"],
             "fitted_on.thermal_input: expected 'temp_c' or 'hours'");
    }
  }
  rec.heldout_rms_mm =
      r.NumberOr(f, "heldout_rms_mm", rec.heldout_rms_mm, "fitted_on");
  rec.systematic_rms_mm =
      r.NumberOr(f, "systematic_rms_mm", rec.systematic_rms_mm, "fitted_on");
}

// covariance.periodic_basis: {<joint>: [[m numbers] x kFourierTerms rows]}
// for joints with a periodic transmission (a1..b32) among extensions.
void ReadPeriodicBases(const YamlReader& r, const YAML::Node& node,
                       Robot* robot) {
  r.ExpectMap(node, "covariance.periodic_basis");
  for (const auto& entry : node) {
    const std::string joint = r.String(entry.first, "periodic_basis key");
    const std::string what = "covariance.periodic_basis." + joint;
    const bool periodic =
        std::any_of(robot->extensions.begin(), robot->extensions.end(),
                    [&](const Extension& e) {
                      return e.joint == joint && IsPeriodicTransmission(e);
                    });
    if (!periodic) {
      r.Fail(entry.first, what +
                              ": no periodic transmission (a1.., b1..) of "
                              "this joint among extensions; a basis belongs "
                              "to such a joint");
    }
    r.ExpectSequence(entry.second, what);
    if (static_cast<int>(entry.second.size()) != kFourierTerms) {
      r.Fail(entry.second, what + ": expected " +
                               std::to_string(kFourierTerms) +
                               " rows (cos q, sin q, ..., sin 32q), got " +
                               std::to_string(entry.second.size()));
    }
    const int m = static_cast<int>(entry.second[0].size());
    Eigen::MatrixXd basis(kFourierTerms, m);
    for (int t = 0; t < kFourierTerms; ++t) {
      const auto row = r.Numbers(entry.second[t],
                                 what + "[" + std::to_string(t) + "]", m, m);
      for (int k = 0; k < m; ++k) basis(t, k) = row[k];
    }
    robot->fitted_on.periodic_bases.emplace_back(joint, basis);
  }
}

// covariance: {params: [names], matrix: [[...], ...]} (symmetric, n x n).
void ReadCovariance(const YamlReader& r, const YAML::Node& c, Robot* robot) {
  r.ExpectMap(c, "covariance");
  r.CheckKeys(c, {"params", "matrix", "periodic_basis"}, "covariance");
  const YAML::Node params = r.Required(c, "params", "covariance");
  r.ExpectSequence(params, "covariance.params");
  FitRecord& rec = robot->fitted_on;
  for (size_t i = 0; i < params.size(); ++i) {
    rec.covariance_params.push_back(
        r.String(params[i], "covariance.params[" + std::to_string(i) + "]"));
  }
  const int n = static_cast<int>(rec.covariance_params.size());
  const YAML::Node m = r.Required(c, "matrix", "covariance");
  r.ExpectSequence(m, "covariance.matrix");
  if (static_cast<int>(m.size()) != n) {
    r.Fail(m, "covariance.matrix: expected " + std::to_string(n) +
                  " rows (one per parameter), got " + std::to_string(m.size()));
  }
  rec.covariance.resize(n, n);
  for (int i = 0; i < n; ++i) {
    const std::string what = "covariance.matrix[" + std::to_string(i) + "]";
    const auto row = r.Numbers(m[i], what, n, n);
    for (int k = 0; k < n; ++k) rec.covariance(i, k) = row[k];
  }
  for (int i = 0; i < n; ++i) {
    for (int k = 0; k < i; ++k) {
      const double a = rec.covariance(i, k), b = rec.covariance(k, i);
      if (std::abs(a - b) > 1e-9 * std::max(1.0, std::abs(a) + std::abs(b))) {
        r.Fail(m[i], "covariance.matrix: not symmetric at (" +
                         std::to_string(i) + ", " + std::to_string(k) + ")");
      }
    }
    if (!(rec.covariance(i, i) >= 0.0)) {
      r.Fail(m[i], "covariance.matrix: negative variance on the diagonal");
    }
  }
  if (c["periodic_basis"]) ReadPeriodicBases(r, c["periodic_basis"], robot);
}

}  // namespace

Robot ParseRobotYaml(const std::string& text, const std::string& file) {
  YamlReader r(file);
  const YAML::Node root = r.Load(text);
  if (!root.IsDefined() || root.IsNull()) {
    throw InputError(file, 0, 0, "empty file: expected a robot description");
  }
  r.ExpectMap(root, "robot file");
  r.CheckKeys(
      root,
      {"kincal_robot", "name", "convention", "gravity", "joints", "tool",
       "bounds", "extensions", "nominal", "fitted_on", "covariance"},
      "robot file");
  Robot robot;
  ReadRobotHeader(r, root, &robot);
  const YAML::Node joints = r.Required(root, "joints", "robot file");
  r.ExpectSequence(joints, "joints");
  if (joints.size() == 0) r.Fail(joints, "joints: expected at least one joint");
  std::set<std::string> names;
  for (size_t i = 0; i < joints.size(); ++i) {
    robot.joints.push_back(
        ReadJoint(r, joints[i], i, robot.convention, &names));
  }
  ReadToolAndBounds(r, root, &robot);
  if (root["extensions"] && !root["extensions"].IsNull()) {
    const YAML::Node ext = root["extensions"];
    r.ExpectSequence(ext, "extensions");
    for (size_t i = 0; i < ext.size(); ++i) {
      robot.extensions.push_back(ReadExtension(r, ext[i], i, robot));
    }
  }
  if (root["nominal"]) ReadNominal(r, root["nominal"], &robot);
  if (root["fitted_on"]) ReadFittedOn(r, root["fitted_on"], &robot);
  if (root["covariance"]) ReadCovariance(r, root["covariance"], &robot);
  return robot;
}

Robot ReadRobotYaml(const std::string& path) {
  return ParseRobotYaml(ReadFile(path), path);
}

namespace {
std::string Vec(const Eigen::Vector3d& v) {
  return "[" + FormatDouble(v.x()) + ", " + FormatDouble(v.y()) + ", " +
         FormatDouble(v.z()) + "]";
}

std::string Geometry(const Robot& robot, const RobotRow& row) {
  std::ostringstream os;
  if (robot.convention == Convention::kUrdf) {
    os << "xyz: " << Vec(row.xyz_mm) << ", rpy: " << Vec(row.rpy_deg);
    if (row.type != JointType::kFixed) os << ", axis: " << Vec(row.axis);
  } else {
    os << "d: " << FormatDouble(row.d_mm)
       << ", alpha: " << FormatDouble(row.alpha_deg)
       << ", a: " << FormatDouble(row.a_mm)
       << ", theta: " << FormatDouble(row.theta_deg);
    if (row.beta_deg != 0.0) os << ", beta: " << FormatDouble(row.beta_deg);
  }
  return os.str();
}
void FormatMatrixRows(const Eigen::MatrixXd& m, const char* indent,
                      std::ostringstream& os) {
  for (int i = 0; i < m.rows(); ++i) {
    os << indent << "- [";
    for (int k = 0; k < m.cols(); ++k) {
      os << (k ? ", " : "") << FormatDouble(m(i, k));
    }
    os << "]\n";
  }
}

void FormatCovariance(const FitRecord& rec, std::ostringstream& os) {
  if (rec.covariance_params.empty()) return;
  os << "covariance:  # interface units, parameter order below\n  params: [";
  for (size_t i = 0; i < rec.covariance_params.size(); ++i) {
    os << (i ? ", " : "") << rec.covariance_params[i];
  }
  os << "]\n  matrix:\n";
  FormatMatrixRows(rec.covariance, "    ", os);
  if (rec.periodic_bases.empty()) return;
  // Fourier coefficients [a1, b1, a2, ...] = B c for <joint>.transmission<k>.
  os << "  periodic_basis:\n";
  for (const auto& jb : rec.periodic_bases) {
    os << "    " << jb.first << ":\n";
    FormatMatrixRows(jb.second, "      ", os);
  }
}

// nominal:, fitted_on: and covariance: when the robot has them.
void FormatFitRecord(const Robot& robot, std::ostringstream& os) {
  if (robot.HasNominal()) {
    os << "nominal:\n  joints:\n";
    for (const RobotRow& j : robot.nominal_joints) {
      os << "    - {name: " << j.name << ", " << Geometry(robot, j) << "}\n";
    }
    os << "  tool: {" << Geometry(robot, robot.nominal_tool) << "}\n";
  }
  const FitRecord& rec = robot.fitted_on;
  if (rec.present()) {
    os << "fitted_on:\n  poses: " << rec.poses << "\n";
    if (!rec.joint_range.empty()) {
      os << "  joints: {";
      for (size_t j = 0; j < rec.joint_range.size(); ++j) {
        os << (j ? ", " : "") << robot.joints[j].name << ": ["
           << FormatDouble(rec.joint_range[j][0]) << ", "
           << FormatDouble(rec.joint_range[j][1]) << "]";
      }
      os << "}\n";
    }
    bool any_gap = false;
    for (const auto& g : rec.joint_gap) any_gap = any_gap || g[0] == g[0];
    if (any_gap) {
      os << "  gaps: {";
      bool first = true;
      for (size_t j = 0; j < rec.joint_gap.size(); ++j) {
        if (!(rec.joint_gap[j][0] == rec.joint_gap[j][0])) continue;
        os << (first ? "" : ", ") << robot.joints[j].name << ": ["
           << FormatDouble(rec.joint_gap[j][0]) << ", "
           << FormatDouble(rec.joint_gap[j][1]) << "]";
        first = false;
      }
      os << "}\n";
    }
    if (rec.temp_lo_c == rec.temp_lo_c) {
      os << "  temp_c: [" << FormatDouble(rec.temp_lo_c) << ", "
         << FormatDouble(rec.temp_hi_c) << "]\n";
    }
    if (rec.has_frame) {
      os << "  frame: [";  // meas_from_base: rotation vector deg, mm
      for (int k = 0; k < 6; ++k) {
        os << (k ? ", " : "") << FormatDouble(rec.frame[k]);
      }
      os << "]\n";
    }
    if (!rec.series_frames.empty()) {
      os << "  series_frames:\n";  // per series, as frame
      for (const auto& sf : rec.series_frames) {
        std::string label = "\"";  // double-quoted YAML scalar
        for (char ch : sf.first) {
          if (ch == '"' || ch == '\\') label += '\\';
          label += ch;
        }
        os << "    " << label << "\": [";
        for (int k = 0; k < 6; ++k)
          os << (k ? ", " : "") << FormatDouble(sf.second[k]);
        os << "]\n";
      }
    }
    if (!rec.thermal_input.empty()) {
      os << "  thermal_input: " << rec.thermal_input << "\n";
    }
    if (rec.heldout_rms_mm == rec.heldout_rms_mm) {
      os << "  heldout_rms_mm: " << FormatDouble(rec.heldout_rms_mm) << "\n";
    }
    if (rec.systematic_rms_mm == rec.systematic_rms_mm) {
      os << "  systematic_rms_mm: " << FormatDouble(rec.systematic_rms_mm)
         << "\n";
    }
  }
  FormatCovariance(rec, os);
}
}  // namespace

std::string FormatRobotYaml(const Robot& robot,
                            const std::vector<std::string>& comment) {
  std::ostringstream os;
  os << "# written by " << ToolVersion() << ": " << CommandLine() << "\n";
  for (const auto& c : comment) os << "# " << c << "\n";
  os << "kincal_robot: 1\n";
  os << "name: " << robot.name << "\n";
  os << "convention: " << ToString(robot.convention) << "\n";
  os << "gravity: " << Vec(robot.gravity) << "\n";
  os << "joints:\n";
  for (const auto& j : robot.joints) {
    os << "  - {name: " << j.name << ", type: " << ToString(j.type) << ", "
       << Geometry(robot, j);
    if (j.HasLimits()) {
      os << ", limits: [" << FormatDouble(j.lower) << ", "
         << FormatDouble(j.upper) << "]";
    }
    if (j.HasMass()) {
      os << ", mass: " << FormatDouble(j.mass_kg) << ", com: " << Vec(j.com_mm);
    }
    os << "}\n";
  }
  os << "tool: {" << Geometry(robot, robot.tool) << "}\n";
  os << "bounds: {length: " << FormatDouble(robot.bound_length_mm)
     << ", angle: " << FormatDouble(robot.bound_angle_deg) << "}\n";
  if (!robot.extensions.empty()) {
    os << "extensions:\n";
    for (const auto& e : robot.extensions) {
      os << "  - {cause: " << e.cause;
      if (!e.joint.empty()) os << ", joint: " << e.joint;
      for (const auto& kv : e.values) {
        os << ", " << kv.first << ": " << FormatDouble(kv.second);
      }
      os << "}\n";
    }
  }
  FormatFitRecord(robot, os);
  return os.str();
}

}  // namespace kincal
