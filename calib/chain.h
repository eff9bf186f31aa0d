#ifndef KINCAL_CALIB_CHAIN_H_
#define KINCAL_CALIB_CHAIN_H_

// The one kinematic chain type of kincal: rows in standard DH, modified DH or
// URDF form, plus per-joint error models (the diagnosis' model extensions)
// and a drift term. Forward kinematics is templated on the scalar so Ceres
// autodiff and plain evaluation share one implementation.
//
// Internal units: mm and radians (see docs/CONVENTIONS.md). Interface
// conversions happen in Chain::FromRobot / Chain::ToRobot and ParamInfo.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>
#include <type_traits>
#include <vector>

#include "data/observations.h"
#include "data/robot.h"

namespace kincal {

// Row geometry block, 6 numbers in internal units:
//   dh / mdh: [theta_rad, d_mm, a_mm, alpha_rad, beta_rad, (unused)]
//   urdf:     [x_mm, y_mm, z_mm, roll_rad, pitch_rad, yaw_rad]
constexpr int kRowBlockSize = 6;
// Cause families of the error model. Each family owns a fixed slice of one
// of two parameter blocks (the fit's blocks: one per joint and one global),
// declared here in one place, and one templated hook below:
//
//   family         block   entries                      hook
//   gain           joint   kGain                        JointValue
//   backlash       joint   kBacklash                    JointValue
//   compliance     joint   kCompliance (tip-mass tau)   JointValue
//   cyclic 1..3    joint   kCyclicCos .. kCyclic3Sin    JointValue
//   elastostatic   joint   kElastostatic (link masses)  JointValue
//   thermal        joint   kThermal (row length growth) RowLengthScale
//   transmission   joint   kTransmission0 .. +23        JointValue
//   drift          global  kDriftX .. kDriftZ           TipOffset
//   mount          global  kMountIso, kMountCos, ..Sin  TipOffset
//
// A new family adds its entries here, its hook in TipInBase, its parameter
// names in model_state.cc and its catalogue entry in diagnose/catalogue.cc.
//
// Per-joint error block, internal units:
//   [gain (1), backlash (rad|mm, full width), compliance (rad|mm per mm of
//    unit-mass torque), cyclic_cos, cyclic_sin (rad, first harmonic of the
//    read angle), cyclic2_cos, cyclic2_sin (second), cyclic3_cos,
//    cyclic3_sin (third harmonic), elastostatic (rad|mm per N m of the
//    gravity torque of the link masses about the joint), thermal (relative
//    growth of the row's lengths per unit of the thermal input: per K when
//    the data have temp_c, else per hour), transmission_1 ..
//    transmission_24 (rad|mm, coefficients of the joint error's periodic
//    basis or of its sine series over the travel, see TransmissionError)]
constexpr int kMaxTransmissionTerms = 24;
// Harmonics of the periodic transmission's Fourier terms (the UR10's gear
// errors reach 15-25 cycles per revolution, docs/DIAGNOSE.md) and their
// number (cos, sin per harmonic).
constexpr int kPeriodicHarmonics = 32;
constexpr int kPeriodicTerms = 2 * kPeriodicHarmonics;
constexpr int kJointErrorBlockSize = 11 + kMaxTransmissionTerms;
enum JointErrorIndex {
  kGain = 0,
  kBacklash,
  kCompliance,
  kCyclicCos,
  kCyclicSin,
  kCyclic2Cos,
  kCyclic2Sin,
  kCyclic3Cos,
  kCyclic3Sin,
  kElastostatic,
  kThermal,
  kTransmission0  // first of kMaxTransmissionTerms sine coefficients
};
constexpr int kMaxHarmonic = 3;
// Index of the cosine term of harmonic h (1..3); the sine term follows it.
constexpr int CyclicCosIndex(int harmonic) {
  return kCyclicCos + 2 * (harmonic - 1);
}
// Global block (named drift for history; the fit passes it as one block):
//   [vx, vy, vz (tip drift in the base frame, mm per hour),
//    mount_iso, mount_cos, mount_sin (compliance of the mount / stand, rad
//    per N m: the base tilts by w = C M under the gravity moment M of the
//    arm's link masses about the base origin, C = [[iso + cos, sin],
//    [sin, iso - cos]] on the horizontal axes)]
constexpr int kDriftBlockSize = 6;
enum GlobalIndex {
  kDriftX = 0,
  kDriftY,
  kDriftZ,
  kMountIso,
  kMountCos,
  kMountSin
};
// Measuring frame block (meas_from_base): [rx, ry, rz (angle-axis, rad),
// tx, ty, tz (mm)].
constexpr int kFrameBlockSize = 6;
// Standard gravity, m/s^2: torques of link masses in N m.
constexpr double kGravityMps2 = 9.80665;

using RowBlock = std::array<double, kRowBlockSize>;
using JointErrorBlock = std::array<double, kJointErrorBlockSize>;

struct ChainRow {
  std::string name;  // joint name, or "tool"
  JointType type = JointType::kRevolute;
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();  // URDF joints only
  RowBlock p{};                                     // geometry, internal units
  // Mass (kg) and centre of mass (mm, frame after the row) of the link the
  // row ends in; NaN mass = not given (robot.yaml mass/com).
  double mass_kg = std::numeric_limits<double>::quiet_NaN();
  Eigen::Vector3d com_mm = Eigen::Vector3d::Zero();
  // Travel [lo, hi] of the joint (internal units) over which the
  // transmission family's sine series lives; lo == hi = none. Structure,
  // not a fitted value: set from the data the map is fitted on. With a
  // periodic basis (below) it is the travel that supports the function.
  double transmission_lo = 0.0, transmission_hi = 0.0;
  // Periodic transmission (revolute joints): the family's coefficients c_k
  // weight kMaxTransmissionTerms functions of the read angle over the whole
  // revolution, phi_k(q) = sum_t B(t, k) f_t(q) with the Fourier terms
  // f = [cos q, sin q, cos 2q, sin 2q, ..., cos Hq, sin Hq] (H =
  // kPeriodicHarmonics); B is kPeriodicTerms x kMaxTransmissionTerms,
  // column-major (empty = the sine series over the travel). Structure, not
  // fitted: the diagnosis builds it from the readings
  // (diagnose/periodic_basis.h); a robot file's Fourier coefficients become
  // one column with c_1 = 1 (FourierBasis).
  std::vector<double> periodic_basis;
  bool periodic() const { return !periodic_basis.empty(); }
};

struct Chain {
  std::string name;
  Convention convention = Convention::kDh;
  Eigen::Vector3d gravity = Eigen::Vector3d(0, 0, -1);
  std::vector<ChainRow> rows;                   // joints in order, tool last
  std::vector<JointErrorBlock> joint_errors;    // one per joint, zero = none
  std::array<double, kDriftBlockSize> drift{};  // global block (see above)
  double bound_length_mm = 5.0;
  double bound_angle_rad = 5.0 * M_PI / 180.0;
  // The range of the thermal input (PoseInput::thermal_x) the thermal terms
  // were fitted on: the model clamps the input to it (a growth measured over
  // 0.4 K is not extrapolated linearly to 10 K). Unbounded unless a robot
  // file's fitted_on states it (FromRobot: temp_c - 20 over the fitted
  // temp_c range).
  double thermal_lo = -std::numeric_limits<double>::infinity();
  double thermal_hi = std::numeric_limits<double>::infinity();
  double ThermalInput(double x) const {
    return std::min(thermal_hi, std::max(thermal_lo, x));
  }

