#include "calib/exact_jacobian.h"

#include <ceres/jet.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>

#include "data/error.h"
#include "data/parallel.h"

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

// 0, 1, 2 when `axis` is the x, y or z unit vector, else -1.
int CoordinateAxis(const Eigen::Vector3d& axis) {
  for (int c = 0; c < 3; ++c)
    if (axis == Eigen::Vector3d::Unit(c)) return c;
  return -1;
}

// R <- R * rotation(axis, angle): about a coordinate axis only two columns
// change; any other axis by the full product.
void RotateInPlace(int coordinate, const Eigen::Vector3d& axis, double c,
                   double s, double angle, Eigen::Matrix3d* R) {
  if (coordinate < 0) {
    *R = *R * AxisRotation(axis, angle);
    return;
  }
  const int a = (coordinate + 1) % 3, b = (coordinate + 2) % 3;
  const Eigen::Vector3d ca = R->col(a), cb = R->col(b);
  R->col(a) = c * ca + s * cb;
  R->col(b) = c * cb - s * ca;
}

// The chain's operations per row and the rotations that do not depend on
// the pose (every rotation but the joint's own): computed once per call.
struct ChainOps {
  std::array<std::array<Op, 7>, kMaxJoints + 1> ops;
  std::array<std::array<double, 7>, kMaxJoints + 1> fixed_c, fixed_s;
  std::array<std::array<int, 7>, kMaxJoints + 1> coordinate;
  std::array<int, kMaxJoints + 1> num_ops;
};

void MakeChainOps(const Chain& chain, ChainOps* out) {
  ChainOps& c = *out;
  for (int i = 0; i <= chain.num_joints(); ++i) {
    c.num_ops[i] = RowOps(chain.convention, chain.rows[i], c.ops[i].data());
    for (int o = 0; o < c.num_ops[i]; ++o) {
      const Op& op = c.ops[i][o];
      c.coordinate[i][o] = CoordinateAxis(op.axis);
      // The row entry's angle (for a joint's rotation: its offset theta).
      c.fixed_c[i][o] = 1.0;
      c.fixed_s[i][o] = 0.0;
      if (op.rotation && op.param >= 0) {
        c.fixed_c[i][o] = std::cos(chain.rows[i].p[op.param]);
        c.fixed_s[i][o] = std::sin(chain.rows[i].p[op.param]);
      }
    }
  }
}

// The measuring frame is linear in the point, ApplyFrame(f, p) = r p + t:
// r and dr / d(rotation vector) from the shared ApplyFrame (autodiff).
struct LinearFrame {
  Eigen::Matrix3d r, dr[3];
  Eigen::Vector3d t;
};

LinearFrame MakeLinearFrame(const double* meas_from_base) {
  using Jet3 = ceres::Jet<double, 3>;
  LinearFrame frame;
  Jet3 f[kFrameBlockSize];
  for (int e = 0; e < kFrameBlockSize; ++e)
    f[e] = e < 3 ? Jet3(meas_from_base[e], e) : Jet3(0.0);
  for (int c = 0; c < 3; ++c) {
    Vec3<Jet3> unit(Jet3(0.0), Jet3(0.0), Jet3(0.0));
    unit[c] = Jet3(1.0);
    const Vec3<Jet3> col = ApplyFrame(f, unit);
    for (int a = 0; a < 3; ++a) {
      frame.r(a, c) = col[a].a;
      for (int d = 0; d < 3; ++d) frame.dr[d](a, c) = col[a].v[d];
    }
  }
  frame.t =
      Eigen::Vector3d(meas_from_base[3], meas_from_base[4], meas_from_base[5]);
  return frame;
}

// Which hooks need derivatives: joint values of joints with a free joint
// error entry (thermal aside), the global block. The free entries of each
// joint's error block are differentiated in chunks of kChunk (the joint
// value is cheap; a Jet over the whole block would mostly carry zeros).
struct FreeHooks {
  bool need_dq[kMaxJoints] = {};
  std::vector<int> free_entries[kMaxJoints];
  bool need_global = false;
};

