#include "calib/chain.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <limits>

#include "data/error.h"
#include "data/extension_kinds.h"

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
  // The thermal terms hold at the temperatures they were fitted on.
  const FitRecord& rec = robot.fitted_on;
  if (rec.thermal_input == "temp_c" && rec.temp_lo_c == rec.temp_lo_c &&
      rec.temp_hi_c >= rec.temp_lo_c) {
    c.thermal_lo = rec.temp_lo_c - 20.0;
    c.thermal_hi = rec.temp_hi_c - 20.0;
  }
  for (const RobotRow& r : robot.joints) {
    ChainRow row;
    row.name = r.name;
    row.type = r.type;
    row.axis = r.axis;
    row.p = RowFromDescription(robot.convention, r);
    row.mass_kg = r.mass_kg;
    row.com_mm = r.com_mm;
    c.rows.push_back(row);
  }
  ChainRow tool;
  tool.name = "tool";
  tool.type = JointType::kFixed;
  tool.p = RowFromDescription(robot.convention, robot.tool);
  tool.mass_kg = robot.tool.mass_kg;
  tool.com_mm = robot.tool.com_mm;
  c.rows.push_back(tool);
  c.joint_errors.assign(robot.joints.size(), JointErrorBlock{});
  c.bound_length_mm = robot.bound_length_mm;
  c.bound_angle_rad = robot.bound_angle_deg * kDegToRad;
  for (const Extension& e : robot.extensions) {
    if (e.cause == "drift") {
      c.drift[kDriftX] = e.values.at("vx");
      c.drift[kDriftY] = e.values.at("vy");
      c.drift[kDriftZ] = e.values.at("vz");
      continue;
    }
    if (e.cause == "mount_compliance") {
      // deg per kN m in the file, rad per N m inside.
      constexpr double kUnit = kDegToRad / 1000.0;
      c.drift[kMountIso] = e.values.at("iso") * kUnit;
      const auto cos_it = e.values.find("aniso_cos");
      const auto sin_it = e.values.find("aniso_sin");
      if (cos_it != e.values.end()) c.drift[kMountCos] = cos_it->second * kUnit;
      if (sin_it != e.values.end()) c.drift[kMountSin] = sin_it->second * kUnit;
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
    if (e.cause == "elastostatic")  // deg (mm) per kN m (kN) in the file
      err[kElastostatic] = e.values.at("per_knm") * unit / 1000.0;
    if (e.cause == "thermal") err[kThermal] = e.values.at("rate");
    if (e.cause == "transmission") {
      // lo, hi: the travel (deg | mm); s1 .. s24: sine coefficients over
      // it; or a1 .. a32, b1 .. b32: Fourier coefficients (deg) of a
      // periodic error over the revolution (FourierBasis).
      c.rows[j].transmission_lo = e.values.at("lo") * unit;
      c.rows[j].transmission_hi = e.values.at("hi") * unit;
      for (int k = 0; k < kMaxTransmissionTerms; ++k) {
        const auto it = e.values.find("s" + std::to_string(k + 1));
        if (it != e.values.end()) err[kTransmission0 + k] = it->second * unit;
      }
      if (IsPeriodicTransmission(e)) {
        std::vector<double> fourier(kPeriodicTerms, 0.0);
        for (int h = 1; h <= kPeriodicHarmonics; ++h) {
          const auto a = e.values.find("a" + std::to_string(h));
          const auto b = e.values.find("b" + std::to_string(h));
          if (a != e.values.end()) fourier[2 * h - 2] = a->second * unit;
          if (b != e.values.end()) fourier[2 * h - 1] = b->second * unit;
        }
        c.rows[j].periodic_basis = FourierBasis(fourier);
        std::fill(err.begin() + kTransmission0, err.end(), 0.0);
        err[kTransmission0] = 1.0;
      }
    }
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
  robot.fitted_on = FitRecord{};  // a record describes other values
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
    if (err[kElastostatic] != 0.0)
      robot.extensions.push_back(
          {"elastostatic",
           name,
           {{"per_knm", err[kElastostatic] / unit * 1000.0}}});
    if (err[kThermal] != 0.0)
      robot.extensions.push_back({"thermal", name, {{"rate", err[kThermal]}}});
    Extension transmission{"transmission", name, {}};
    if (rows[j].periodic()) {
      const std::vector<double> f = PeriodicCoefficients(rows[j], err);
      for (int h = 1; h <= kPeriodicHarmonics; ++h) {
        if (f[2 * h - 2] == 0.0 && f[2 * h - 1] == 0.0) continue;
        transmission.values["a" + std::to_string(h)] = f[2 * h - 2] / unit;
        transmission.values["b" + std::to_string(h)] = f[2 * h - 1] / unit;
      }
    }
    for (int k = 0; k < kMaxTransmissionTerms && !rows[j].periodic(); ++k) {
      if (err[kTransmission0 + k] == 0.0) continue;
      transmission.values["s" + std::to_string(k + 1)] =
          err[kTransmission0 + k] / unit;
    }
    if (!transmission.values.empty() &&
        rows[j].transmission_hi > rows[j].transmission_lo) {
      transmission.values["lo"] = rows[j].transmission_lo / unit;
      transmission.values["hi"] = rows[j].transmission_hi / unit;
      robot.extensions.push_back(transmission);
    }
  }
  if (drift[0] != 0.0 || drift[1] != 0.0 || drift[2] != 0.0) {
    robot.extensions.push_back(
        {"drift", "", {{"vx", drift[0]}, {"vy", drift[1]}, {"vz", drift[2]}}});
  }
  if (drift[kMountIso] != 0.0 || drift[kMountCos] != 0.0 ||
      drift[kMountSin] != 0.0) {
    constexpr double kUnit = kDegToRad / 1000.0;
    robot.extensions.push_back({"mount_compliance",
                                "",
                                {{"iso", drift[kMountIso] / kUnit},
                                 {"aniso_cos", drift[kMountCos] / kUnit},
                                 {"aniso_sin", drift[kMountSin] / kUnit}}});
  }
  return robot;
}

