#include "bundle/robot_record.h"

#include <Eigen/Dense>
#include <array>
#include <cmath>
#include <limits>

#include "calib/chain.h"
#include "calib/fit_record.h"
#include "data/observations.h"
#include "data/rigid3.h"

namespace kincal {
namespace {

using Block = std::array<double, 6>;
constexpr double kStep = 1e-6;  // central differences, rad | mm

// The fitted frames of bundle.h: A = rig_from_base | rig_from_flange and
// B = flange_from_tool | base_from_target, as pose blocks.
Block RigSide(const BundleResult& r) {
  return r.mount == RigMount::kFlange
             ? PoseBlockFromRigid3(
                   Rigid3FromPoseBlock(r.flange_from_rig.data()).Inverse())
             : r.rig_from_base;
}
Block ToolSide(const BundleResult& r) {
  return r.mount == RigMount::kFlange ? r.base_from_target : r.flange_from_tool;
}

// The measuring frame from the frame it follows: rig_from_base = A on a
// stand, target_from_base = B^-1 with the cameras on the flange.
Eigen::Matrix<double, 6, 1> MeasuringFrame(RigMount mount, const Block& x) {
  const Block b =
      mount == RigMount::kFlange
          ? PoseBlockFromRigid3(Rigid3FromPoseBlock(x.data()).Inverse())
          : x;
  return Eigen::Map<const Eigen::Matrix<double, 6, 1>>(b.data());
}

// Where the tool row ends in the flange frame, from the frame it follows:
// the needle tip B * tip_in_tool on a stand, the rig origin (A^-1's
// translation) on the flange.
Eigen::Vector3d ToolRowEnd(RigMount mount, const Target& target,
                           const Block& x) {
  const Rigid3 r = Rigid3FromPoseBlock(x.data());
  return mount == RigMount::kFlange ? r.Inverse().t : r * target.tip_in_tool;
}

// d f / d x for a function of one pose block (central differences).
template <int Rows, typename F>
Eigen::Matrix<double, Rows, 6> BlockDerivative(const Block& x, F f) {
  Eigen::Matrix<double, Rows, 6> d;
  for (int k = 0; k < 6; ++k) {
    Block plus = x, minus = x;
    plus[k] += kStep;
    minus[k] -= kStep;
    d.col(k) = (f(plus) - f(minus)) / (2 * kStep);
  }
  return d;
}

// D^+: the tool row's position parameters per mm of its origin (pseudo-
// inverse: a parameter that does not move the origin, DH theta with a = 0,
// gets none of the uncertainty).
Eigen::Matrix3d ToolParamsPerOrigin(const Chain& chain) {
  const ChainRow& row = chain.rows[chain.tool_row()];
  const std::vector<int> index = ToolRowPositionIndices(chain.convention);
  auto origin = [&](const RowBlock& p) {
    return RowApply<double>(chain.convention, row, p.data(), 0.0,
                            Vec3<double>::Zero());
  };
  Eigen::Matrix3d d;
  for (int c = 0; c < 3; ++c) {
    RowBlock plus = row.p, minus = row.p;
    plus[index[c]] += kStep;
    minus[index[c]] -= kStep;
    d.col(c) = (origin(plus) - origin(minus)) / (2 * kStep);
  }
  return d.completeOrthogonalDecomposition().pseudoInverse();
}

}  // namespace

std::vector<int> ToolRowPositionIndices(Convention convention) {
  // dh: theta, d, a (origin (a cos theta, a sin theta, d)); mdh: d, a,
  // alpha (origin Rx(alpha) Ry(beta) (a, 0, d)); urdf: x, y, z.
  if (convention == Convention::kMdh) return {1, 2, 3};
  return {0, 1, 2};
}

BundleRobotCovariance RobotFileCovariance(const BundleResult& result,
                                          const Target& target) {
  BundleRobotCovariance out;
  const int p = static_cast<int>(result.params.size());
  const int n_in = p + 12;
  if (result.covariance.rows() != n_in || result.covariance.cols() != n_in) {
    return out;
  }
  ModelState state;
  state.chain = result.chain;
  out.params = FrameParams();
  for (const BundleParam& bp : result.params) {
    out.params.push_back(FindParam(state, bp.name));
  }
  const std::vector<int> tool_index =
      ToolRowPositionIndices(result.chain.convention);
  for (int index : tool_index) {
    for (const ParamInfo& g : GeometryParams(result.chain)) {
      if (g.block == result.chain.tool_row() && g.index == index) {
        out.params.push_back(g);
      }
    }
  }
  const int n_out = static_cast<int>(out.params.size());
  if (n_out != 6 + p + 3) return {};

  // L: columns [params, A, B], rows [frame, params, tool row position].
  const bool flange = result.mount == RigMount::kFlange;
  const Block a = RigSide(result), b = ToolSide(result);
  Eigen::MatrixXd L = Eigen::MatrixXd::Zero(n_out, n_in);
  if (flange) {
    L.block<6, 6>(0, p + 6) = BlockDerivative<6>(
        b, [&](const Block& x) { return MeasuringFrame(result.mount, x); });
  } else {
    L.block<6, 6>(0, p).setIdentity();
  }
  L.block(6, 0, p, p).setIdentity();
  const Eigen::Matrix3d per_origin = ToolParamsPerOrigin(result.chain);
  auto tip = [&](const Block& x) {
    return ToolRowEnd(result.mount, target, x);
  };
  L.block<3, 6>(6 + p, flange ? p : p + 6) =
      per_origin * BlockDerivative<3>(flange ? a : b, tip);
  out.covariance = L * result.covariance * L.transpose();
  return out;
}

void RecordBundleFit(const Robot& nominal,
                     const std::vector<BundleFrame>& frames,
                     const std::vector<int>& fitted, const Target& target,
                     BundleResult* result) {
  result->calibrated.SetNominal(nominal);
  if (fitted.empty()) return;  // (the fit needs frames; no record without)
  Observations obs;
  obs.joint_names = nominal.JointNames();
  for (const BundleFrame& f : frames) {
    Observation o;
    o.pose = std::to_string(f.frame);
    o.q = f.q_reading;
    o.t_s = f.t_s;
    obs.rows.push_back(o);
  }
  ModelState state;
  state.chain = result->chain;
  const Eigen::Matrix<double, 6, 1> frame = MeasuringFrame(
      result->mount, result->mount == RigMount::kFlange ? ToolSide(*result)
                                                        : RigSide(*result));
  for (int k = 0; k < 6; ++k) state.meas_from_base[k] = frame[k];
  const BundleRobotCovariance cov = RobotFileCovariance(*result, target);
  FitRecordInput in;
  in.obs = &obs;
  in.rows = fitted;
  in.state = &state;
  in.params = &cov.params;
  in.covariance = &cov.covariance;
  in.heldout_rms_mm = result->heldout_tips > 0
                          ? result->heldout_tip_rms_mm
                          : std::numeric_limits<double>::quiet_NaN();
  result->calibrated = WithFitRecord(result->calibrated, nominal, in);
}

}  // namespace kincal