FreeHooks FindFreeHooks(const std::vector<ParamInfo>& params) {
  FreeHooks hooks;
  for (const ParamInfo& p : params) {
    if (p.kind == ParamKind::kJointError && p.index != kThermal) {
      hooks.need_dq[p.block] = true;
      std::vector<int>& f = hooks.free_entries[p.block];
      if (std::find(f.begin(), f.end(), p.index) == f.end())
        f.push_back(p.index);
    }
    if (p.kind == ParamKind::kDrift) hooks.need_global = true;
  }
  return hooks;
}

// Joint values of one pose (calib/chain.h TipInBase) and, for the joints
// whose error entries are free, their derivatives by those entries.
struct JointValues {
  double q[kMaxJoints];
  Eigen::Matrix<double, kJointErrorBlockSize, 1> dq[kMaxJoints];
  bool trig = false;  // PoseInput::trig holds the read angles' cos / sin
};

void ComputeJointValues(const Chain& chain, const PoseInput& in,
                        const FreeHooks& hooks, JointValues* out) {
  constexpr int kChunk = 8;
  using JetE = ceres::Jet<double, kChunk>;
  const int n = chain.num_joints();
  const bool masses = static_cast<int>(in.tau_mass.size()) == n;
  const bool trig = static_cast<int>(in.trig.size()) == 2 * kMaxHarmonic * n;
  out->trig = trig;
  for (int j = 0; j < n; ++j) {
    const double tm = masses ? in.tau_mass[j] : 0.0;
    const double* tr = trig ? &in.trig[2 * kMaxHarmonic * j] : nullptr;
    const ChainRow& row = chain.rows[j];
    const double* ts = static_cast<int>(in.transmission_sines.size()) ==
                               kMaxTransmissionTerms * n
                           ? &in.transmission_sines[kMaxTransmissionTerms * j]
                           : nullptr;
    if (!hooks.need_dq[j]) {
      const double* e = chain.joint_errors[j].data();
      out->q[j] = trig ? ModelJointValueTrig<double>(row, in.q[j], in.s[j],
                                                     in.tau[j], e, tm, tr, ts)
                       : ModelJointValue<double>(row, in.q[j], in.s[j],
                                                 in.tau[j], e, tm);
      continue;
    }
    const std::vector<int>& f = hooks.free_entries[j];
    JetE e[kJointErrorBlockSize];
    for (int t = 0; t < kJointErrorBlockSize; ++t)
      e[t] = JetE(chain.joint_errors[j][t]);
    for (size_t first = 0; first < f.size(); first += kChunk) {
      const size_t last = std::min(f.size(), first + kChunk);
      for (size_t c = first; c < last; ++c)
        e[f[c]] = JetE(chain.joint_errors[j][f[c]], int(c - first));
      const JetE qj =
          trig ? ModelJointValueTrig<JetE>(row, in.q[j], in.s[j], in.tau[j], e,
                                           tm, tr, ts)
               : ModelJointValue<JetE>(row, in.q[j], in.s[j], in.tau[j], e, tm);
      out->q[j] = qj.a;
      for (size_t c = first; c < last; ++c) {
        out->dq[j][f[c]] = qj.v[c - first];
        e[f[c]] = JetE(chain.joint_errors[j][f[c]]);
      }
    }
  }
}

// One pose's forward pass: the tip before drift and mount tilt, the
// thermal scaling of each row's lengths, and (with `keep_axes`) axis and
// origin of every operation in the base frame.
struct ForwardPass {
  Eigen::Vector3d axis_w[kMaxJoints + 1][7], origin_w[kMaxJoints + 1][7];
  Eigen::Vector3d tip;
  double factor[kMaxJoints + 1];
  bool thermal = false;
};

