#include "bundle/bundle.h"

#include <ceres/ceres.h>
#include <ceres/normal_prior.h>

#include <Eigen/Dense>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <memory>
#include <numeric>
#include <random>
#include <set>
#include <sstream>

#include "bundle/robot_record.h"
#include "calib/holdout.h"
#include "calib/identifiability.h"
#include "data/error.h"
#include "data/median.h"
#include "data/observations.h"
#include "data/rigid3.h"

namespace kincal {
namespace {

constexpr int kStride = 16;
constexpr int kMaxJoints = 16;

template <typename T>
using Mat3T = Eigen::Matrix<T, 3, 3>;

// The parameter blocks of the whole problem.
struct State {
  Chain chain;  // rows[j].p and joint_errors[j] are parameter blocks
  // rig_from_tool = rig_side * M(q) * tool_side (bundle.h): rig_from_base
  // and flange_from_tool on a stand; rig_from_flange and base_from_target
  // with the cameras on the flange (`flange`, M inverted).
  bool flange = false;
  std::array<double, 6> rig_side{};
  std::array<double, 6> tool_side{};
  std::vector<std::array<double, kNumIntrinsics>> intrinsics;
  std::vector<std::array<double, 6>> cam_from_rig;
};

// All corners of one frame f (every camera c), 2 residuals per corner i:
//   e_i = w_i (ProjectPoint(intrinsics_c, cam_from_rig_c * A * M(q_f) * B
//         * X_i) - u_i)
// with A, M, B as in bundle.h: on a stand A = rig_from_base, M =
// base_from_flange, B = flange_from_tool; on the flange A = rig_from_flange,
// M = flange_from_base = base_from_flange^-1, B = base_from_target; w_i the
// corner's weight (BundleCorner::weight);
//   r_i = e_i                                 if |e_i| <= h
//   r_i = e_i * sqrt(2 h |e_i| - h^2) / |e_i|  otherwise (h = huber_px),
// so |r_i|^2 = rho(|e_i|^2), Huber's loss per corner, and the frame's cost
// is sum_i rho(|e_i|^2) / 2. The loss is applied inside the functor, not as
// a ceres::LossFunction: one residual block holds a whole frame, and a
// LossFunction would apply one rho to the frame's summed squared norm.
class FrameCost {
 public:
  FrameCost(const Chain* chain, const PoseInput* input, bool with_errors,
            bool flange, int num_cameras,
            std::vector<Eigen::Vector3d> points_in_tool,
            std::vector<int> cameras, std::vector<Eigen::Vector2d> pixels,
            std::vector<double> weights, double huber_px)
      : chain_(chain),
        input_(input),
        with_errors_(with_errors),
        flange_(flange),
        num_cameras_(num_cameras),
        points_(std::move(points_in_tool)),
        cameras_(std::move(cameras)),
        pixels_(std::move(pixels)),
        weights_(std::move(weights)),
        huber_(huber_px) {}

  // The cost function over `block_sizes` (the layout below), 2 residuals per
  // corner.
  static ceres::CostFunction* Create(
      const Chain* chain, const PoseInput* input, bool with_errors, bool flange,
      int num_cameras, const std::vector<int>& block_sizes,
      std::vector<Eigen::Vector3d> points_in_tool, std::vector<int> cameras,
      std::vector<Eigen::Vector2d> pixels, std::vector<double> weights,
      double huber_px) {
    const int num_residuals = 2 * static_cast<int>(points_in_tool.size());
    auto* cost = new ceres::DynamicAutoDiffCostFunction<FrameCost, kStride>(
        new FrameCost(chain, input, with_errors, flange, num_cameras,
                      std::move(points_in_tool), std::move(cameras),
                      std::move(pixels), std::move(weights), huber_px));
    for (int size : block_sizes) cost->AddParameterBlock(size);
    cost->SetNumResiduals(num_residuals);
    return cost;
  }

  // Blocks: rows[0..J-1] (6), A (6), B (6),
  // [joint errors 0..J-1 (9)], per camera: intrinsics (12), cam_from_rig (6).
  template <typename T>
  bool operator()(T const* const* p, T* residuals) const {
    const int nj = chain_->num_joints();
    T q[kMaxJoints];
    for (int j = 0; j < nj; ++j) {
      q[j] = ModelJointValue<T>(chain_->rows[j], input_->q[j], input_->s[j],
                                input_->tau[j],
                                with_errors_ ? p[nj + 2 + j] : nullptr);
    }
    Mat4<T> m = Mat4<T>::Identity();
    for (int j = 0; j < nj; ++j) {
      m = m * RowTransform(chain_->convention, chain_->rows[j], p[j], q[j]);
    }
    // rig_from_tool = A * M * B, M = base_from_flange or its inverse.
    const Mat3T<T> r_rb = RotationMatrixFromVectorT(p[nj]);
    const Mat3T<T> r_ft = RotationMatrixFromVectorT(p[nj + 1]);
    const Vec3<T> t_rb(p[nj][3], p[nj][4], p[nj][5]);
    const Vec3<T> t_ft(p[nj + 1][3], p[nj + 1][4], p[nj + 1][5]);
    Mat3T<T> r_bf = m.template block<3, 3>(0, 0);
    Vec3<T> t_bf = m.template block<3, 1>(0, 3);
    if (flange_) {
      r_bf.transposeInPlace();
      t_bf = -(r_bf * t_bf);
    }
    const Mat3T<T> r_rf = r_rb * r_bf;
    const Vec3<T> t_rf = r_rb * t_bf + t_rb;
    const Mat3T<T> r_rt = r_rf * r_ft;
    const Vec3<T> t_rt = r_rf * t_ft + t_rf;
    const int cam0 = nj + 2 + (with_errors_ ? nj : 0);
    Mat3T<T> r_cr[4];
    Vec3<T> t_cr[4];
    for (int c = 0; c < num_cameras_ && c < 4; ++c) {
      const T* e = p[cam0 + 2 * c + 1];
      const Mat3T<T> r = RotationMatrixFromVectorT(e);
      r_cr[c] = r * r_rt;
      t_cr[c] = r * t_rt + Vec3<T>(e[3], e[4], e[5]);
    }
    const T c2(huber_ * huber_);
    for (size_t i = 0; i < points_.size(); ++i) {
      const int c = cameras_[i];
      const Vec3<T> pc = r_cr[c] * points_[i].cast<T>() + t_cr[c];
      T px[2];
      if (!ProjectPoint(p[cam0 + 2 * c], pc.data(), px)) return false;
      T rx = T(weights_[i]) * (px[0] - T(pixels_[i].x()));
      T ry = T(weights_[i]) * (px[1] - T(pixels_[i].y()));
      const T s = rx * rx + ry * ry;
      if (s > c2) {
        using std::sqrt;
        const T r = sqrt(s);
        const T f = sqrt(T(2) * T(huber_) * r - c2) / r;
        rx *= f;
        ry *= f;
      }
      residuals[2 * i] = rx;
      residuals[2 * i + 1] = ry;
    }
    return true;
  }