  int num_joints() const { return static_cast<int>(rows.size()) - 1; }
  int tool_row() const { return num_joints(); }

  // Converts a robot description (mm, deg) into the internal chain; the
  // robot's extensions fill joint_errors / drift, row beta fills axis tilt.
  static Chain FromRobot(const Robot& robot);
  // Writes the chain's values back into `description` (mm, deg); non-zero
  // joint errors and drift become `extensions:` entries.
  Robot ToRobot(const Robot& description) const;

  // Reading units (mm | deg) <-> internal (mm | rad) for joint j.
  double ReadingToInternal(int joint, double reading) const;
  double InternalToReading(int joint, double value) const;
  bool HasJointErrors() const;
};

// Everything about one pose that the error models need beside the readings.
struct PoseInput {
  std::vector<double> q;    // joint readings, internal units (rad | mm)
  std::vector<double> s;    // approach direction per joint: +1, -1, 0 unknown
  std::vector<double> tau;  // gravity torque about each joint axis (see below)
  double t_h = 0.0;         // hours since the first timed row (0 if untimed)
  // Gravity torque of the arm's link masses about each joint axis (N m;
  // prismatic: force along the axis, N), nominal geometry and readings.
  // Masses from the robot file, else a uniform-beam proxy (MakePoseInputs).
  std::vector<double> tau_mass;
  // Gravity moment of all link masses about the base origin, base frame, N m.
  Eigen::Vector3d moment = Eigen::Vector3d::Zero();
  // Input of the thermal family: temp_c - 20 (K) when every row has a
  // temperature and it varies, else t_h (h).
  double thermal_x = 0.0;
  // cos(h q), sin(h q) for h = 1..3 per joint (6 per joint), precomputed by
  // MakePoseInputs; empty = computed on the fly.
  std::vector<double> trig;
  // sin(k pi u) - m_k, k = 1..24, per joint (TransmissionError) for the
  // chain's travels, precomputed by FillTransmissionSines; empty = computed
  // on the fly.
  std::vector<double> transmission_sines;
};

// The periodic basis of a function given by its Fourier coefficients
// (kPeriodicTerms, internal units): F in the first column, zeros elsewhere
// (its coefficient c_1 = 1).
std::vector<double> FourierBasis(const std::vector<double>& fourier);
// A periodic row's transmission as Fourier coefficients B c (internal
// units, [cos q, sin q, cos 2q, ...], kPeriodicTerms); zeros for a row
// without a periodic basis.
std::vector<double> PeriodicCoefficients(const ChainRow& row,
                                         const JointErrorBlock& err);

// Fills PoseInput::transmission_sines for `chain`'s travels and periodic
// bases (clears it when no joint has one). Must be called again when a
// travel or a basis changes.
void FillTransmissionSines(const Chain& chain, PoseInput* in);

// Builds PoseInputs for the rows of `obs` (in visit order). `s` follows the
// spec: the sign of the joint's last motion before the pose; a joint that did
// not move keeps its previous sign; unknown (0) before the first motion.
// `tau` is computed with `chain`'s geometry (normally the nominal robot) and
// the read joint values: for a revolute joint, (z x (p_tip - o)) . g_unit (mm,
// torque of a unit mass at the tip); for a prismatic joint, z . g_unit.
// `tau_mass` and `moment` use the rows' masses and centres of mass; when no
// row has a mass, each row is a uniform beam of 10 kg per metre of its
// nominal length with its centre of mass half-way (the elastostatic and
// mount compliances then absorb the scale). `thermal_x` is temp_c - 20 deg C
// when every row has one and it varies, else t_h.
std::vector<PoseInput> MakePoseInputs(const Chain& chain,
                                      const Observations& obs);
// The part of a PoseInput that depends on the readings alone (tau, tau_mass,
// moment, trig; internal units), with s = 0, t_h = 0 and thermal_x = 0: for
// callers that choose the readings themselves (inverse kinematics), which
// then set s, t_h and thermal_x.
PoseInput PoseInputAt(const Chain& chain,
                      const std::vector<double>& q_internal);
// True when the thermal input of these observations is temperature (K).
bool ThermalUsesTemperature(const Observations& obs);

// ---------------------------------------------------------------------------
// Templated kinematics.

template <typename T>
using Mat4 = Eigen::Matrix<T, 4, 4>;
template <typename T>
using Vec3 = Eigen::Matrix<T, 3, 1>;

namespace internal {
template <typename T>
Mat4<T> RotZ(const T& a) {
  using std::cos;
  using std::sin;
  Mat4<T> m = Mat4<T>::Identity();
  m(0, 0) = cos(a);
  m(0, 1) = -sin(a);
  m(1, 0) = sin(a);
  m(1, 1) = cos(a);
  return m;
}
template <typename T>
Mat4<T> RotX(const T& a) {
  using std::cos;
  using std::sin;
  Mat4<T> m = Mat4<T>::Identity();
  m(1, 1) = cos(a);
  m(1, 2) = -sin(a);
  m(2, 1) = sin(a);
  m(2, 2) = cos(a);
  return m;
}
template <typename T>
Mat4<T> RotY(const T& a) {
  using std::cos;
  using std::sin;
  Mat4<T> m = Mat4<T>::Identity();
  m(0, 0) = cos(a);
  m(0, 2) = sin(a);
  m(2, 0) = -sin(a);
  m(2, 2) = cos(a);
  return m;
}
template <typename T>
Mat4<T> Trans(const T& x, const T& y, const T& z) {
  Mat4<T> m = Mat4<T>::Identity();
  m(0, 3) = x;
  m(1, 3) = y;
  m(2, 3) = z;
  return m;
}
// Rotation by angle a about the unit axis u (Rodrigues).
template <typename T>
Mat4<T> RotAxis(const Eigen::Vector3d& u, const T& a) {
  using std::cos;
  using std::sin;
  const T c = cos(a), s = sin(a), v = T(1) - c;
  Mat4<T> m = Mat4<T>::Identity();
  m(0, 0) = c + u.x() * u.x() * v;
  m(0, 1) = u.x() * u.y() * v - u.z() * s;
  m(0, 2) = u.x() * u.z() * v + u.y() * s;
  m(1, 0) = u.y() * u.x() * v + u.z() * s;
  m(1, 1) = c + u.y() * u.y() * v;
  m(1, 2) = u.y() * u.z() * v - u.x() * s;
  m(2, 0) = u.z() * u.x() * v - u.y() * s;
  m(2, 1) = u.z() * u.y() * v + u.x() * s;
  m(2, 2) = c + u.z() * u.z() * v;
  return m;
}
}  // namespace internal

// The transform of one row, previous frame <- next frame, for joint value q
// (internal units; q = 0 for the tool row). The DH variant is chosen by
// `convention`:
//   dh:   Rz(theta + q) Tz(d + q) Tx(a) Rx(alpha) Ry(beta)
//   mdh:  Rx(alpha) Ry(beta) Tx(a) Rz(theta + q) Tz(d + q)
//   urdf: T(x, y, z) Rz(yaw) Ry(pitch) Rx(roll) R(axis, q) | T(axis q)
// where "+ q" applies to theta for revolute and to d for prismatic joints.
template <typename T>
Mat4<T> RowTransform(Convention convention, const ChainRow& row, const T* p,
                     const T& q) {
  using internal::RotAxis;
  using internal::RotX;
  using internal::RotY;
  using internal::RotZ;
  using internal::Trans;
  const T zero(0);
  const bool revolute = row.type == JointType::kRevolute;
  const bool prismatic = row.type == JointType::kPrismatic;
  switch (convention) {
    case Convention::kDh: {
      const T theta = revolute ? p[0] + q : p[0];
      const T d = prismatic ? p[1] + q : p[1];
      return RotZ(theta) * Trans(p[2], zero, d) * RotX(p[3]) * RotY(p[4]);
    }
    case Convention::kMdh: {
      const T theta = revolute ? p[0] + q : p[0];
      const T d = prismatic ? p[1] + q : p[1];
      return RotX(p[3]) * RotY(p[4]) * Trans(p[2], zero, zero) * RotZ(theta) *
             Trans(zero, zero, d);
    }
    case Convention::kUrdf: {
      Mat4<T> m =
          Trans(p[0], p[1], p[2]) * RotZ(p[5]) * RotY(p[4]) * RotX(p[3]);
      if (revolute) return m * RotAxis(row.axis, q);
      if (prismatic) {
        return m * Trans(T(row.axis.x()) * q, T(row.axis.y()) * q,
                         T(row.axis.z()) * q);
      }
      return m;
    }
  }
  return Mat4<T>::Identity();
}

// Transmission family hook: an angle error that varies along the joint's
// travel without being a low harmonic of the angle (the kinematic error of a
// gear train, an encoder's non-linearity). Two shapes:
//  - periodic (ChainRow::periodic_basis, revolute joints): a function of the
//    angle over the whole revolution, e(q) = sum_k c_k phi_k(q) (see
//    ChainRow), defined at every angle (a gear's or an encoder's error
//    repeats every turn); no constant term (that is the geometry's offset);
//  - sine series over the travel [lo, hi] of the data, without its mean
//    over the travel:
//      e(q) = sum_k c_k (sin(k pi u) - m_k),  u = (q_read - lo) / (hi - lo),
//      m_k = (1 - cos(k pi)) / (k pi) (the mean of sin(k pi u) on [0, 1]),
//    for k = 1..24 inside the travel, and 0 outside (prismatic joints, and
//    files that state it). RMS over the travel: sqrt(|c|^2 / 2 - (m . c)^2).
// `c` points at kMaxTransmissionTerms values; `sines` (optional) at the
// functions' values at q_read (PoseInput::transmission_sines).
inline double TransmissionMean(int k) {  // m_k, k = 1..24
  return (k % 2 == 1) ? 2.0 / (k * M_PI) : 0.0;
}
// The Fourier terms f_t(q) of the periodic basis (kPeriodicTerms).
inline void PeriodicTerms(double q, double* f) {
  const double c1 = std::cos(q), s1 = std::sin(q);
  double c = c1, s = s1;
  for (int h = 0; h < kPeriodicHarmonics; ++h) {
    f[2 * h] = c;
    f[2 * h + 1] = s;
    const double cn = c * c1 - s * s1;
    s = s * c1 + c * s1;
    c = cn;
  }
}
template <typename T>
T TransmissionError(const T* c, double q_read, const ChainRow& row,
                    const double* sines = nullptr) {
  const bool periodic = row.periodic();
  const double lo = row.transmission_lo, hi = row.transmission_hi;
  if (!periodic && (!(hi > lo) || q_read <= lo || q_read >= hi)) return T(0);
  if (sines != nullptr) {  // precomputed (PoseInput::transmission_sines)
    T e(0);
    for (int k = 0; k < kMaxTransmissionTerms; ++k) e += c[k] * sines[k];
    return e;
  }
  if constexpr (std::is_same_v<T, double>) {  // most joints have no series
    bool any = false;
    for (int k = 0; k < kMaxTransmissionTerms && !any; ++k) any = c[k] != 0.0;
    if (!any) return 0.0;
  }
  T e(0);
  if (periodic) {
    double f[kPeriodicTerms];
    PeriodicTerms(q_read, f);
    for (int k = 0; k < kMaxTransmissionTerms; ++k) {
      if constexpr (std::is_same_v<T, double>) {
        if (c[k] == 0.0) continue;
      }
      const double* b = &row.periodic_basis[kPeriodicTerms * k];
      double phi = 0.0;
      for (int t = 0; t < kPeriodicTerms; ++t) phi += b[t] * f[t];
      e += c[k] * phi;
    }
    return e;
  }
  const double x = M_PI * (q_read - lo) / (hi - lo);
  const double two_cos = 2.0 * std::cos(x);
  double s_prev = 0.0, s = std::sin(x);  // sin(k x) by recurrence
  for (int k = 0; k < kMaxTransmissionTerms; ++k) {
    e += c[k] * (s - TransmissionMean(k + 1));
    const double next = two_cos * s - s_prev;
    s_prev = s;
    s = next;
  }
  return e;
}

// The joint value FK uses for a reading (docs/CONVENTIONS.md):
//   q = (1 + gain) q_read - s backlash / 2 + compliance tau
//       + sum_h cyclic{h}_cos cos(h q_read) + cyclic{h}_sin sin(h q_read)
//       + elastostatic tau_mass + transmission(q_read)
// for harmonics h = 1..3. `err` may be null (no error model). Cyclic terms
// apply to revolute joints; the transmission function to joints with a
// periodic basis or a travel (TransmissionError).
template <typename T>
T ModelJointValue(const ChainRow& row, double q_read, double s, double tau,
                  const T* err, double tau_mass = 0.0) {
  if (err == nullptr) return T(q_read);
  T q = (T(1) + err[kGain]) * q_read - T(0.5 * s) * err[kBacklash] +
        err[kCompliance] * tau + err[kElastostatic] * tau_mass +
        TransmissionError(err + kTransmission0, q_read, row);
  if (row.type == JointType::kRevolute) {
    for (int h = 1; h <= kMaxHarmonic; ++h) {
      const int k = CyclicCosIndex(h);
      q += err[k] * std::cos(h * q_read) + err[k + 1] * std::sin(h * q_read);
    }
  }
  return q;
}

// The same with cos(h q_read), sin(h q_read) precomputed (PoseInput::trig),
// as the fit evaluates it many times per pose.
template <typename T>
T ModelJointValueTrig(const ChainRow& row, double q_read, double s, double tau,
                      const T* err, double tau_mass, const double* trig,
                      const double* transmission_sines = nullptr) {
  if (err == nullptr) return T(q_read);
  T q =
      (T(1) + err[kGain]) * q_read - T(0.5 * s) * err[kBacklash] +
      err[kCompliance] * tau + err[kElastostatic] * tau_mass +
      TransmissionError(err + kTransmission0, q_read, row, transmission_sines);
  if (row.type == JointType::kRevolute) {
    for (int h = 1; h <= kMaxHarmonic; ++h) {
      const int k = CyclicCosIndex(h);
      q += err[k] * trig[2 * (h - 1)] + err[k + 1] * trig[2 * (h - 1) + 1];
    }
  }
  return q;
}

// base_from_tip for model joint values q (internal units), rows[i] pointing
// at row i's geometry block (tool last).
template <typename T>
Mat4<T> BaseFromTip(const Chain& chain, const T* const* rows, const T* q) {
  Mat4<T> m = Mat4<T>::Identity();
  for (int i = 0; i < chain.num_joints(); ++i) {
    m = m * RowTransform(chain.convention, chain.rows[i], rows[i], q[i]);
  }
  return m * RowTransform(chain.convention, chain.rows[chain.tool_row()],
                          rows[chain.tool_row()], T(0));
}

namespace internal {
// Rotations and translations applied to a point, without building matrices.
template <typename T>
Vec3<T> RotZApply(const T& a, const Vec3<T>& x) {
  using std::cos;
  using std::sin;
  const T c = cos(a), s = sin(a);
  return Vec3<T>(c * x[0] - s * x[1], s * x[0] + c * x[1], x[2]);
}
template <typename T>
Vec3<T> RotXApply(const T& a, const Vec3<T>& x) {
  using std::cos;
  using std::sin;
  const T c = cos(a), s = sin(a);
  return Vec3<T>(x[0], c * x[1] - s * x[2], s * x[1] + c * x[2]);
}
template <typename T>
Vec3<T> RotYApply(const T& a, const Vec3<T>& x) {
  using std::cos;
  using std::sin;
  const T c = cos(a), s = sin(a);
  return Vec3<T>(c * x[0] + s * x[2], x[1], -s * x[0] + c * x[2]);
}
template <typename T>
Vec3<T> RotAxisApply(const Eigen::Vector3d& u, const T& a, const Vec3<T>& x) {
  using std::cos;
  using std::sin;
  const T c = cos(a), s = sin(a);
  const Vec3<T> uu = u.cast<T>();
  return x * c + uu.cross(x) * s + uu * (uu.dot(x) * (T(1) - c));
}
}  // namespace internal

// The same transform as RowTransform, applied to a point x (next frame) to
// give it in the previous frame; cheaper than the matrix for autodiff.
template <typename T>
Vec3<T> RowApply(Convention convention, const ChainRow& row, const T* p,
                 const T& q, const Vec3<T>& x) {
  using internal::RotAxisApply;
  using internal::RotXApply;
  using internal::RotYApply;
  using internal::RotZApply;
  const bool revolute = row.type == JointType::kRevolute;
  const bool prismatic = row.type == JointType::kPrismatic;
  switch (convention) {
    case Convention::kDh: {  // Rz(theta + q) Tz(d + q) Tx(a) Rx(alpha) Ry(beta)
      Vec3<T> y = RotXApply(p[3], RotYApply(p[4], x));
      y[0] += p[2];
      y[2] += prismatic ? p[1] + q : p[1];
      return RotZApply(revolute ? p[0] + q : p[0], y);
    }
    case Convention::kMdh: {  // Rx(alpha) Ry(beta) Tx(a) Rz(theta + q) Tz(d +
                              // q)
      Vec3<T> y = x;
      y[2] += prismatic ? p[1] + q : p[1];
      y = RotZApply(revolute ? p[0] + q : p[0], y);
      y[0] += p[2];
      return RotXApply(p[3], RotYApply(p[4], y));
    }
    case Convention::kUrdf: {  // T(xyz) Rz(yaw) Ry(pitch) Rx(roll) [joint]
      Vec3<T> y = x;
      if (revolute) y = RotAxisApply(row.axis, q, y);
      if (prismatic) {
        for (int k = 0; k < 3; ++k) y[k] += T(row.axis[k]) * q;
      }
      y = RotZApply(p[5], RotYApply(p[4], RotXApply(p[3], y)));
      return Vec3<T>(y[0] + p[0], y[1] + p[1], y[2] + p[2]);
    }
  }
  return x;
}

// The tip (origin of the last frame) in the base frame for model joint
// values q: rows applied to the point from the tool back to the base.
template <typename T>
Vec3<T> TipPosition(const Chain& chain, const T* const* rows, const T* q) {
  Vec3<T> p = RowApply(chain.convention, chain.rows[chain.tool_row()],
                       rows[chain.tool_row()], T(0), Vec3<T>(T(0), T(0), T(0)));
  for (int i = chain.num_joints() - 1; i >= 0; --i) {
    p = RowApply(chain.convention, chain.rows[i], rows[i], q[i], p);
  }
  return p;
}

// Thermal family hook: the row's lengths scaled by (1 + thermal x):
// dh / mdh d and a, urdf x, y, z.
template <typename T>
void ScaleRowLengths(Convention convention, const T& factor, T* p) {
  if (convention == Convention::kUrdf) {
    for (int k = 0; k < 3; ++k) p[k] *= factor;
  } else {
    p[1] *= factor;
    p[2] *= factor;
  }
}

// Mount family hook: the base tilts by w = C M (see kMountIso) about the
// base origin; returns the tip moved by w x p.
template <typename T>
Vec3<T> MountTilt(const T* global, const Eigen::Vector3d& moment,
                  const Vec3<T>& p) {
  const T wx = (global[kMountIso] + global[kMountCos]) * moment.x() +
               global[kMountSin] * moment.y();
  const T wy = global[kMountSin] * moment.x() +
               (global[kMountIso] - global[kMountCos]) * moment.y();
  const Vec3<T> w(wx, wy, T(0));
  return p + w.cross(p);
}

// The needle tip in the base frame for one pose: error model, FK, drift,
// mount tilt. `joint_errors` (one block per joint) and `drift` (the global
// block) may be null.
template <typename T>
Vec3<T> TipInBase(const Chain& chain, const T* const* rows,
                  const T* const* joint_errors, const T* drift,
                  const PoseInput& in) {
  constexpr int kMaxJoints = 16;
  T q[kMaxJoints];
  const bool masses =
      static_cast<int>(in.tau_mass.size()) == chain.num_joints();
  const bool trig =
      static_cast<int>(in.trig.size()) == 2 * kMaxHarmonic * chain.num_joints();
  const bool sines = static_cast<int>(in.transmission_sines.size()) ==
                     kMaxTransmissionTerms * chain.num_joints();
  for (int j = 0; j < chain.num_joints(); ++j) {
    const double tm = masses ? in.tau_mass[j] : 0.0;
    const T* err = joint_errors ? joint_errors[j] : nullptr;
    const ChainRow& row = chain.rows[j];
    q[j] = trig ? ModelJointValueTrig<T>(
                      row, in.q[j], in.s[j], in.tau[j], err, tm,
                      &in.trig[2 * kMaxHarmonic * j],
                      sines ? &in.transmission_sines[kMaxTransmissionTerms * j]
                            : nullptr)
                : ModelJointValue<T>(row, in.q[j], in.s[j], in.tau[j], err, tm);
  }
  Vec3<T> p;
  const double thermal_x = chain.ThermalInput(in.thermal_x);
  if (joint_errors != nullptr && thermal_x != 0.0) {
    // Thermal growth: rows with their lengths scaled (copies).
    T buf[kMaxJoints + 1][kRowBlockSize];
    const T* scaled[kMaxJoints + 1];
    for (int r = 0; r <= chain.num_joints(); ++r) {
      for (int k = 0; k < kRowBlockSize; ++k) buf[r][k] = rows[r][k];
      if (r < chain.num_joints()) {
        ScaleRowLengths(chain.convention,
                        T(1) + joint_errors[r][kThermal] * thermal_x, buf[r]);
      }
      scaled[r] = buf[r];
    }
    p = TipPosition(chain, scaled, q);
  } else {
    p = TipPosition(chain, rows, q);
  }
  if (drift != nullptr) {
    for (int k = 0; k < 3; ++k) p[k] += drift[k] * in.t_h;
    p = MountTilt(drift, in.moment, p);
  }
  return p;
}

// p_in_meas = meas_from_base * p_in_base with frame = [angle-axis, t].
template <typename T>
Vec3<T> ApplyFrame(const T* frame, const Vec3<T>& p_in_base) {
  using std::cos;
  using std::sin;
  using std::sqrt;
  // Rodrigues with the small-angle branch, as ceres::AngleAxisRotatePoint.
  const T theta2 =
      frame[0] * frame[0] + frame[1] * frame[1] + frame[2] * frame[2];
  Vec3<T> r;
  if (theta2 > T(1e-24)) {
    const T theta = sqrt(theta2);
    const T c = cos(theta), s = sin(theta);
    const Vec3<T> w(frame[0] / theta, frame[1] / theta, frame[2] / theta);
    const Vec3<T> wxp = w.cross(p_in_base);
    const T wdp = w.dot(p_in_base);
    r = p_in_base * c + wxp * s + w * (wdp * (T(1) - c));
  } else {
    const Vec3<T> w(frame[0], frame[1], frame[2]);
    r = p_in_base + w.cross(p_in_base);
  }
  return Vec3<T>(r[0] + frame[3], r[1] + frame[4], r[2] + frame[5]);
}

// Plain-double conveniences over the templated functions above.
Eigen::Vector3d TipInBase(const Chain& chain, const PoseInput& in,
                          bool with_errors = true);
Eigen::Matrix4d BaseFromTipAt(const Chain& chain,
                              const std::vector<double>& q_internal);
// The joint values FK uses for a pose (ModelJointValue of every joint), and
// base_from_tip through the whole error model: the position is TipInBase's;
// the rotation is FK's at those joint values, tilted by the mount family.
std::vector<double> ModelJointValues(const Chain& chain, const PoseInput& in);
Eigen::Matrix4d ModelBaseFromTip(const Chain& chain, const PoseInput& in);
// Frames of every joint axis (base_from_link before joint j's motion), used
// for gravity torques: origin and unit axis of joint j in the base frame.
void JointAxesInBase(const Chain& chain, const std::vector<double>& q_internal,
                     std::vector<Eigen::Vector3d>* origins,
                     std::vector<Eigen::Vector3d>* axes);

}  // namespace kincal

#endif  // KINCAL_CALIB_CHAIN_H_