void RunForwardPass(const Chain& chain, const ChainOps& c, const PoseInput& in,
                    const JointValues& joints, bool keep_axes,
                    ForwardPass* out) {
  const int n = chain.num_joints();
  const double* q = joints.q;
  // Thermal scaling of the rows' lengths (calib/chain.h TipInBase).
  const double thermal_x = chain.ThermalInput(in.thermal_x);
  out->thermal = thermal_x != 0.0;
  for (int i = 0; i <= n; ++i) {
    out->factor[i] = out->thermal && i < n
                         ? 1.0 + chain.joint_errors[i][kThermal] * thermal_x
                         : 1.0;
  }
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  Eigen::Vector3d t = Eigen::Vector3d::Zero();
  for (int i = 0; i <= n; ++i) {
    const RowBlock& p = chain.rows[i].p;
    for (int o = 0; o < c.num_ops[i]; ++o) {
      const Op& op = c.ops[i][o];
      const int axis = c.coordinate[i][o];
      const Eigen::Vector3d w = axis >= 0 ? Eigen::Vector3d(R.col(axis))
                                          : Eigen::Vector3d(R * op.axis);
      if (keep_axes) {
        out->axis_w[i][o] = w;
        out->origin_w[i][o] = t;
      }
      if (op.rotation) {
        if (!op.joint) {
          if (c.fixed_s[i][o] != 0.0 || c.fixed_c[i][o] != 1.0)
            RotateInPlace(axis, op.axis, c.fixed_c[i][o], c.fixed_s[i][o],
                          p[op.param], &R);
        } else if (joints.trig && q[i] == in.q[i]) {
          // No joint error: cos / sin of theta + q from the read angle's
          // precomputed ones (PoseInput::trig).
          const double cq = in.trig[2 * kMaxHarmonic * i];
          const double sq = in.trig[2 * kMaxHarmonic * i + 1];
          const double cs = c.fixed_c[i][o] * cq - c.fixed_s[i][o] * sq;
          const double sn = c.fixed_s[i][o] * cq + c.fixed_c[i][o] * sq;
          const double angle = (op.param >= 0 ? p[op.param] : 0.0) + q[i];
          RotateInPlace(axis, op.axis, cs, sn, angle, &R);
        } else {
          const double angle = (op.param >= 0 ? p[op.param] : 0.0) + q[i];
          RotateInPlace(axis, op.axis, std::cos(angle), std::sin(angle), angle,
                        &R);
        }
      } else {
        double amount = op.param >= 0 ? p[op.param] : 0.0;
        if (op.param >= 0 && IsLength(chain.convention, op.param))
          amount *= out->factor[i];
        if (op.joint) amount += q[i];
        t += w * amount;
      }
    }
  }
  out->tip = t;
}

// d tip / d (scaled) row entry and d tip / d q of one pose: w x (tip - o)
// for a rotation, w for a translation.
struct TipDerivatives {
  Eigen::Vector3d d_row[kMaxJoints + 1][kRowBlockSize];
  Eigen::Vector3d d_q[kMaxJoints];
};

void ComputeTipDerivatives(const ChainOps& c, const ForwardPass& fwd, int n,
                           TipDerivatives* out) {
  for (int i = 0; i <= n; ++i) {
    for (int e = 0; e < kRowBlockSize; ++e) out->d_row[i][e].setZero();
    if (i < n) out->d_q[i].setZero();
    for (int o = 0; o < c.num_ops[i]; ++o) {
      const Eigen::Vector3d d = c.ops[i][o].rotation
                                    ? Eigen::Vector3d(fwd.axis_w[i][o].cross(
                                          fwd.tip - fwd.origin_w[i][o]))
                                    : fwd.axis_w[i][o];
      if (c.ops[i][o].param >= 0) out->d_row[i][c.ops[i][o].param] += d;
      if (c.ops[i][o].joint && i < n) out->d_q[i] += d;
    }
  }
}