 private:
  const Chain* const chain_;
  const PoseInput* const input_;
  const bool with_errors_;
  const bool flange_;
  const int num_cameras_;
  const std::vector<Eigen::Vector3d> points_;
  const std::vector<int> cameras_;
  const std::vector<Eigen::Vector2d> pixels_;
  const std::vector<double> weights_;
  const double huber_;
};

// What is variable in one build of the problem.
struct Freedom {
  // Per joint row: indices that are free (empty = row constant).
  std::vector<std::vector<int>> row_free;
  // Per joint: error-model indices that are free.
  std::vector<std::vector<int>> error_free;
  bool frames = true;  // the two frames A and B
  bool cameras = false;
  bool with_errors = false;  // error blocks present in the residuals
};

struct Built {
  std::unique_ptr<ceres::Problem> problem;
  std::vector<ceres::ResidualBlockId> blocks;  // per training frame
  int residuals = 0;
};

void SetFree(ceres::Problem* problem, double* block, int size,
             const std::vector<int>& free) {
  if (free.empty()) {
    problem->SetParameterBlockConstant(block);
    return;
  }
  if (static_cast<int>(free.size()) == size) return;
  std::vector<int> fixed;
  for (int k = 0; k < size; ++k) {
    if (std::find(free.begin(), free.end(), k) == free.end())
      fixed.push_back(k);
  }
  problem->SetManifold(block, new ceres::SubsetManifold(size, fixed));
}

struct Obs {      // the fit's view of one frame
  int index = 0;  // into frames
  std::vector<Eigen::Vector3d> points;
  std::vector<int> cameras;
  std::vector<Eigen::Vector2d> pixels;
  std::vector<double> weights;
  std::vector<int> tag_of;     // per corner: key camera * 1000 + tag index
  std::vector<int> corner_of;  // per corner: its index in the tag (0..3)
};

// A single corner's key: its tag observation's key (Obs::tag_of) and corner.
int CornerKey(int tag_key, int corner) { return tag_key * 4 + corner; }

// Tag observations and single corners the fit leaves out.
struct Dropped {
  std::set<int> tags;     // Obs::tag_of keys
  std::set<int> corners;  // CornerKey keys
};

Built Build(State* st, const std::vector<Obs>& obs,
            const std::vector<PoseInput>& inputs, const Freedom& fr,
            const BundleOptions& opt, const Rig& rig0) {
  Built b;
  ceres::Problem::Options po;
  po.manifold_ownership = ceres::TAKE_OWNERSHIP;
  b.problem = std::make_unique<ceres::Problem>(po);
  ceres::Problem* problem = b.problem.get();
  const int nj = st->chain.num_joints();
  const int ncam = static_cast<int>(st->intrinsics.size());
  std::vector<double*> params;
  std::vector<int> sizes;
  for (int j = 0; j < nj; ++j) {
    params.push_back(st->chain.rows[j].p.data());
    sizes.push_back(kRowBlockSize);
  }
  params.push_back(st->rig_side.data());
  sizes.push_back(6);
  params.push_back(st->tool_side.data());
  sizes.push_back(6);
  if (fr.with_errors) {
    for (int j = 0; j < nj; ++j) {
      params.push_back(st->chain.joint_errors[j].data());
      sizes.push_back(kJointErrorBlockSize);
    }
  }
  for (int c = 0; c < ncam; ++c) {
    params.push_back(st->intrinsics[c].data());
    sizes.push_back(kNumIntrinsics);
    params.push_back(st->cam_from_rig[c].data());
    sizes.push_back(6);
  }
  for (const Obs& o : obs) {
    ceres::CostFunction* cost = FrameCost::Create(
        &st->chain, &inputs[o.index], fr.with_errors, st->flange, ncam, sizes,
        o.points, o.cameras, o.pixels, o.weights, opt.huber_px);
    b.blocks.push_back(problem->AddResidualBlock(cost, nullptr, params));
    b.residuals += 2 * static_cast<int>(o.points.size());
  }
  if (obs.empty()) return b;
  for (int j = 0; j < nj; ++j) {
    SetFree(problem, st->chain.rows[j].p.data(), kRowBlockSize, fr.row_free[j]);
    if (fr.with_errors) {
      SetFree(problem, st->chain.joint_errors[j].data(), kJointErrorBlockSize,
              fr.error_free[j]);
    }
  }
  if (!fr.frames) {
    problem->SetParameterBlockConstant(st->rig_side.data());
    problem->SetParameterBlockConstant(st->tool_side.data());
  }
  for (int c = 0; c < ncam; ++c) {
    double* intr = st->intrinsics[c].data();
    double* ext = st->cam_from_rig[c].data();
    if (!fr.cameras) {
      problem->SetParameterBlockConstant(intr);
      problem->SetParameterBlockConstant(ext);
      continue;
    }
    const CameraIntrinsics& k0 = rig0.cameras[c].intrinsics;
    const int nd = static_cast<int>(k0.distortion.size());
    std::vector<int> free = {kFx, kFy, kCx, kCy};
    for (int i = 0; i < nd && i < 8; ++i) free.push_back(kK1 + i);
    SetFree(problem, intr, kNumIntrinsics, free);
    const std::array<double, kNumIntrinsics> a0 = k0.ToArray();
    Eigen::MatrixXd A = Eigen::MatrixXd::Zero(kNumIntrinsics, kNumIntrinsics);
    Eigen::VectorXd b0(kNumIntrinsics);
    for (int i = 0; i < kNumIntrinsics; ++i) {
      b0[i] = a0[i];
      const double sigma = i < kCx   ? opt.prior_focal_px
                           : i < kK1 ? opt.prior_principal_px
                                     : opt.prior_distortion;
      A(i, i) = 1.0 / sigma;
    }
    problem->AddResidualBlock(new ceres::NormalPrior(A, b0), nullptr, intr);
    if (c == 0) {  // the rig frame is the first camera's frame
      problem->SetParameterBlockConstant(ext);
    } else {
      const std::array<double, 6> e0 =
          PoseBlockFromRigid3(rig0.cameras[c].cam_from_rig);
      Eigen::MatrixXd E = Eigen::MatrixXd::Zero(6, 6);
      Eigen::VectorXd e(6);
      for (int i = 0; i < 6; ++i) {
        e[i] = e0[i];
        E(i, i) = i < 3 ? 1.0 / (opt.prior_rotation_deg * M_PI / 180.0)
                        : 1.0 / opt.prior_translation_mm;
      }
      problem->AddResidualBlock(new ceres::NormalPrior(E, e), nullptr, ext);
    }
  }
  return b;
}

ceres::Solver::Summary Solve(ceres::Problem* problem, const BundleOptions& o) {
  ceres::Solver::Options so;
  so.linear_solver_type = ceres::DENSE_NORMAL_CHOLESKY;
  so.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
  so.max_num_iterations = o.max_iterations;
  so.function_tolerance = 1e-10;
  so.parameter_tolerance = 1e-10;
  so.gradient_tolerance = 1e-12;
  so.num_threads = o.num_threads;
  so.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(so, problem, &summary);
  return summary;
}

// Per-corner residuals (without the Huber scaling) of frames `obs`:
// weighted by BundleCorner::weight (what the Huber scale and the outlier
// rules judge) or, with `in_pixels`, in pixels (what the RMS report).
std::vector<double> CornerErrors(State* st, const std::vector<Obs>& obs,
                                 const std::vector<PoseInput>& inputs,
                                 bool with_errors, const Rig& rig0,
                                 bool in_pixels = false) {
  std::vector<double> out;
  if (obs.empty()) return out;
  BundleOptions plain;
  plain.huber_px = 1e12;
  Freedom fr;
  fr.row_free.assign(st->chain.num_joints(), {});
  fr.error_free.assign(st->chain.num_joints(), {});
  fr.frames = false;
  fr.with_errors = with_errors;
  Built b = Build(st, obs, inputs, fr, plain, rig0);
  for (size_t i = 0; i < obs.size(); ++i) {
    const ceres::CostFunction* cf =
        b.problem->GetCostFunctionForResidualBlock(b.blocks[i]);
    std::vector<double*> ps;
    b.problem->GetParameterBlocksForResidualBlock(b.blocks[i], &ps);
    std::vector<double> r(cf->num_residuals());
    if (!cf->Evaluate(ps.data(), r.data(), nullptr)) {
      for (size_t k = 0; k < r.size() / 2; ++k) out.push_back(1e6);
      continue;
    }
    for (size_t k = 0; k + 1 < r.size(); k += 2) {
      const double w = in_pixels ? obs[i].weights[k / 2] : 1.0;
      out.push_back(std::hypot(r[k], r[k + 1]) / w);
    }
  }
  return out;
}

// The automatic Huber scale (BundleOptions::huber_px = 0) from the corner
// errors of a first fit.
constexpr double kAutoHuberSigmas = 3.0;
constexpr double kMinAutoHuberPx = 0.05;
double AutoHuberPx(const std::vector<double>& errors) {
  if (errors.empty()) return 1.0;
  const double sigma = UpperMedian(errors) / 1.1774;
  return std::max(kMinAutoHuberPx, kAutoHuberSigmas * sigma);
}

double Rms(const std::vector<double>& v) {
  if (v.empty()) return 0.0;
  double s = 0;
  for (double x : v) s += x * x;
  return std::sqrt(s / v.size());
}

// A candidate parameter of the scan: its column in the evaluated Jacobian.
struct Candidate {
  std::string name;
  int column = 0;
  double bound = 0;  // admissible deviation (internal units), 0 = none
  bool robot = true;
  ParamInfo info;
};

Rigid3 BaseFromFlange(const Chain& chain, const PoseInput& in,
                      bool with_errors) {
  const int nj = chain.num_joints();
  Mat4<double> m = Mat4<double>::Identity();
  for (int j = 0; j < nj; ++j) {
    const double q = ModelJointValue<double>(
        chain.rows[j], in.q[j], in.s[j], in.tau[j],
        with_errors ? chain.joint_errors[j].data() : nullptr);
    m = m * RowTransform(chain.convention, chain.rows[j],
                         chain.rows[j].p.data(), q);
  }
  Rigid3 r;
  r.R = m.block<3, 3>(0, 0);
  r.t = m.block<3, 1>(0, 3);
  return r;
}

// The tool row's origin minus a wanted tip (3 residuals).
struct ToolOrigin {
  const ChainRow* row;
  Convention conv;
  Eigen::Vector3d tip;
  template <typename T>
  bool operator()(const T* p, T* r) const {
    const Vec3<T> o = RowApply(conv, *row, p, T(0), Vec3<T>(T(0), T(0), T(0)));
    for (int k = 0; k < 3; ++k) r[k] = o[k] - T(tip[k]);
    return true;
  }
};

// Sets the tool row so that its origin is `tip_in_flange`.
void SetToolRow(const Eigen::Vector3d& tip, Chain* chain) {
  ChainRow& row = chain->rows[chain->tool_row()];
  if (chain->convention == Convention::kDh) {
    // Rz(theta) Tz(d) Tx(a) Rx(alpha) Ry(beta): origin (a cos, a sin, d).
    const double a = std::hypot(tip.x(), tip.y());
    double theta = a > 1e-9 ? std::atan2(tip.y(), tip.x()) : row.p[0];
    double sa = a;
    // Keep the sign of a (and theta near its nominal value) when possible.
    const double wrap = std::remainder(theta - row.p[0], 2 * M_PI);
    if (std::abs(wrap) > M_PI / 2 && a > 1e-9) {
      theta += M_PI;
      sa = -a;
    }
    row.p[0] = row.p[0] + std::remainder(theta - row.p[0], 2 * M_PI);
    row.p[1] = tip.z();
    row.p[2] = sa;
    return;
  }
  // Other conventions: least squares on the row's parameters from nominal.
  ceres::Problem problem;
  problem.AddResidualBlock(
      new ceres::AutoDiffCostFunction<ToolOrigin, 3, kRowBlockSize>(
          new ToolOrigin{&row, chain->convention, tip}),
      nullptr, row.p.data());
  if (chain->convention == Convention::kMdh) {
    problem.SetManifold(row.p.data(),
                        new ceres::SubsetManifold(kRowBlockSize, {0, 4, 5}));
  } else {
    problem.SetManifold(row.p.data(),
                        new ceres::SubsetManifold(kRowBlockSize, {3, 4, 5}));
  }
  ceres::Solver::Options so;
  so.logging_type = ceres::SILENT;
  ceres::Solver::Summary s;
  ceres::Solve(so, &problem, &s);
}

}  // namespace

bool SeenByTwoCameras(const BundleFrame& f) {
  for (const BundleCorner& c : f.corners) {
    if (c.camera != f.corners.front().camera) return true;
  }
  return false;
}

bool SeenByEnoughCameras(const BundleFrame& f, int num_cameras) {
  return num_cameras < 2 ? !f.corners.empty() : SeenByTwoCameras(f);
}

bool HandEyeStart(const std::vector<Rigid3>& base_from_flange,
                  const std::vector<Rigid3>& rig_from_tool, Rigid3* x,
                  Rigid3* y) {
  const int n = static_cast<int>(base_from_flange.size());
  if (n < 3 || rig_from_tool.size() != base_from_flange.size()) return false;
  // RX RF_i = RT_i RY^T: [RF_i^T (x) I, -(I (x) RT_i)] [vec RX; vec RY^T] = 0.
  Eigen::MatrixXd A(9 * n, 18);
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  for (int i = 0; i < n; ++i) {
    const Eigen::Matrix3d& rf = base_from_flange[i].R;
    const Eigen::Matrix3d& rt = rig_from_tool[i].R;
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) {
        A.block<3, 3>(9 * i + 3 * c, 3 * r) = rf(r, c) * I;  // rf^T(c, r)
        A.block<3, 3>(9 * i + 3 * c, 9 + 3 * r) = -(I(c, r) * rt);
      }
    }
  }
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(A, Eigen::ComputeFullV);
  const Eigen::VectorXd sv = svd.singularValues();
  // A unique solution leaves one (near) null direction.
  if (!(sv(16) > 1e-3 * sv(0))) return false;
  const Eigen::VectorXd v = svd.matrixV().col(17);
  Eigen::Matrix3d rx = Eigen::Map<const Eigen::Matrix3d>(v.data());
  Eigen::Matrix3d ryt = Eigen::Map<const Eigen::Matrix3d>(v.data() + 9);
  const double det = rx.determinant();
  if (std::abs(det) < 1e-12) return false;
  const double scale = std::cbrt(det);
  rx /= scale;
  ryt /= scale;
  auto project = [](const Eigen::Matrix3d& m) {
    Eigen::JacobiSVD<Eigen::Matrix3d> s(
        m, Eigen::ComputeFullU | Eigen::ComputeFullV);
    Eigen::Matrix3d d = Eigen::Matrix3d::Identity();
    d(2, 2) =
        (s.matrixU() * s.matrixV().transpose()).determinant() < 0 ? -1 : 1;
    return Eigen::Matrix3d(s.matrixU() * d * s.matrixV().transpose());
  };
  x->R = project(rx);
  y->R = project(ryt).transpose();
  // t_T = RX RF t_Y + t_X + RX t_F.
  Eigen::MatrixXd M(3 * n, 6);
  Eigen::VectorXd b(3 * n);
  for (int i = 0; i < n; ++i) {
    M.block<3, 3>(3 * i, 0) = x->R * base_from_flange[i].R;
    M.block<3, 3>(3 * i, 3) = I;
    b.segment<3>(3 * i) = rig_from_tool[i].t - x->R * base_from_flange[i].t;
  }
  const Eigen::VectorXd t = M.colPivHouseholderQr().solve(b);
  y->t = t.head<3>();
  x->t = t.tail<3>();
  return x->R.allFinite() && y->R.allFinite() && t.allFinite();
}

