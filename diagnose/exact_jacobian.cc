#include "diagnose/exact_jacobian.h"

#include <ceres/jet.h>

#include <Eigen/Geometry>
#include <array>

#include "data/error.h"

namespace kincal {
namespace {

constexpr int kMaxJoints = 16;

// One elementary operation of a row: a rotation about or a translation
// along a unit axis of the frame it acts in. `param` is the row block entry
// it carries (-1: none), `joint` whether the joint value enters it.
struct Op {
  bool rotation = false;
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();
  int param = -1;
  bool joint = false;
};

// The row's operations in order (calib/chain.h RowTransform).
int RowOps(Convention convention, const ChainRow& row, Op* ops) {
  const bool revolute = row.type == JointType::kRevolute;
  const bool prismatic = row.type == JointType::kPrismatic;
  const Eigen::Vector3d x = Eigen::Vector3d::UnitX(),
                        y = Eigen::Vector3d::UnitY(),
                        z = Eigen::Vector3d::UnitZ();
  switch (convention) {
    case Convention::kDh:  // Rz(theta + q) Tz(d + q) Tx(a) Rx(alpha) Ry(beta)
      ops[0] = {true, z, 0, revolute};
      ops[1] = {false, z, 1, prismatic};
      ops[2] = {false, x, 2, false};
      ops[3] = {true, x, 3, false};
      ops[4] = {true, y, 4, false};
      return 5;
    case Convention::kMdh:  // Rx(alpha) Ry(beta) Tx(a) Rz(theta + q) Tz(d + q)
      ops[0] = {true, x, 3, false};
      ops[1] = {true, y, 4, false};
      ops[2] = {false, x, 2, false};
      ops[3] = {true, z, 0, revolute};
      ops[4] = {false, z, 1, prismatic};
      return 5;
    case Convention::kUrdf: {  // T(xyz) Rz(yaw) Ry(pitch) Rx(roll) joint
      ops[0] = {false, x, 0, false};
      ops[1] = {false, y, 1, false};
      ops[2] = {false, z, 2, false};
      ops[3] = {true, z, 5, false};
      ops[4] = {true, y, 4, false};
      ops[5] = {true, x, 3, false};
      if (revolute || prismatic) {
        ops[6] = {revolute, row.axis.normalized(), -1, true};
        return 7;
      }
      return 6;
    }
  }
  return 0;
}

// Row block entries that are lengths (scaled by the thermal family).
bool IsLength(Convention convention, int index) {
  return convention == Convention::kUrdf ? index < 3
                                         : (index == 1 || index == 2);
}

Eigen::Matrix3d AxisRotation(const Eigen::Vector3d& axis, double angle) {
  return Eigen::AngleAxisd(angle, axis).toRotationMatrix();
}

}  // namespace

void ResidualsAndJacobian(const std::vector<Measurement>& measurements,
                          const ModelState& state,
                          const std::vector<ParamInfo>& params,
                          Eigen::VectorXd* r, Eigen::MatrixXd* J) {
  const Chain& chain = state.chain;
  const int n = chain.num_joints();
  KINCAL_CHECK(n <= kMaxJoints, "too many joints");
  const int m = static_cast<int>(measurements.size());
  const int k = static_cast<int>(params.size());
  r->setZero(3 * m);
  if (J != nullptr) J->setZero(3 * m, k);
  const double* rows[kMaxJoints + 1];
  const double* errs[kMaxJoints];
  for (int i = 0; i <= n; ++i) rows[i] = chain.rows[i].p.data();
  for (int j = 0; j < n; ++j) errs[j] = chain.joint_errors[j].data();
  // Operations of every row (structure only).
  std::array<std::array<Op, 7>, kMaxJoints + 1> ops;
  std::array<int, kMaxJoints + 1> num_ops;
  for (int i = 0; i <= n; ++i)
    num_ops[i] = RowOps(chain.convention, chain.rows[i], ops[i].data());

  using JetE = ceres::Jet<double, kJointErrorBlockSize>;
  using Jet9 = ceres::Jet<double, 9>;
  for (int pose = 0; pose < m; ++pose) {
    const Measurement& meas = measurements[pose];
    if (meas.kind != Measurement::kMeasured) continue;
    const PoseInput& in = meas.input;
    // Residual from the shared chain.
    const Vec3<double> tip_value =
        TipInBase<double>(chain, rows, errs, chain.drift.data(), in);
    const Vec3<double> res =
        ApplyFrame(state.meas_from_base.data(), tip_value) - meas.p_in_meas;
    r->segment<3>(3 * pose) = res;
    if (J == nullptr || k == 0) continue;

    // Joint values and their derivatives by the joint error entries.
    const bool masses = static_cast<int>(in.tau_mass.size()) == n;
    const bool trig = static_cast<int>(in.trig.size()) == 2 * kMaxHarmonic * n;
    double q[kMaxJoints];
    Eigen::Matrix<double, kJointErrorBlockSize, 1> dq[kMaxJoints];
    for (int j = 0; j < n; ++j) {
      JetE e[kJointErrorBlockSize];
      for (int t = 0; t < kJointErrorBlockSize; ++t)
        e[t] = JetE(chain.joint_errors[j][t], t);
      const double tm = masses ? in.tau_mass[j] : 0.0;
      const JetE qj =
          trig ? ModelJointValueTrig<JetE>(chain.rows[j].type, in.q[j], in.s[j],
                                           in.tau[j], e, tm,
                                           &in.trig[2 * kMaxHarmonic * j])
               : ModelJointValue<JetE>(chain.rows[j].type, in.q[j], in.s[j],
                                       in.tau[j], e, tm);
      q[j] = qj.a;
      dq[j] = qj.v;
    }
    // Thermal scaling of the rows' lengths (calib/chain.h TipInBase).
    const bool thermal = in.thermal_x != 0.0;
    double scaled[kMaxJoints + 1][kRowBlockSize];
    double factor[kMaxJoints + 1];
    for (int i = 0; i <= n; ++i) {
      for (int t = 0; t < kRowBlockSize; ++t) scaled[i][t] = rows[i][t];
      factor[i] = 1.0;
      if (thermal && i < n) {
        factor[i] = 1.0 + chain.joint_errors[i][kThermal] * in.thermal_x;
        ScaleRowLengths(chain.convention, factor[i], scaled[i]);
      }
    }
    // Forward pass: axis and origin of every operation in the base frame.
    Eigen::Vector3d axis_w[kMaxJoints + 1][7], origin_w[kMaxJoints + 1][7];
    Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
    Eigen::Vector3d t = Eigen::Vector3d::Zero();
    for (int i = 0; i <= n; ++i) {
      const double qi = i < n ? q[i] : 0.0;
      for (int o = 0; o < num_ops[i]; ++o) {
        const Op& op = ops[i][o];
        double amount = op.param >= 0 ? scaled[i][op.param] : 0.0;
        if (op.joint) amount += qi;
        axis_w[i][o] = R * op.axis;
        origin_w[i][o] = t;
        if (op.rotation) {
          if (amount != 0.0) R = R * AxisRotation(op.axis, amount);
        } else {
          t += axis_w[i][o] * amount;
        }
      }
    }
    const Eigen::Vector3d tip = t;  // before drift and mount tilt
    auto d_op = [&](int i, int o) -> Eigen::Vector3d {
      return ops[i][o].rotation
                 ? Eigen::Vector3d(axis_w[i][o].cross(tip - origin_w[i][o]))
                 : axis_w[i][o];
    };
    // d tip / d scaled row entry, d tip / d q.
    Eigen::Vector3d d_row[kMaxJoints + 1][kRowBlockSize];
    Eigen::Vector3d d_q[kMaxJoints];
    for (int i = 0; i <= n; ++i) {
      for (int e = 0; e < kRowBlockSize; ++e) d_row[i][e].setZero();
      if (i < n) d_q[i].setZero();
      for (int o = 0; o < num_ops[i]; ++o) {
        const Eigen::Vector3d d = d_op(i, o);
        if (ops[i][o].param >= 0) d_row[i][ops[i][o].param] += d;
        if (ops[i][o].joint && i < n) d_q[i] += d;
      }
    }
    // Drift, mount tilt and frame (the shared hooks, autodiff): inputs
    // global[0..5] | p[0..2], then frame[0..5] | p[0..2].
    const Eigen::Vector3d drifted =
        tip + Eigen::Vector3d(chain.drift[0], chain.drift[1], chain.drift[2]) *
                  in.t_h;
    Jet9 g[kDriftBlockSize];
    for (int e = 0; e < kDriftBlockSize; ++e) g[e] = Jet9(chain.drift[e], e);
    const Vec3<Jet9> pm(Jet9(drifted[0], 6), Jet9(drifted[1], 7),
                        Jet9(drifted[2], 8));
    const Vec3<Jet9> tilted = MountTilt(g, in.moment, pm);
    Jet9 f[kFrameBlockSize];
    for (int e = 0; e < kFrameBlockSize; ++e)
      f[e] = Jet9(state.meas_from_base[e], e);
    const Vec3<Jet9> pf(Jet9(tilted[0].a, 6), Jet9(tilted[1].a, 7),
                        Jet9(tilted[2].a, 8));
    const Vec3<Jet9> out = ApplyFrame(f, pf);
    Eigen::Matrix3d d_frame_p, d_mount_p;
    Eigen::Matrix<double, 3, 6> d_frame, d_global;
    for (int a = 0; a < 3; ++a) {
      d_frame.row(a) = out[a].v.head<6>().transpose();
      d_frame_p.row(a) = out[a].v.tail<3>().transpose();
      d_global.row(a) = tilted[a].v.head<6>().transpose();
      d_mount_p.row(a) = tilted[a].v.tail<3>().transpose();
    }
    const Eigen::Matrix3d d_tip = d_frame_p * d_mount_p;  // dr / d tip
    d_global = d_frame_p * d_global;
    for (int c = 0; c < k; ++c) {
      const ParamInfo& p = params[c];
      Eigen::Vector3d col = Eigen::Vector3d::Zero();
      switch (p.kind) {
        case ParamKind::kRow: {
          const int i = p.block;
          col = d_tip * d_row[i][p.index];
          if (IsLength(chain.convention, p.index)) col *= factor[i];
          break;
        }
        case ParamKind::kJointError: {
          const int j = p.block;
          if (p.index == kThermal) {
            Eigen::Vector3d d = Eigen::Vector3d::Zero();
            if (thermal) {
              for (int e = 0; e < kRowBlockSize; ++e) {
                if (IsLength(chain.convention, e))
                  d += d_row[j][e] * (rows[j][e] * in.thermal_x);
              }
            }
            col = d_tip * d;
          } else {
            col = d_tip * d_q[j] * dq[j][p.index];
          }
          break;
        }
        case ParamKind::kDrift:
          col = d_global.col(p.index);
          if (p.index < 3) col += d_tip.col(p.index) * in.t_h;
          break;
        case ParamKind::kFrame:
          col = d_frame.col(p.index);
          break;
        case ParamKind::kPoint:
          break;  // measured rows do not depend on fixed points
      }
      J->block<3, 1>(3 * pose, c) = col;
    }
  }
}

}  // namespace kincal