// Mount tilt's derivatives (the shared hook, autodiff) at the drifted tip:
// by the point and, when a global entry is free, by global[0..5].
void MountTiltDerivatives(const Chain& chain, const PoseInput& in,
                          const Eigen::Vector3d& drifted, bool need_global,
                          Eigen::Matrix3d* d_mount_p,
                          Eigen::Matrix<double, 3, 6>* d_global) {
  d_global->setZero();
  if (need_global) {
    using Jet9 = ceres::Jet<double, 9>;
    Jet9 g[kDriftBlockSize];
    for (int e = 0; e < kDriftBlockSize; ++e) g[e] = Jet9(chain.drift[e], e);
    const Vec3<Jet9> pm(Jet9(drifted[0], 6), Jet9(drifted[1], 7),
                        Jet9(drifted[2], 8));
    const Vec3<Jet9> tilt = MountTilt(g, in.moment, pm);
    for (int a = 0; a < 3; ++a) {
      d_global->row(a) = tilt[a].v.head<6>().transpose();
      d_mount_p->row(a) = tilt[a].v.tail<3>().transpose();
    }
    return;
  }
  using Jet3 = ceres::Jet<double, 3>;
  Jet3 g[kDriftBlockSize];
  for (int e = 0; e < kDriftBlockSize; ++e) g[e] = Jet3(chain.drift[e]);
  const Vec3<Jet3> pm(Jet3(drifted[0], 0), Jet3(drifted[1], 1),
                      Jet3(drifted[2], 2));
  const Vec3<Jet3> tilt = MountTilt(g, in.moment, pm);
  for (int a = 0; a < 3; ++a) d_mount_p->row(a) = tilt[a].v.transpose();
}

// One pose's derivatives, in the measuring frame where they meet the
// residual.
struct PoseDerivatives {
  const Chain* chain = nullptr;
  const PoseInput* in = nullptr;
  const LinearFrame* frame = nullptr;
  int frame_index = 0;  // Measurement::frame
  const JointValues* joints = nullptr;
  const ForwardPass* fwd = nullptr;
  const TipDerivatives* tip = nullptr;
  Eigen::Matrix3d d_tip;                 // dr / d tip
  Eigen::Matrix<double, 3, 6> d_global;  // dr / d global[0..5]
  Eigen::Vector3d tilted;                // the tip after drift and tilt
};

// The residual's derivative by one parameter (internal units).
Eigen::Vector3d JacobianColumn(const PoseDerivatives& d, const ParamInfo& p) {
  const Chain& chain = *d.chain;
  const PoseInput& in = *d.in;
  switch (p.kind) {
    case ParamKind::kRow: {
      Eigen::Vector3d col = d.d_tip * d.tip->d_row[p.block][p.index];
      if (IsLength(chain.convention, p.index)) col *= d.fwd->factor[p.block];
      return col;
    }
    case ParamKind::kJointError: {
      const int j = p.block;
      if (p.index != kThermal)
        return d.d_tip * d.tip->d_q[j] * d.joints->dq[j][p.index];
      Eigen::Vector3d dt = Eigen::Vector3d::Zero();
      if (d.fwd->thermal) {
        for (int e = 0; e < kRowBlockSize; ++e) {
          if (IsLength(chain.convention, e))
            dt += d.tip->d_row[j][e] *
                  (chain.rows[j].p[e] * chain.ThermalInput(in.thermal_x));
        }
      }
      return d.d_tip * dt;
    }
    case ParamKind::kDrift: {
      Eigen::Vector3d col = d.d_global.col(p.index);
      if (p.index < 3) col += d.d_tip.col(p.index) * in.t_h;
      return col;
    }
    case ParamKind::kFrame:
      if (p.block != d.frame_index) break;  // another series' frame
      return p.index < 3 ? Eigen::Vector3d(d.frame->dr[p.index] * d.tilted)
                         : Eigen::Vector3d::Unit(p.index - 3);
    case ParamKind::kPoint:
      break;  // measured rows do not depend on fixed points
  }
  return Eigen::Vector3d::Zero();
}

}  // namespace