Rigid3 ModelRigFromTool(const BundleResult& result, int index) {
  const bool errors = result.chain.HasJointErrors();
  const Rigid3 base_from_flange =
      BaseFromFlange(result.chain, result.inputs.at(index), errors);
  if (result.mount == RigMount::kFlange) {
    return Rigid3FromPoseBlock(result.flange_from_rig.data()).Inverse() *
           base_from_flange.Inverse() *
           Rigid3FromPoseBlock(result.base_from_target.data());
  }
  return Rigid3FromPoseBlock(result.rig_from_base.data()) * base_from_flange *
         Rigid3FromPoseBlock(result.flange_from_tool.data());
}

Eigen::Vector3d MeasuredPoint(RigMount mount, const Target& target,
                              const Rigid3& rig_from_tool) {
  if (mount == RigMount::kFlange) return rig_from_tool.Inverse().t;
  return rig_from_tool * target.tip_in_tool;
}

namespace {

// Pose inputs (approach directions, torques) of every frame, in frame order.
std::vector<PoseInput> FramePoseInputs(const Robot& nominal,
                                       const Chain& nominal_chain,
                                       const std::vector<BundleFrame>& frames) {
  const int nj = nominal_chain.num_joints();
  Observations ob;
  ob.joint_names = nominal.JointNames();
  for (const BundleFrame& f : frames) {
    if (f.q_reading.size() != static_cast<size_t>(nj)) {
      throw InputError("bundle: frame " + std::to_string(f.frame) + " has " +
                       std::to_string(f.q_reading.size()) +
                       " joint readings, the robot " + std::to_string(nj));
    }
    Observation o;
    o.pose = std::to_string(f.frame);
    o.q = f.q_reading;
    o.t_s = f.t_s;
    ob.rows.push_back(o);
  }
  return MakePoseInputs(nominal_chain, ob);
}

// The parameters of --extensions: joint error parameters or a beta.
std::vector<ParamInfo> ExtensionParams(const Chain& chain,
                                       const BundleOptions& opt) {
  ModelState names_state;
  names_state.chain = chain;
  std::vector<ParamInfo> ext;
  for (const std::string& name : opt.extensions) {
    const ParamInfo p = FindParam(names_state, name);
    if (p.kind != ParamKind::kJointError &&
        !(p.kind == ParamKind::kRow && p.index == 4)) {
      throw InputError("--extensions: '" + name +
                       "' is not a joint error parameter (e.g. j3.backlash, "
                       "j2.gain, j2.compliance, j3.cyclic_cos) or a beta");
    }
    ext.push_back(p);
  }
  return ext;
}

// Frames with corners split into training and held-out frames (each in
// frame order): fold `opt.fold` of `opt.folds`, or the first
// floor(holdout_fraction * n) of a seeded shuffle.
HoldoutSplit SplitFrames(const std::vector<BundleFrame>& frames,
                         const BundleOptions& opt) {
  std::vector<int> usable;
  for (size_t i = 0; i < frames.size(); ++i) {
    if (!frames[i].corners.empty()) usable.push_back(static_cast<int>(i));
  }
  if (opt.folds >= 2) return HoldOutFold(usable, opt.folds, opt.fold, opt.seed);
  std::mt19937_64 rng(opt.seed);
  const int num_heldout = static_cast<int>(
      std::floor(opt.holdout_fraction * static_cast<double>(usable.size())));
  return HoldOutFirst(usable, num_heldout, &rng);
}

// The fit's view of frames `indices`: tool corners, cameras and pixels,
// without the tag observations and corners in `dropped` (tag key: (frame *
// 8 + camera) * 1000 + tag).
std::vector<Obs> MakeObs(const std::vector<BundleFrame>& frames,
                         const Target& target, const std::vector<int>& indices,
                         const Dropped& dropped) {
  std::vector<Obs> out;
  for (int i : indices) {
    Obs o;
    o.index = i;
    for (const BundleCorner& c : frames[i].corners) {
      const int key = (i * 8 + c.camera) * 1000 + c.tag;
      if (dropped.tags.count(key) ||
          dropped.corners.count(CornerKey(key, c.corner))) {
        continue;
      }
      o.points.push_back(target.tags.at(c.tag).CornerInTool(c.corner));
      o.cameras.push_back(c.camera);
      o.pixels.push_back(c.px);
      o.weights.push_back(c.weight);
      o.tag_of.push_back(key);
      o.corner_of.push_back(c.corner);
    }
    if (!o.points.empty()) out.push_back(std::move(o));
  }
  return out;
}

// A tracked tool pose good enough to start from or to compare tips with:
// enough tags, a small RMS, and on a rig of two or more cameras two of them
// (one camera of a stereo rig leaves the depth weak: tens of mm at 2 m; a
// one-camera rig has nothing better, SeenByEnoughCameras).
bool WellTracked(const BundleFrame& f, const BundleOptions& opt,
                 int num_cameras) {
  return !(!f.tracked || f.tracked_tags < opt.start_min_tags ||
           f.tracked_rms_px > opt.start_max_rms_px ||
           !SeenByEnoughCameras(f, num_cameras));
}

// Start values of the two frames (rig_from_base and flange_from_tool, or
// rig_from_flange and base_from_target): hand-eye from the well-tracked
// training frames with the nominal robot.
void StartFrames(const std::vector<BundleFrame>& frames,
                 const BundleResult& res, const BundleOptions& opt, State* st) {
  std::vector<Rigid3> bf, rt;
  for (int i : res.train) {
    const BundleFrame& f = frames[i];
    if (!WellTracked(f, opt, static_cast<int>(res.rig.cameras.size()))) {
      continue;
    }
    const Rigid3 m = BaseFromFlange(st->chain, res.inputs[i], false);
    bf.push_back(st->flange ? m.Inverse() : m);
    rt.push_back(f.rig_from_tool);
  }
  Rigid3 x, y;
  if (!HandEyeStart(bf, rt, &x, &y)) {
    throw InputError(
        "bundle: " + std::to_string(bf.size()) +
        " training frames with a well-tracked target (>= " +
        std::to_string(opt.start_min_tags) +
        " tags); need at least 3 with different orientations to find " +
        (st->flange ? "where the rig sits on the flange and where the target "
                      "is in the base"
                    : "where the base is in the rig and where the target "
                      "sits on the flange"));
  }
  st->rig_side = PoseBlockFromRigid3(x);
  st->tool_side = PoseBlockFromRigid3(y);
}

// The dense pixel Jacobian of the training frames with respect to the two
// frames (columns 0..11) and every row and error block (columns from
// `column_of[(0 row | 1 error, joint)]`).
Eigen::MatrixXd PixelJacobian(State* st, const std::vector<Obs>& train,
                              const std::vector<PoseInput>& inputs,
                              const Freedom& fixed_robot,
                              const BundleOptions& opt, const Rig& rig,
                              std::map<std::pair<int, int>, int>* column_of) {
  const int nj = st->chain.num_joints();
  const bool with_errors = fixed_robot.with_errors;
  // Evaluate with every candidate block fully variable, columns per block.
  Freedom eval = fixed_robot;
  for (int j = 0; j < nj; ++j) {
    eval.row_free[j] = {0, 1, 2, 3, 4, 5};
    if (with_errors) {
      eval.error_free[j].resize(kJointErrorBlockSize);
      std::iota(eval.error_free[j].begin(), eval.error_free[j].end(), 0);
    }
  }
  Built b = Build(st, train, inputs, eval, opt, rig);
  ceres::Problem::EvaluateOptions eo;
  std::vector<double*> blocks = {st->rig_side.data(), st->tool_side.data()};
  int col = 12;
  for (int j = 0; j < nj; ++j) {
    blocks.push_back(st->chain.rows[j].p.data());
    (*column_of)[{0, j}] = col;
    col += kRowBlockSize;
  }
  if (with_errors) {
    for (int j = 0; j < nj; ++j) {
      blocks.push_back(st->chain.joint_errors[j].data());
      (*column_of)[{1, j}] = col;
      col += kJointErrorBlockSize;
    }
  }
  eo.parameter_blocks = blocks;
  eo.residual_blocks = b.blocks;
  eo.num_threads = opt.num_threads;
  double cost = 0;
  std::vector<double> residuals;
  ceres::CRSMatrix crs;
  b.problem->Evaluate(eo, &cost, &residuals, nullptr, &crs);
  Eigen::MatrixXd J = Eigen::MatrixXd::Zero(crs.num_rows, crs.num_cols);
  for (int r = 0; r < crs.num_rows; ++r) {
    for (int k = crs.rows[r]; k < crs.rows[r + 1]; ++k) {
      J(r, crs.cols[k]) = crs.values[k];
    }
  }
  return J;
}

// Pixel noise for the statistical criterion: the median tracked RMS of the
// training frames (the per-frame tool pose fits, 6 parameters per frame,
// see detection noise, not model error); at least 0.02 px, 0.1 px without
// tracked frames.
double TrackedPixelNoise(const std::vector<BundleFrame>& frames,
                         const std::vector<int>& train) {
  std::vector<double> tracked_rms;
  for (int i : train) {
    if (frames[i].tracked) tracked_rms.push_back(frames[i].tracked_rms_px);
  }
  if (tracked_rms.empty()) return 0.1;
  return std::max(0.02, UpperMedian(std::move(tracked_rms)));
}

struct IdentifiabilityScan {
  std::vector<std::string> accepted;        // in priority order
  std::vector<std::string> unidentifiable;  // held at nominal
  Freedom fit;                              // the accepted ones free
};

// calib's identifiability scan (calib/identifiability.h) on the pixel
// Jacobian in priority order: the two frames' 12 pose columns, then
// `candidates`. A candidate is accepted when the part of its column outside
// the span of those before it is larger than the tolerance (sine of the
// angle) and, for a row parameter, its conditional sigma
// sigma_px / (|column| sine) is below max_sigma_fraction of its bound.
IdentifiabilityScan ScanIdentifiability(
    const Eigen::MatrixXd& J,
    const std::map<std::pair<int, int>, int>& column_of,
    const std::vector<ParamInfo>& candidates, const Chain& chain,
    double sigma_px, const Freedom& fixed_robot, const BundleOptions& opt) {
  constexpr int kPoseColumns = 12;  // the two frames A and B
  std::vector<ParamInfo> ordered;
  Eigen::MatrixXd columns(J.rows(), kPoseColumns + candidates.size());
  for (int c = 0; c < kPoseColumns; ++c) {
    ordered.push_back(
        {"pose." + std::to_string(c), ParamKind::kFrame, 0, c, false});
    columns.col(c) = J.col(c);
  }
  for (const ParamInfo& p : candidates) {
    columns.col(ordered.size()) = J.col(
        column_of.at({p.kind == ParamKind::kRow ? 0 : 1, p.block}) + p.index);
    ordered.push_back(p);
  }
  IdentifiabilityOptions options;
  options.tolerance = opt.identifiability_tolerance;
  options.noise_sigma_mm = sigma_px;  // the residuals' unit: pixels
  options.max_sigma_fraction = opt.max_sigma_fraction;
  const Identifiability id =
      AnalyzeJacobianColumns(columns, ordered, chain, options);

  IdentifiabilityScan scan;
  scan.fit = fixed_robot;
  for (const ParamInfo& p : id.identifiable) {
    if (p.kind == ParamKind::kFrame) continue;
    scan.accepted.push_back(p.name);
    if (p.kind == ParamKind::kRow)
      scan.fit.row_free[p.block].push_back(p.index);
    if (p.kind == ParamKind::kJointError) {
      scan.fit.error_free[p.block].push_back(p.index);
    }
  }
  for (const ParamInfo& p : id.unidentifiable) {
    if (p.kind != ParamKind::kFrame) scan.unidentifiable.push_back(p.name);
  }
  return scan;
}

// Tag observations of the training frames whose RMS exceeds
// max(outlier_px, outlier_ratio * median tag RMS), added to `*dropped`.
void DropOutlierTags(State* st, const std::vector<Obs>& train,
                     const std::vector<PoseInput>& inputs, bool with_errors,
                     const BundleOptions& opt, const Rig& rig,
                     std::set<int>* dropped) {
  const std::vector<double> e =
      CornerErrors(st, train, inputs, with_errors, rig);
  std::map<int, std::pair<double, int>> per_tag;
  size_t k = 0;
  for (const Obs& o : train) {
    for (size_t i = 0; i < o.points.size(); ++i, ++k) {
      per_tag[o.tag_of[i]].first += e[k] * e[k];
      per_tag[o.tag_of[i]].second += 1;
    }
  }
  std::vector<double> rms;
  for (auto& [key, v] : per_tag) rms.push_back(std::sqrt(v.first / v.second));
  const double limit =
      std::max(opt.outlier_px, opt.outlier_ratio * UpperMedian(rms));
  size_t t = 0;
  for (auto& [key, v] : per_tag) {
    if (rms[t++] > limit) dropped->insert(key);
  }
}

// Corners of the kept tags whose error exceeds max(outlier_sigmas * sigma,
// kMinOutlierCornerPx), sigma = median corner error / 1.1774 (the median of
// a 2-D Gaussian error's norm), added to `*dropped`.
constexpr double kMinOutlierCornerPx = 0.2;
void DropOutlierCorners(State* st, const std::vector<Obs>& train,
                        const std::vector<PoseInput>& inputs, bool with_errors,
                        const BundleOptions& opt, const Rig& rig,
                        std::set<int>* dropped) {
  if (!(opt.outlier_sigmas > 0)) return;
  const std::vector<double> e =
      CornerErrors(st, train, inputs, with_errors, rig);
  if (e.empty()) return;
  const double limit = std::max(opt.outlier_sigmas * UpperMedian(e) / 1.1774,
                                kMinOutlierCornerPx);
  size_t k = 0;
  for (const Obs& o : train) {
    for (size_t i = 0; i < o.points.size(); ++i, ++k) {
      if (e[k] > limit) dropped->insert(CornerKey(o.tag_of[i], o.corner_of[i]));
    }
  }
}

// One coordinate of a parameter block (the covariance's rows).
struct Coordinate {
  const double* block = nullptr;
  int size = 0;   // the block's size
  int index = 0;  // inside the block
};

// The covariance among `coords` (unscaled): Ceres' covariance (dense SVD,
// pseudo-inverse) of their blocks, every pair once. False when Ceres cannot
// compute it.
bool CoordinateCovariance(ceres::Problem* problem,
                          const std::vector<Coordinate>& coords,
                          int num_threads, Eigen::MatrixXd* out) {
  std::vector<Coordinate> blocks;  // distinct blocks, first-seen order
  std::vector<int> block_of;
  for (const Coordinate& c : coords) {
    size_t k = 0;
    while (k < blocks.size() && blocks[k].block != c.block) ++k;
    if (k == blocks.size()) blocks.push_back(c);
    block_of.push_back(static_cast<int>(k));
  }
  std::vector<std::pair<const double*, const double*>> pairs;
  for (size_t i = 0; i < blocks.size(); ++i) {
    for (size_t j = i; j < blocks.size(); ++j) {
      pairs.push_back({blocks[i].block, blocks[j].block});
    }
  }
  ceres::Covariance::Options co;
  co.algorithm_type = ceres::DENSE_SVD;
  co.null_space_rank = -1;
  co.num_threads = num_threads;
  ceres::Covariance cov(co);
  if (pairs.empty() || !cov.Compute(pairs, problem)) return false;
  // Block pair (i <= j), row-major size_i x size_j.
  std::map<std::pair<int, int>, std::vector<double>> pair_cov;
  for (size_t i = 0; i < blocks.size(); ++i) {
    for (size_t j = i; j < blocks.size(); ++j) {
      std::vector<double>& c =
          pair_cov[{static_cast<int>(i), static_cast<int>(j)}];
      c.resize(blocks[i].size * blocks[j].size);
      if (!cov.GetCovarianceBlock(blocks[i].block, blocks[j].block, c.data())) {
        return false;
      }
    }
  }
  const int n = static_cast<int>(coords.size());
  out->resize(n, n);
  for (int a = 0; a < n; ++a) {
    for (int b = 0; b < n; ++b) {
      const int i = block_of[a], j = block_of[b];
      (*out)(a, b) =
          i <= j ? pair_cov[{i, j}]
                           [coords[a].index * blocks[j].size + coords[b].index]
                 : pair_cov[{j, i}]
                           [coords[b].index * blocks[i].size + coords[a].index];
    }
  }
  return out->allFinite();
}

// sigma0 (px) of the final fit, each accepted parameter's value and sigma
// (interface units; NaN where the covariance is not available) and their
// covariance with the two frames (BundleResult::covariance): the covariance
// of the free blocks scaled by sigma0^2.
void EstimateCovariance(State* st, const std::vector<Obs>& train,
                        const std::vector<PoseInput>& inputs,
                        const Freedom& fit, const BundleOptions& opt,
                        const Rig& rig,
                        const std::vector<ParamInfo>& candidates,
                        const std::vector<std::string>& accepted,
                        BundleResult* res) {
  Built b = Build(st, train, inputs, fit, opt, rig);
  int nfree = 12;
  for (const auto& r : fit.row_free) nfree += static_cast<int>(r.size());
  for (const auto& r : fit.error_free) nfree += static_cast<int>(r.size());
  double cost = 0;
  b.problem->Evaluate(ceres::Problem::EvaluateOptions(), &cost, nullptr,
                      nullptr, nullptr);
  res->sigma0_px = std::sqrt(2 * cost / std::max(1, b.residuals - nfree));
  // The accepted parameters in candidate order, then the frames A and B.
  std::vector<ParamInfo> params;
  std::vector<Coordinate> coords;
  for (const ParamInfo& p : candidates) {
    if (std::find(accepted.begin(), accepted.end(), p.name) == accepted.end()) {
      continue;
    }
    params.push_back(p);
    coords.push_back(p.kind == ParamKind::kRow
                         ? Coordinate{st->chain.rows[p.block].p.data(),
                                      kRowBlockSize, p.index}
                         : Coordinate{st->chain.joint_errors[p.block].data(),
                                      kJointErrorBlockSize, p.index});
  }
  for (int k = 0; k < 6; ++k) coords.push_back({st->rig_side.data(), 6, k});
  for (int k = 0; k < 6; ++k) coords.push_back({st->tool_side.data(), 6, k});
  Eigen::MatrixXd cov;
  const bool have_cov =
      !params.empty() &&
      CoordinateCovariance(b.problem.get(), coords, opt.num_threads, &cov);
  if (have_cov) res->covariance = cov * (res->sigma0_px * res->sigma0_px);
  ModelState ms;
  ms.chain = st->chain;
  for (size_t k = 0; k < params.size(); ++k) {
    const ParamInfo& p = params[k];
    BundleParam bp;
    bp.name = p.name;
    bp.value = p.ToInterface(ParamValue(ms, p));
    bp.sigma = std::numeric_limits<double>::quiet_NaN();
    if (have_cov) {
      const double var = std::max(0.0, res->covariance(k, k));
      bp.sigma = std::abs(p.ToInterface(std::sqrt(var)));
    }
    res->params.push_back(bp);
  }
}

// The solved state into the result: the tool row (to the tip, or to the rig
// origin with the cameras on the flange), the robot, both frames and the
// refined rig.
void WriteSolution(const Robot& nominal, const Rig& rig, const Target& target,
                   bool with_errors, State* st, BundleResult* res) {
  const Rigid3 a = Rigid3FromPoseBlock(st->rig_side.data());
  const Rigid3 b = Rigid3FromPoseBlock(st->tool_side.data());
  if (st->flange) {
    res->flange_from_rig = PoseBlockFromRigid3(a.Inverse());
    res->base_from_target = st->tool_side;
    SetToolRow(a.Inverse().t, &st->chain);
  } else {
    res->rig_from_base = st->rig_side;
    res->flange_from_tool = st->tool_side;
    SetToolRow(b * target.tip_in_tool, &st->chain);
  }
  if (!with_errors) {
    for (auto& e : st->chain.joint_errors) e.fill(0.0);
  }
  res->chain = st->chain;
  res->calibrated = st->chain.ToRobot(nominal);
  for (size_t c = 0; c < rig.cameras.size(); ++c) {
    const int nd =
        static_cast<int>(rig.cameras[c].intrinsics.distortion.size());
    CameraIntrinsics k =
        CameraIntrinsics::FromArray(st->intrinsics[c].data(), nd);
    k.name = rig.cameras[c].intrinsics.name;
    k.width = rig.cameras[c].intrinsics.width;
    k.height = rig.cameras[c].intrinsics.height;
    res->rig.cameras[c].intrinsics = k;
    res->rig.cameras[c].cam_from_rig =
        c == 0 ? rig.cameras[0].cam_from_rig
               : Rigid3FromPoseBlock(st->cam_from_rig[c].data());
  }
}

// Held-out tips: the model's tip against the tracked tip of every
// well-tracked held-out frame (mm); with the cameras on the flange, the rig
// origin in the target frame (MeasuredPoint).
void HeldOutTips(const std::vector<BundleFrame>& frames, const Target& target,
                 const BundleOptions& opt, BundleResult* res) {
  std::vector<double> tip_err;
  for (int i : res->heldout) {
    const BundleFrame& f = frames[i];
    if (!WellTracked(f, opt, static_cast<int>(res->rig.cameras.size()))) {
      continue;
    }
    const Eigen::Vector3d model =
        MeasuredPoint(res->mount, target, ModelRigFromTool(*res, i));
    const Eigen::Vector3d seen =
        MeasuredPoint(res->mount, target, f.rig_from_tool);
    tip_err.push_back((model - seen).norm());
  }
  res->heldout_tips = static_cast<int>(tip_err.size());
  res->heldout_tip_mm = tip_err;
  res->heldout_tip_rms_mm = Rms(tip_err);
}

// Each fitted extension's effect_mm: the RMS over the used frames of the
// distance the tool row's end moves when the parameter is set to zero (what
// a finding changes in the robot's predictions).
void ExtensionEffects(const std::vector<ParamInfo>& ext, BundleResult* res) {
  std::vector<int> used = res->train;
  used.insert(used.end(), res->heldout.begin(), res->heldout.end());
  for (const ParamInfo& p : ext) {
    for (BundleParam& bp : res->params) {
      if (bp.name != p.name || used.empty()) continue;
      ModelState without;
      without.chain = res->chain;
      *ParamAddress(&without, p) = 0.0;
      double sum = 0.0;
      for (int i : used) {
        sum += (TipInBase(res->chain, res->inputs[i]) -
                TipInBase(without.chain, res->inputs[i]))
                   .squaredNorm();
      }
      bp.effect_mm = std::sqrt(sum / static_cast<double>(used.size()));
    }
  }
}

// Names: the two frames and the tool row's position are determined by
// construction, its orientation is not; then the accepted candidates.
void NameIdentifiable(const Chain& chain,
                      const std::vector<std::string>& accepted,
                      BundleResult* res) {
  const char* fn[6] = {"rx", "ry", "rz", "tx", "ty", "tz"};
  const bool flange = res->mount == RigMount::kFlange;
  for (int k = 0; k < 6; ++k) {
    res->identifiable.push_back(
        std::string(flange ? "base_from_target." : "frame.") + fn[k]);
  }
  for (int k = 0; k < 6; ++k) {
    res->identifiable.push_back(
        std::string(flange ? "flange_from_rig." : "flange_from_target.") +
        fn[k]);
  }
  for (const std::string& a : accepted) res->identifiable.push_back(a);
  const std::vector<int> position_index =
      ToolRowPositionIndices(chain.convention);
  for (const ParamInfo& p : GeometryParams(chain)) {
    if (p.block != chain.tool_row()) continue;
    const bool position =
        std::find(position_index.begin(), position_index.end(), p.index) !=
        position_index.end();
    (position ? res->identifiable : res->unidentifiable).push_back(p.name);
  }
}

}  // namespace