std::vector<double> FourierBasis(const std::vector<double>& fourier) {
  KINCAL_CHECK(static_cast<int>(fourier.size()) == kPeriodicTerms,
               "Fourier coefficients: " << fourier.size());
  std::vector<double> b(kPeriodicTerms * kMaxTransmissionTerms, 0.0);
  std::copy(fourier.begin(), fourier.end(), b.begin());
  return b;
}

std::vector<double> PeriodicCoefficients(const ChainRow& row,
                                         const JointErrorBlock& err) {
  std::vector<double> f(kPeriodicTerms, 0.0);
  if (!row.periodic()) return f;
  for (int k = 0; k < kMaxTransmissionTerms; ++k) {
    const double c = err[kTransmission0 + k];
    if (c == 0.0) continue;
    for (int t = 0; t < kPeriodicTerms; ++t)
      f[t] += row.periodic_basis[kPeriodicTerms * k + t] * c;
  }
  return f;
}

void FillTransmissionSines(const Chain& chain, PoseInput* in) {
  const int n = chain.num_joints();
  bool any = false;
  for (int j = 0; j < n; ++j)
    any = any || chain.rows[j].periodic() ||
          chain.rows[j].transmission_hi > chain.rows[j].transmission_lo;
  in->transmission_sines.clear();
  if (!any) return;
  in->transmission_sines.assign(kMaxTransmissionTerms * n, 0.0);
  for (int j = 0; j < n; ++j) {
    const ChainRow& row = chain.rows[j];
    if (row.periodic()) {  // the basis functions at the reading: B^T f(q)
      double f[kPeriodicTerms];
      PeriodicTerms(in->q[j], f);
      for (int k = 0; k < kMaxTransmissionTerms; ++k) {
        const double* b = &row.periodic_basis[kPeriodicTerms * k];
        double phi = 0.0;
        for (int t = 0; t < kPeriodicTerms; ++t) phi += b[t] * f[t];
        in->transmission_sines[kMaxTransmissionTerms * j + k] = phi;
      }
      continue;
    }
    // Each term through the hook itself (a unit coefficient vector).
    for (int k = 0; k < kMaxTransmissionTerms; ++k) {
      double unit[kMaxTransmissionTerms] = {};
      unit[k] = 1.0;
      in->transmission_sines[kMaxTransmissionTerms * j + k] =
          TransmissionError(unit, in->q[j], chain.rows[j]);
    }
  }
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
  for (double v : drift) {
    if (v != 0.0) return true;
  }
  return false;
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

std::vector<double> ModelJointValues(const Chain& chain, const PoseInput& in) {
  const int n = chain.num_joints();
  const bool masses = static_cast<int>(in.tau_mass.size()) == n;
  std::vector<double> q(n);
  for (int j = 0; j < n; ++j) {
    const ChainRow& row = chain.rows[j];
    q[j] = ModelJointValue<double>(row, in.q[j], in.s[j], in.tau[j],
                                   chain.joint_errors[j].data(),
                                   masses ? in.tau_mass[j] : 0.0);
  }
  return q;
}

Eigen::Matrix4d ModelBaseFromTip(const Chain& chain, const PoseInput& in) {
  Eigen::Matrix4d m = BaseFromTipAt(chain, ModelJointValues(chain, in));
  const double* g = chain.drift.data();
  const Eigen::Vector3d w((g[kMountIso] + g[kMountCos]) * in.moment.x() +
                              g[kMountSin] * in.moment.y(),
                          g[kMountSin] * in.moment.x() +
                              (g[kMountIso] - g[kMountCos]) * in.moment.y(),
                          0.0);
  if (w.norm() > 0) {
    m.block<3, 3>(0, 0) =
        Eigen::AngleAxisd(w.norm(), w.normalized()).toRotationMatrix() *
        m.block<3, 3>(0, 0);
  }
  m.block<3, 1>(0, 3) = TipInBase(chain, in);
  return m;
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

bool ThermalUsesTemperature(const Observations& obs) {
  if (obs.rows.empty()) return false;
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (const Observation& o : obs.rows) {
    if (!o.HasTemp()) return false;
    lo = std::min(lo, o.temp_c);
    hi = std::max(hi, o.temp_c);
  }
  return hi > lo;
}

PoseInput PoseInputAt(const Chain& chain,
                      const std::vector<double>& q_internal) {
  const int n = chain.num_joints();
  KINCAL_CHECK(static_cast<int>(q_internal.size()) == n,
               "pose has " << q_internal.size() << " joints, chain " << n);
  // Link masses: the rows' (and the tool's) when any is given, else uniform
  // beams of 10 kg/m of nominal row length, centre of mass half-way.
  bool any_mass = false;
  for (const ChainRow& r : chain.rows) any_mass = any_mass || r.mass_kg >= 0;
  PoseInput in;
  in.q = q_internal;
  in.s.assign(n, 0.0);
  // Gravity torque of a unit mass at the tip (nominal geometry, readings).
  std::vector<Eigen::Vector3d> origins, axes;
  JointAxesInBase(chain, in.q, &origins, &axes);
  const Eigen::Matrix4d tip = BaseFromTipAt(chain, in.q);
  const Eigen::Vector3d p_tip = tip.block<3, 1>(0, 3);
  in.tau.resize(n);
  for (int j = 0; j < n; ++j) {
    in.tau[j] = chain.rows[j].type == JointType::kPrismatic
                    ? axes[j].dot(chain.gravity)
                    : axes[j].cross(p_tip - origins[j]).dot(chain.gravity);
  }
  // Link masses: weight vectors (N) at their centres (base frame, mm).
  std::vector<Eigen::Vector3d> com(n + 1);
  std::vector<double> mass(n + 1, 0.0);
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  for (int r = 0; r <= n; ++r) {
    const ChainRow& row = chain.rows[r];
    const Eigen::Vector3d start = m.block<3, 1>(0, 3);
    m = m * RowTransform<double>(chain.convention, row, row.p.data(),
                                 r < n ? in.q[r] : 0.0);
    const Eigen::Vector3d end = m.block<3, 1>(0, 3);
    if (any_mass) {
      mass[r] = row.mass_kg >= 0 ? row.mass_kg : 0.0;
      com[r] = (m * row.com_mm.homogeneous()).head<3>();
    } else {
      mass[r] = 10.0 * (end - start).norm() / 1000.0;
      com[r] = 0.5 * (start + end);
    }
  }
  in.tau_mass.assign(n, 0.0);
  in.moment.setZero();
  for (int r = 0; r <= n; ++r) {
    const Eigen::Vector3d weight = mass[r] * kGravityMps2 * chain.gravity;
    in.moment += com[r].cross(weight) / 1000.0;
    for (int j = 0; j < n && j <= r; ++j) {
      in.tau_mass[j] +=
          chain.rows[j].type == JointType::kPrismatic
              ? axes[j].dot(weight)
              : axes[j].cross(com[r] - origins[j]).dot(weight) / 1000.0;
    }
  }
  in.trig.resize(2 * kMaxHarmonic * n);
  for (int j = 0; j < n; ++j) {
    for (int h = 1; h <= kMaxHarmonic; ++h) {
      in.trig[2 * kMaxHarmonic * j + 2 * (h - 1)] = std::cos(h * in.q[j]);
      in.trig[2 * kMaxHarmonic * j + 2 * (h - 1) + 1] = std::sin(h * in.q[j]);
    }
  }
  return in;
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
  const bool use_temp = ThermalUsesTemperature(obs);
  std::vector<PoseInput> out;
  std::vector<double> s(n, 0.0);
  const std::vector<double>* prev = nullptr;
  std::vector<double> q(n);
  for (const Observation& o : obs.rows) {
    for (int j = 0; j < n; ++j) q[j] = chain.ReadingToInternal(j, o.q[j]);
    if (prev != nullptr) {
      for (int j = 0; j < n; ++j) {
        const double dq = o.q[j] - (*prev)[j];
        if (dq > 0) s[j] = 1.0;
        if (dq < 0) s[j] = -1.0;
      }
    }
    prev = &o.q;
    PoseInput in = PoseInputAt(chain, q);
    in.s = s;
    in.t_h = o.HasTime() ? (o.t_s - t0) / 3600.0 : 0.0;
    in.thermal_x = use_temp ? o.temp_c - 20.0 : in.t_h;
    out.push_back(std::move(in));
  }
  return out;
}

}  // namespace kincal