void ResidualsAndJacobian(const std::vector<Measurement>& measurements,
                          const ModelState& state,
                          const std::vector<ParamInfo>& params,
                          Eigen::VectorXd* r, Eigen::MatrixXd* J, int threads) {
  const Chain& chain = state.chain;
  const int n = chain.num_joints();
  KINCAL_CHECK(n <= kMaxJoints, "too many joints");
  const int m = static_cast<int>(measurements.size());
  const int k = static_cast<int>(params.size());
  r->setZero(3 * m);
  const bool jacobian = J != nullptr && k > 0;
  if (J != nullptr) J->setZero(3 * m, k);
  ChainOps ops;
  MakeChainOps(chain, &ops);
  std::vector<LinearFrame> frames;
  for (int f = 0; f < state.NumFrames(); ++f)
    frames.push_back(MakeLinearFrame(state.FrameBlock(f)));
  const FreeHooks hooks = jacobian ? FindFreeHooks(params) : FreeHooks{};
  // Each block of poses on its own thread: the rows are independent and
  // the chain's operations, frames and hooks are read only.
  const auto pose_block = [&](int begin, int end) {
    JointValues joints;
    ForwardPass fwd;
    TipDerivatives tip;
    for (int pose = begin; pose < end; ++pose) {
      const Measurement& meas = measurements[pose];
      if (meas.kind != Measurement::kMeasured) continue;
      const PoseInput& in = meas.input;
      const LinearFrame& frame = frames[meas.frame];
      ComputeJointValues(chain, in, hooks, &joints);
      RunForwardPass(chain, ops, in, joints, jacobian, &fwd);
      // Drift and mount tilt (calib/chain.h TipInBase), then the frame.
      const Eigen::Vector3d drifted =
          fwd.tip +
          Eigen::Vector3d(chain.drift[0], chain.drift[1], chain.drift[2]) *
              in.t_h;
      const Vec3<double> tilted =
          MountTilt<double>(chain.drift.data(), in.moment, drifted);
      r->segment<3>(3 * pose) = frame.r * tilted + frame.t - meas.p_in_meas;
      if (!jacobian) continue;

      ComputeTipDerivatives(ops, fwd, n, &tip);
      Eigen::Matrix3d d_mount_p;
      PoseDerivatives d;
      MountTiltDerivatives(chain, in, drifted, hooks.need_global, &d_mount_p,
                           &d.d_global);
      d.chain = &chain;
      d.in = &in;
      d.frame = &frame;
      d.frame_index = meas.frame;
      d.joints = &joints;
      d.fwd = &fwd;
      d.tip = &tip;
      d.d_tip = frame.r * d_mount_p;
      d.d_global = frame.r * d.d_global;
      d.tilted = tilted;
      for (int c = 0; c < k; ++c)
        J->block<3, 1>(3 * pose, c) = JacobianColumn(d, params[c]);
    }
  };
  for (const Measurement& meas : measurements) {
    KINCAL_CHECK(
        meas.kind != Measurement::kMeasured ||
            (meas.frame >= 0 && meas.frame < state.NumFrames()),
        "a measured row's frame " << meas.frame << " of " << state.NumFrames());
  }
  // Below a few hundred poses a thread costs more than it saves.
  constexpr int kPosesPerThread = 256;
  const std::vector<std::pair<int, int>> blocks =
      EvenRanges(m, std::min(threads, m / kPosesPerThread));
  ParallelFor(static_cast<int>(blocks.size()), static_cast<int>(blocks.size()),
              [&](int b) { pose_block(blocks[b].first, blocks[b].second); });
}

Eigen::MatrixXd NormalMatrix(const Eigen::MatrixXd& J, int threads) {
  const int k = static_cast<int>(J.cols());
  // Below a few thousand rows per thread the split costs more than it saves.
  constexpr int kRowsPerThread = 2048;
  const std::vector<std::pair<int, int>> blocks = EvenRanges(
      static_cast<int>(J.rows()),
      std::max(1, std::min<int>(threads, J.rows() / kRowsPerThread)));
  std::vector<Eigen::MatrixXd> parts(blocks.size());
  ParallelFor(
      static_cast<int>(blocks.size()), static_cast<int>(blocks.size()),
      [&](int b) {
        parts[b] = Eigen::MatrixXd::Zero(k, k);
        parts[b].selfadjointView<Eigen::Lower>().rankUpdate(
            J.middleRows(blocks[b].first, blocks[b].second - blocks[b].first)
                .transpose());
      });
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(k, k);
  for (const Eigen::MatrixXd& part : parts) a += part;
  return a.selfadjointView<Eigen::Lower>();
}

}  // namespace kincal