BundleResult RunBundle(const Robot& nominal, const Rig& rig,
                       const Target& target,
                       const std::vector<BundleFrame>& frames,
                       const BundleOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  BundleOptions opt = options;  // the automatic Huber scale is set below
  const bool auto_huber = !(opt.huber_px > 0);
  if (auto_huber) opt.huber_px = 1.0;  // for the fits before the first estimate
  BundleResult res;
  res.frames = static_cast<int>(frames.size());
  res.rig = rig;
  res.mount = rig.mount;
  State st;
  st.flange = rig.mount == RigMount::kFlange;
  st.chain = Chain::FromRobot(nominal);
  const int nj = st.chain.num_joints();
  if (nj > kMaxJoints) throw InputError("bundle: more than 16 joints");
  if (rig.cameras.size() > 4) throw InputError("bundle: more than 4 cameras");
  for (const BundleFrame& f : frames) {
    for (const BundleCorner& c : f.corners) {
      if (!(c.weight > 0 && std::isfinite(c.weight))) {
        throw InputError("bundle: frame " + std::to_string(f.frame) +
                         " has a corner of weight " + std::to_string(c.weight) +
                         " (expected > 0)");
      }
    }
  }
  for (const Camera& c : rig.cameras) {
    st.intrinsics.push_back(c.intrinsics.ToArray());
    st.cam_from_rig.push_back(PoseBlockFromRigid3(c.cam_from_rig));
  }
  res.inputs = FramePoseInputs(nominal, st.chain, frames);
  const std::vector<ParamInfo> ext = ExtensionParams(st.chain, opt);
  bool with_errors = st.chain.HasJointErrors();
  for (const ParamInfo& p : ext) {
    with_errors |= p.kind == ParamKind::kJointError;
  }

  // Hold-out, start values, the two frames with the nominal robot.
  HoldoutSplit split = SplitFrames(frames, opt);
  res.train = std::move(split.train);
  res.heldout = std::move(split.heldout);
  res.used_frames = static_cast<int>(res.train.size() + res.heldout.size());
  res.train_frames = static_cast<int>(res.train.size());
  res.heldout_frames = static_cast<int>(res.heldout.size());
  Dropped dropped;
  std::vector<Obs> train = MakeObs(frames, target, res.train, dropped);
  StartFrames(frames, res, opt, &st);
  Freedom fixed_robot;
  fixed_robot.row_free.assign(nj, {});
  fixed_robot.error_free.assign(nj, {});
  fixed_robot.with_errors = with_errors;
  res.start_reproj_rms_px =
      Rms(CornerErrors(&st, train, res.inputs, with_errors, rig, true));
  {
    Built b = Build(&st, train, res.inputs, fixed_robot, opt, rig);
    Solve(b.problem.get(), opt);
  }

  // Identifiability on the pixel Jacobian, all candidates free.
  std::vector<ParamInfo> candidates;
  for (const ParamInfo& p : GeometryParams(st.chain)) {
    if (p.block < st.chain.tool_row()) candidates.push_back(p);
  }
  for (const ParamInfo& p : ext) candidates.push_back(p);
  std::map<std::pair<int, int>, int> column_of;
  const Eigen::MatrixXd J =
      PixelJacobian(&st, train, res.inputs, fixed_robot, opt, rig, &column_of);
  IdentifiabilityScan scan = ScanIdentifiability(
      J, column_of, candidates, st.chain, TrackedPixelNoise(frames, res.train),
      fixed_robot, opt);
  res.unidentifiable = scan.unidentifiable;
  Freedom& fit = scan.fit;
  fit.cameras = opt.refine_cameras;

  // The joint fit; then drop outlier tags, set the automatic Huber scale
  // from the remaining corners, and refit.
  ceres::Solver::Summary summary;
  for (int round = 0; round < 2; ++round) {
    Built b = Build(&st, train, res.inputs, fit, opt, rig);
    summary = Solve(b.problem.get(), opt);
    if (round == 1) break;
    DropOutlierTags(&st, train, res.inputs, with_errors, opt, rig,
                    &dropped.tags);
    DropOutlierCorners(&st, MakeObs(frames, target, res.train, dropped),
                       res.inputs, with_errors, opt, rig, &dropped.corners);
    if (dropped.tags.empty() && dropped.corners.empty() && !auto_huber) break;
    res.dropped_tags = static_cast<int>(dropped.tags.size());
    res.dropped_corners = static_cast<int>(dropped.corners.size());
    train = MakeObs(frames, target, res.train, dropped);
    if (auto_huber) {
      opt.huber_px =
          AutoHuberPx(CornerErrors(&st, train, res.inputs, with_errors, rig));
    }
  }
  res.huber_px = opt.huber_px;
  res.termination = summary.message;
  res.iterations = static_cast<int>(summary.iterations.size());
  EstimateCovariance(&st, train, res.inputs, fit, opt, rig, candidates,
                     scan.accepted, &res);

  // Training and held-out statistics, then the solution.
  res.reproj_rms_px =
      Rms(CornerErrors(&st, train, res.inputs, with_errors, rig, true));
  res.corners = 0;
  for (const Obs& o : train) res.corners += static_cast<int>(o.points.size());
  const std::vector<Obs> heldout = MakeObs(frames, target, res.heldout, {});
  res.heldout_corner_px =
      CornerErrors(&st, heldout, res.inputs, with_errors, rig, true);
  res.heldout_reproj_rms_px = Rms(res.heldout_corner_px);
  WriteSolution(nominal, rig, target, with_errors, &st, &res);
  HeldOutTips(frames, target, opt, &res);
  ExtensionEffects(ext, &res);
  NameIdentifiable(st.chain, scan.accepted, &res);
  std::vector<int> fitted;  // training frames with corners in the fit
  for (const Obs& o : train) fitted.push_back(o.index);
  RecordBundleFit(nominal, frames, fitted, target, &res);
  res.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
          .count();
  return res;
}

}  // namespace kincal
