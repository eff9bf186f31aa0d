#include "calib/chain.h"

#include <Eigen/Geometry>
#include <algorithm>

#include "data/error.h"

namespace kincal {
namespace {
constexpr double kDegToRad = M_PI / 180.0;

RowBlock RowFromDescription(Convention convention, const RobotRow& r) {
  RowBlock p{};
  if (convention == Convention::kUrdf) {
    p = {r.xyz_mm.x(),
         r.xyz_mm.y(),
         r.xyz_mm.z(),
         r.rpy_deg.x() * kDegToRad,
         r.rpy_deg.y() * kDegToRad,
         r.rpy_deg.z() * kDegToRad};
  } else {
    p = {r.theta_deg * kDegToRad, r.d_mm, r.a_mm, r.alpha_deg * kDegToRad,
         r.beta_deg * kDegToRad,  0.0};
  }
  return p;
}

void RowToDescription(Convention convention, const RowBlock& p, RobotRow* r) {
  if (convention == Convention::kUrdf) {
    r->xyz_mm = Eigen::Vector3d(p[0], p[1], p[2]);
    r->rpy_deg = Eigen::Vector3d(p[3], p[4], p[5]) / kDegToRad;
  } else {
    r->theta_deg = p[0] / kDegToRad;
    r->d_mm = p[1];
    r->a_mm = p[2];
    r->alpha_deg = p[3] / kDegToRad;
    r->beta_deg = p[4] / kDegToRad;
  }
}
}  // namespace

Chain Chain::FromRobot(const Robot& robot) {
  KINCAL_CHECK(static_cast<int>(robot.joints.size()) <= 16,
               "at most 16 joints, got " << robot.joints.size());
  Chain c;
  c.name = robot.name;
  c.convention = robot.convention;
  c.gravity = robot.gravity.normalized();
  for (const RobotRow& r : robot.joints) {
    ChainRow row;
    row.name = r.name;
    row.type = r.type;
    row.axis = r.axis;
    row.p = RowFromDescription(robot.convention, r);
    c.rows.push_back(row);
  }
  ChainRow tool;
  tool.name = "tool";
  tool.type = JointType::kFixed;
  tool.p = RowFromDescription(robot.convention, robot.tool);
  c.rows.push_back(tool);
  c.joint_errors.assign(robot.joints.size(), JointErrorBlock{});
  c.bound_length_mm = robot.bound_length_mm;
  c.bound_angle_rad = robot.bound_angle_deg * kDegToRad;
  for (const Extension& e : robot.extensions) {
    if (e.cause == "drift") {
      c.drift = {e.values.at("vx"), e.values.at("vy"), e.values.at("vz")};
      continue;
    }
    const int j = robot.JointIndex(e.joint);
    KINCAL_CHECK(j >= 0, "extension on unknown joint " << e.joint);
    const double unit =
        robot.joints[j].type == JointType::kRevolute ? kDegToRad : 1.0;
    JointErrorBlock& err = c.joint_errors[j];
    if (e.cause == "backlash") err[kBacklash] = e.values.at("width") * unit;
    if (e.cause == "compliance")
      err[kCompliance] = e.values.at("per_torque") * unit;
    if (e.cause == "gain") err[kGain] = e.values.at("g");
    if (e.cause == "cyclic") {
      // Harmonic 1: cos, sin; harmonics 2, 3: cos2, sin2, cos3, sin3.
      for (int h = 1; h <= kMaxHarmonic; ++h) {
        const std::string suffix = h == 1 ? "" : std::to_string(h);
        const auto cos_it = e.values.find("cos" + suffix);
        const auto sin_it = e.values.find("sin" + suffix);
        if (cos_it != e.values.end()) {
          err[CyclicCosIndex(h)] = cos_it->second * unit;
        }
        if (sin_it != e.values.end()) {
          err[CyclicCosIndex(h) + 1] = sin_it->second * unit;
        }
      }
    }
  }
  return c;
}

Robot Chain::ToRobot(const Robot& description) const {
  KINCAL_CHECK(description.joints.size() + 1 == rows.size(),
               "robot description has " << description.joints.size()
                                        << " joints, chain " << num_joints());
  Robot robot = description;
  for (int j = 0; j < num_joints(); ++j) {
    RowToDescription(convention, rows[j].p, &robot.joints[j]);
  }
  RowToDescription(convention, rows[tool_row()].p, &robot.tool);
  robot.extensions.clear();
  for (int j = 0; j < num_joints(); ++j) {
    const JointErrorBlock& err = joint_errors[j];
    const double unit = rows[j].type == JointType::kRevolute ? kDegToRad : 1.0;
    const std::string& name = rows[j].name;
    if (err[kBacklash] != 0.0)
      robot.extensions.push_back(
          {"backlash", name, {{"width", err[kBacklash] / unit}}});
    if (err[kCompliance] != 0.0)
      robot.extensions.push_back(
          {"compliance", name, {{"per_torque", err[kCompliance] / unit}}});
    Extension cyclic{"cyclic", name, {}};
    for (int h = 1; h <= kMaxHarmonic; ++h) {
      const int k = CyclicCosIndex(h);
      if (err[k] == 0.0 && err[k + 1] == 0.0) continue;
      const std::string suffix = h == 1 ? "" : std::to_string(h);
      cyclic.values["cos" + suffix] = err[k] / unit;
      cyclic.values["sin" + suffix] = err[k + 1] / unit;
    }
    if (!cyclic.values.empty()) {
      cyclic.values.emplace("cos", 0.0);  // the format requires harmonic 1
      cyclic.values.emplace("sin", 0.0);
      robot.extensions.push_back(cyclic);
    }
    if (err[kGain] != 0.0)
      robot.extensions.push_back({"gain", name, {{"g", err[kGain]}}});
  }
  if (drift[0] != 0.0 || drift[1] != 0.0 || drift[2] != 0.0) {
    robot.extensions.push_back(
        {"drift", "", {{"vx", drift[0]}, {"vy", drift[1]}, {"vz", drift[2]}}});
  }
  return robot;
}

double Chain::ReadingToInternal(int joint, double reading) const {
  return rows[joint].type == JointType::kRevolute ? reading * kDegToRad
                                                  : reading;
}

double Chain::InternalToReading(int joint, double value) const {
  return rows[joint].type == JointType::kRevolute ? value / kDegToRad : value;
}

bool Chain::HasJointErrors() const {
  for (const auto& e : joint_errors) {
    for (double v : e) {
      if (v != 0.0) return true;
    }
  }
  return drift[0] != 0.0 || drift[1] != 0.0 || drift[2] != 0.0;
}

namespace {
std::vector<const double*> RowPointers(const Chain& chain) {
  std::vector<const double*> rows;
  for (const auto& r : chain.rows) rows.push_back(r.p.data());
  return rows;
}
}  // namespace

Eigen::Matrix4d BaseFromTipAt(const Chain& chain,
                              const std::vector<double>& q_internal) {
  const std::vector<const double*> rows = RowPointers(chain);
  return BaseFromTip<double>(chain, rows.data(), q_internal.data());
}

Eigen::Vector3d TipInBase(const Chain& chain, const PoseInput& in,
                          bool with_errors) {
  const std::vector<const double*> rows = RowPointers(chain);
  std::vector<const double*> errs;
  for (const auto& e : chain.joint_errors) errs.push_back(e.data());
  return TipInBase<double>(chain, rows.data(),
                           with_errors ? errs.data() : nullptr,
                           with_errors ? chain.drift.data() : nullptr, in);
}

void JointAxesInBase(const Chain& chain, const std::vector<double>& q,
                     std::vector<Eigen::Vector3d>* origins,
                     std::vector<Eigen::Vector3d>* axes) {
  origins->clear();
  axes->clear();
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  for (int j = 0; j < chain.num_joints(); ++j) {
    const ChainRow& row = chain.rows[j];
    const RowBlock& p = row.p;
    Eigen::Matrix4d at = m;  // frame in which joint j moves about/along z
    Eigen::Vector3d axis_local = Eigen::Vector3d::UnitZ();
    if (chain.convention == Convention::kMdh) {
      at = m * internal::RotX(p[3]) * internal::RotY(p[4]) *
           internal::Trans(p[2], 0.0, 0.0);
    } else if (chain.convention == Convention::kUrdf) {
      at = m * internal::Trans(p[0], p[1], p[2]) * internal::RotZ(p[5]) *
           internal::RotY(p[4]) * internal::RotX(p[3]);
      axis_local = row.axis;
    }
    origins->push_back(at.block<3, 1>(0, 3));
    axes->push_back((at.block<3, 3>(0, 0) * axis_local).normalized());
    m = m * RowTransform<double>(chain.convention, row, p.data(), q[j]);
  }
}

std::vector<PoseInput> MakePoseInputs(const Chain& chain,
                                      const Observations& obs) {
  const int n = chain.num_joints();
  KINCAL_CHECK(
      static_cast<int>(obs.joint_names.size()) == n,
      "observations have " << obs.joint_names.size() << " joints, chain " << n);
  double t0 = 0.0;
  bool any_time = false;
  for (const auto& r : obs.rows) {
    if (r.HasTime()) {
      t0 = any_time ? std::min(t0, r.t_s) : r.t_s;
      any_time = true;
    }
  }
  std::vector<PoseInput> out;
  std::vector<double> s(n, 0.0);
  const std::vector<double>* prev = nullptr;
  std::vector<Eigen::Vector3d> origins, axes;
  for (const Observation& o : obs.rows) {
    PoseInput in;
    in.q.resize(n);
    for (int j = 0; j < n; ++j) in.q[j] = chain.ReadingToInternal(j, o.q[j]);
    if (prev != nullptr) {
      for (int j = 0; j < n; ++j) {
        const double dq = o.q[j] - (*prev)[j];
        if (dq > 0) s[j] = 1.0;
        if (dq < 0) s[j] = -1.0;
      }
    }
    prev = &o.q;
    in.s = s;
    in.t_h = o.HasTime() ? (o.t_s - t0) / 3600.0 : 0.0;
    // Gravity torque of a unit mass at the tip (nominal geometry, readings).
    JointAxesInBase(chain, in.q, &origins, &axes);
    const Eigen::Matrix4d tip = BaseFromTipAt(chain, in.q);
    const Eigen::Vector3d p_tip = tip.block<3, 1>(0, 3);
    in.tau.resize(n);
    for (int j = 0; j < n; ++j) {
      in.tau[j] = chain.rows[j].type == JointType::kPrismatic
                      ? axes[j].dot(chain.gravity)
                      : axes[j].cross(p_tip - origins[j]).dot(chain.gravity);
    }
    out.push_back(in);
  }
  return out;
}

}  // namespace kincal
