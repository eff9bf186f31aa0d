#include "vision/target_layout.h"

#include <ceres/ceres.h>

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <memory>
#include <set>
#include <sstream>

#include "camcal/cost_functions.h"
#include "data/error.h"
#include "data/median.h"
#include "data/rigid3.h"
#include "vision/stereo_images.h"

namespace kincal {

void TargetLayoutOptions::Check() const {
  if (!IsKnownTagFamily(family)) {
    throw InputError("--family: unknown tag family '" + family +
                     "' (expected tag36h11, tag25h9 or tag16h5)");
  }
  if (!(tag_size_mm >= 0.5 && tag_size_mm <= 5000)) {
    throw InputError(
        "--size: expected the edge of the tags' black square "
        "in mm (0.5 to 5000), got " +
        std::to_string(tag_size_mm));
  }
  if (min_views < 2) throw InputError("min_views: expected at least 2");
  if (!(huber_px > 0) || !(outlier_px > 0) || !(outlier_ratio > 1) ||
      !(max_rms_px > 0)) {
    throw InputError(
        "huber_px, outlier_px and max_rms_px must be > 0 and outlier_ratio "
        "> 1");
  }
  if (max_iterations < 1) throw InputError("max_iterations: expected >= 1");
  pose.Check();
}

void PivotTipOptions::Check() const {
  if (min_views < 3) throw InputError("pivot min_views: expected at least 3");
  if (!(min_tilt_deg >= 0) || !(min_conditioning > 0)) {
    throw InputError(
        "pivot min_tilt_deg must be >= 0 and min_conditioning > 0");
  }
  if (!(outlier_mm > 0) || !(outlier_ratio > 1)) {
    throw InputError(
        "pivot outlier_mm must be > 0 and outlier_ratio > 1 (a pose is left "
        "out beyond max(outlier_mm, outlier_ratio * median residual))");
  }
  pose.Check();
}

namespace {

// Reprojection of one tag corner through the layout:
//   r = pi(K, cam_from_rig * rig_from_tool * tool_from_tag * c_in_tag) - px
// with rig_from_tool = (exp([a]x) R_tool0, t) and tool_from_tag =
// (exp([b]x) R_tag0, u): the blocks (a, t) and (b, u) are rotation vectors
// of small corrections applied on the left of the start rotations (so that
// b's covariance is the rotation error's in the tool frame), translations
// in mm. false (no residual, no exception) for a point behind the camera.
class LayoutCornerCost {
 public:
  LayoutCornerCost(const Eigen::Vector2d& px, const Eigen::Vector3d& c_in_tag,
                   const Camera& camera, const Eigen::Matrix3d& rig_R_tool0,
                   const Eigen::Matrix3d& tool_R_tag0)
      : px_(px),
        c_in_tag_(c_in_tag),
        intrinsics_(camera.intrinsics.ToArray()),
        cam_from_rig_(camera.cam_from_rig),
        rig_R_tool0_(rig_R_tool0),
        tool_R_tag0_(tool_R_tag0) {}

  template <typename T>
  bool operator()(const T* rig_from_tool, const T* tool_from_tag,
                  T* residuals) const {
    using M3 = Eigen::Matrix<T, 3, 3>;
    using V3 = Eigen::Matrix<T, 3, 1>;
    const M3 tool_R_tag =
        RotationMatrixFromVectorT(tool_from_tag) * tool_R_tag0_.cast<T>();
    const M3 rig_R_tool =
        RotationMatrixFromVectorT(rig_from_tool) * rig_R_tool0_.cast<T>();
    const V3 c_in_tool =
        tool_R_tag * c_in_tag_.cast<T>() +
        V3(tool_from_tag[3], tool_from_tag[4], tool_from_tag[5]);
    const V3 c_in_rig =
        rig_R_tool * c_in_tool +
        V3(rig_from_tool[3], rig_from_tool[4], rig_from_tool[5]);
    const V3 c_in_cam =
        cam_from_rig_.R.cast<T>() * c_in_rig + cam_from_rig_.t.cast<T>();
    T intrinsics[kNumIntrinsics];
    for (int i = 0; i < kNumIntrinsics; ++i) intrinsics[i] = T(intrinsics_[i]);
    return PixelResidual(intrinsics, c_in_cam.data(), px_, residuals);
  }

  static ceres::CostFunction* Create(const Eigen::Vector2d& px,
                                     const Eigen::Vector3d& c_in_tag,
                                     const Camera& camera,
                                     const Eigen::Matrix3d& rig_R_tool0,
                                     const Eigen::Matrix3d& tool_R_tag0) {
    return new ceres::AutoDiffCostFunction<LayoutCornerCost, 2, 6, 6>(
        new LayoutCornerCost(px, c_in_tag, camera, rig_R_tool0, tool_R_tag0));
  }

 private:
  const Eigen::Vector2d px_;
  const Eigen::Vector3d c_in_tag_;
  const std::array<double, kNumIntrinsics> intrinsics_;
  const Rigid3 cam_from_rig_;
  const Eigen::Matrix3d rig_R_tool0_;
  const Eigen::Matrix3d tool_R_tag0_;
};

// Step 1: rig_from_tag of every tag found in a frame, by id.
using TagPoses = std::map<int, Rigid3>;

std::vector<TagPoses> SingleTagPoses(const Rig& rig,
                                     const std::vector<LayoutFrame>& frames,
                                     const TargetLayoutOptions& options) {
  std::vector<TagPoses> poses(frames.size());
  for (size_t f = 0; f < frames.size(); ++f) {
    std::set<int> ids;
    for (const auto& cam : frames[f].detections) {
      for (const TagDetection& d : cam) ids.insert(d.id);
    }
    for (int id : ids) {
      Target one;
      one.family = options.family;
      TargetTag tag;
      tag.id = id;
      tag.size_mm = options.tag_size_mm;
      one.tags.push_back(tag);
      const ToolPoseResult r =
          EstimateToolPose(rig, one, frames[f].detections, options.pose);
      if (r.found) poses[f][id] = r.rig_from_tool;
    }
  }
  return poses;
}

// The candidate whose translation is nearest the per-axis median.
Rigid3 MedianCandidate(const std::vector<Rigid3>& candidates) {
  Eigen::Vector3d median;
  for (int k = 0; k < 3; ++k) {
    std::vector<double> v;
    for (const Rigid3& c : candidates) v.push_back(c.t(k));
    std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
    median(k) = v[v.size() / 2];
  }
  size_t best = 0;
  for (size_t i = 1; i < candidates.size(); ++i) {
    if ((candidates[i].t - median).norm() <
        (candidates[best].t - median).norm()) {
      best = i;
    }
  }
  return candidates[best];
}

// Steps 2-3: the reference tag and every tag's start pose in the tool frame.
std::map<int, Rigid3> StartLayout(const std::vector<TagPoses>& poses,
                                  int* reference) {
  std::map<int, int> seen;
  for (const TagPoses& p : poses) {
    for (const auto& [id, pose] : p) ++seen[id];
  }
  if (seen.empty()) {
    throw InputError(
        "no tag of the family was found in any view: check --family and the "
        "images (the tags must be sharp and at least ~20 px wide)");
  }
  *reference = seen.begin()->first;
  for (const auto& [id, n] : seen) {
    if (n > seen[*reference]) *reference = id;
  }
  std::map<int, Rigid3> layout = {{*reference, Rigid3()}};
  bool grew = true;
  while (grew && layout.size() < seen.size()) {
    grew = false;
    for (const auto& [id, n] : seen) {
      if (layout.count(id)) continue;
      std::vector<Rigid3> candidates;
      for (const TagPoses& p : poses) {
        if (!p.count(id)) continue;
        for (const auto& [placed, tool_from_placed] : layout) {
          if (!p.count(placed)) continue;
          candidates.push_back(tool_from_placed * p.at(placed).Inverse() *
                               p.at(id));
          break;
        }
      }
      if (candidates.empty()) continue;
      layout[id] = MedianCandidate(candidates);
      grew = true;
    }
  }
  if (layout.size() < seen.size()) {
    std::ostringstream os;
    os << "tags";
    for (const auto& [id, n] : seen) {
      if (!layout.count(id)) os << " " << id;
    }
    os << " were never seen in one image together with tag " << *reference
       << " or a tag connected to it, so their place on the tool is unknown: "
          "record views that show each of them together with a neighbouring "
          "tag";
    throw InputError(os.str());
  }
  return layout;
}

struct Corner {
  int frame = 0;  // index into the used frames
  int tag = 0;    // index into the layout's tags
  int camera = 0;
  int k = 0;
  Eigen::Vector2d px;
};

struct Problem {
  std::vector<int> ids;  // tags by index
  std::vector<std::array<double, 6>> tag_blocks, frame_blocks;
  std::vector<Eigen::Matrix3d> tag_R0, frame_R0;
  std::vector<Eigen::Vector3d> tag_t0, frame_t0;
  std::vector<Corner> corners;
  std::vector<bool> corner_used;
  int reference = 0;  // index
};

std::unique_ptr<ceres::Problem> BuildProblem(Problem* p, const Rig& rig,
                                             double tag_size_mm,
                                             ceres::LossFunction* loss) {
  ceres::Problem::Options po;
  po.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  auto problem = std::make_unique<ceres::Problem>(po);
  for (size_t i = 0; i < p->corners.size(); ++i) {
    if (!p->corner_used[i]) continue;
    const Corner& c = p->corners[i];
    problem->AddResidualBlock(
        LayoutCornerCost::Create(c.px, TagCornerInTag(c.k, tag_size_mm),
                                 rig.cameras[c.camera], p->frame_R0[c.frame],
                                 p->tag_R0[c.tag]),
        loss, p->frame_blocks[c.frame].data(), p->tag_blocks[c.tag].data());
  }
  problem->SetParameterBlockConstant(p->tag_blocks[p->reference].data());
  return problem;
}

Rigid3 BlockPose(const std::array<double, 6>& block,
                 const Eigen::Matrix3d& R0) {
  const Rigid3 delta = Rigid3FromPoseBlock(block.data());
  return {delta.R * R0, delta.t};
}

void Solve(ceres::Problem* problem, int max_iterations) {
  ceres::Solver::Options so;
  so.linear_solver_type = ceres::SPARSE_SCHUR;
  so.max_num_iterations = max_iterations;
  so.function_tolerance = 1e-12;
  so.gradient_tolerance = 1e-12;
  so.parameter_tolerance = 1e-12;
  ceres::Solver::Summary summary;
  ceres::Solve(so, problem, &summary);
}

// Residual norm of each corner (px); -1 for a point behind a camera.
std::vector<double> CornerResiduals(const Problem& p, const Rig& rig,
                                    double tag_size_mm) {
  std::vector<double> out;
  for (const Corner& c : p.corners) {
    const LayoutCornerCost cost(c.px, TagCornerInTag(c.k, tag_size_mm),
                                rig.cameras[c.camera], p.frame_R0[c.frame],
                                p.tag_R0[c.tag]);
    double r[2];
    out.push_back(
        cost(p.frame_blocks[c.frame].data(), p.tag_blocks[c.tag].data(), r)
            ? std::hypot(r[0], r[1])
            : -1.0);
  }
  return out;
}

// The frames with two or more placed tags, their start poses and corners.
Problem CollectProblem(const Rig& rig, const std::vector<LayoutFrame>& frames,
                       const std::vector<TagPoses>& poses,
                       const std::map<int, Rigid3>& layout, int reference,
                       const TargetLayoutOptions& options,
                       std::vector<int>* frames_used) {
  Problem p;
  std::map<int, int> index;
  for (const auto& [id, pose] : layout) {
    if (id == reference) p.reference = static_cast<int>(p.ids.size());
    index[id] = static_cast<int>(p.ids.size());
    p.ids.push_back(id);
    p.tag_R0.push_back(pose.R);
    p.tag_blocks.push_back({0, 0, 0, pose.t.x(), pose.t.y(), pose.t.z()});
  }
  Target start;
  start.family = options.family;
  for (const auto& [id, pose] : layout) {
    TargetTag tag;
    tag.id = id;
    tag.size_mm = options.tag_size_mm;
    tag.tool_from_tag = pose;
    start.tags.push_back(tag);
  }
  for (size_t f = 0; f < frames.size(); ++f) {
    if (poses[f].size() < 2) continue;
    const ToolPoseResult r =
        EstimateToolPose(rig, start, frames[f].detections, options.pose);
    if (!r.found) continue;
    const int fi = static_cast<int>(frames_used->size());
    frames_used->push_back(static_cast<int>(f));
    p.frame_R0.push_back(r.rig_from_tool.R);
    const Eigen::Vector3d& t = r.rig_from_tool.t;
    p.frame_blocks.push_back({0, 0, 0, t.x(), t.y(), t.z()});
    for (size_t c = 0; c < frames[f].detections.size(); ++c) {
      std::set<int> ids_here;
      for (const TagDetection& d : frames[f].detections[c]) {
        ids_here.insert(d.id);
      }
      for (const TagDetection& d : frames[f].detections[c]) {
        // Tags detected twice in one camera are ambiguous: left out.
        if (!index.count(d.id) || !poses[f].count(d.id)) continue;
        if (std::count_if(
                frames[f].detections[c].begin(), frames[f].detections[c].end(),
                [&](const TagDetection& e) { return e.id == d.id; }) > 1) {
          continue;
        }
        for (int k = 0; k < 4; ++k) {
          if (!d.usable[k]) continue;
          p.corners.push_back(
              {fi, index[d.id], static_cast<int>(c), k, d.corners[k]});
        }
      }
    }
  }
  p.corner_used.assign(p.corners.size(), true);
  return p;
}

// Corners whose residual is too large after the robust fit are left out.
int RejectOutliers(Problem* p, const Rig& rig,
                   const TargetLayoutOptions& options) {
  const std::vector<double> res = CornerResiduals(*p, rig, options.tag_size_mm);
  std::vector<double> sorted;
  for (double r : res) {
    if (r >= 0) sorted.push_back(r);
  }
  if (sorted.empty()) return 0;
  std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2,
                   sorted.end());
  const double limit = std::max(
      options.outlier_px, options.outlier_ratio * sorted[sorted.size() / 2]);
  // A corner that fails takes its tag observation's other corners with it:
  // a tag's corners err together (a quad fitted as a whole, a neighbouring
  // tag in the refinement's band), so its "good" corners are suspect too.
  std::set<std::array<int, 3>> failed;
  for (size_t i = 0; i < res.size(); ++i) {
    if (res[i] < 0 || res[i] > limit) {
      const Corner& c = p->corners[i];
      failed.insert({c.frame, c.tag, c.camera});
    }
  }
  int rejected = 0;
  for (size_t i = 0; i < res.size(); ++i) {
    const Corner& c = p->corners[i];
    if (p->corner_used[i] && failed.count({c.frame, c.tag, c.camera})) {
      p->corner_used[i] = false;
      ++rejected;
    }
  }
  return rejected;
}

// Moves every block's rotation into its start rotation (rotation vector 0),
// so that Jacobians at the blocks are those of left corrections of the
// fitted poses.
void Rebase(Problem* p) {
  for (size_t i = 0; i < p->tag_blocks.size(); ++i) {
    p->tag_R0[i] = BlockPose(p->tag_blocks[i], p->tag_R0[i]).R;
    std::fill_n(p->tag_blocks[i].begin(), 3, 0.0);
  }
  for (size_t f = 0; f < p->frame_blocks.size(); ++f) {
    p->frame_R0[f] = BlockPose(p->frame_blocks[f], p->frame_R0[f]).R;
    std::fill_n(p->frame_blocks[f].begin(), 3, 0.0);
  }
}

using Matrix26 = Eigen::Matrix<double, 2, 6, Eigen::RowMajor>;
using Matrix6d = Eigen::Matrix<double, 6, 6>;
using Vector6d = Eigen::Matrix<double, 6, 1>;

// One corner's residual and its Jacobians on the frame's and the tag's
// blocks; false for a point behind the camera.
bool CornerJacobians(const Eigen::Vector2d& px, const Eigen::Vector3d& c_in_tag,
                     const Camera& camera, const Eigen::Matrix3d& rig_R_tool0,
                     const Eigen::Matrix3d& tool_R_tag0,
                     const double* frame_block, const double* tag_block,
                     Eigen::Vector2d* residual, Matrix26* d_frame,
                     Matrix26* d_tag) {
  const std::unique_ptr<ceres::CostFunction> cost(
      LayoutCornerCost::Create(px, c_in_tag, camera, rig_R_tool0, tool_R_tag0));
  const double* blocks[2] = {frame_block, tag_block};
  double* jacobians[2] = {d_frame->data(), d_tag->data()};
  return cost->Evaluate(blocks, residual->data(), jacobians);
}

// Inverse on the range of a symmetric positive semi-definite matrix: a frame
// whose every tag observation was left out has H_ff = 0 and no say.
Matrix6d PseudoInverse(const Matrix6d& h) {
  const Eigen::SelfAdjointEigenSolver<Matrix6d> eig(h);
  const Eigen::Matrix<double, 6, 1> values = eig.eigenvalues();
  const double floor = 1e-12 * std::max(values.maxCoeff(), 0.0);
  Eigen::Matrix<double, 6, 1> inverse;
  for (int k = 0; k < 6; ++k) {
    inverse(k) = values(k) > floor && values(k) > 0 ? 1 / values(k) : 0;
  }
  return eig.eigenvectors() * inverse.asDiagonal() *
         eig.eigenvectors().transpose();
}

// Step 5: the tags' joint covariance (LayoutCovariance), 6 per tag in the
// problem's tag order, the reference's rows and columns 0. The frame poses
// are eliminated per frame: S = H_tt - sum_f H_tf H_ff^-1 H_ft, and a tag
// observation's score on the tags is u_c = g_t - H_tf H_ff^-1 g_f.
Eigen::MatrixXd TagCovariance(const Problem& p, const Rig& rig,
                              double tag_size_mm, double sigma0,
                              LayoutCovariance model) {
  const int tags = static_cast<int>(p.ids.size());
  const int frames = static_cast<int>(p.frame_blocks.size());
  const auto column = [&](int tag) {
    return tag == p.reference ? -1 : 6 * (tag < p.reference ? tag : tag - 1);
  };
  const int dim = 6 * (tags - 1);
  std::vector<Matrix6d> h_ff(frames, Matrix6d::Zero());
  std::vector<Eigen::MatrixXd> h_ft(frames, Eigen::MatrixXd::Zero(6, dim));
  Eigen::MatrixXd h_tt = Eigen::MatrixXd::Zero(dim, dim);
  // Each tag observation's Jacobian rows on (its frame's 6, the tags') and
  // residuals, keyed (frame, tag, camera).
  struct Observation {
    std::vector<Eigen::RowVectorXd> rows;
    std::vector<double> residuals;
  };
  std::map<std::array<int, 3>, Observation> observations;
  for (size_t i = 0; i < p.corners.size(); ++i) {
    if (!p.corner_used[i]) continue;
    const Corner& c = p.corners[i];
    Eigen::Vector2d r;
    Matrix26 jf, jt;
    if (!CornerJacobians(c.px, TagCornerInTag(c.k, tag_size_mm),
                         rig.cameras[c.camera], p.frame_R0[c.frame],
                         p.tag_R0[c.tag], p.frame_blocks[c.frame].data(),
                         p.tag_blocks[c.tag].data(), &r, &jf, &jt)) {
      continue;
    }
    h_ff[c.frame] += jf.transpose() * jf;
    const int col = column(c.tag);
    Observation& obs = observations[{c.frame, c.tag, c.camera}];
    for (int k = 0; k < 2; ++k) {
      Eigen::RowVectorXd row = Eigen::RowVectorXd::Zero(6 + dim);
      row.head<6>() = jf.row(k);
      if (col >= 0) row.segment<6>(6 + col) = jt.row(k);
      obs.rows.push_back(row);
      obs.residuals.push_back(r(k));
    }
    if (col < 0) continue;
    h_ft[c.frame].middleCols<6>(col) += jf.transpose() * jt;
    h_tt.block<6, 6>(col, col) += jt.transpose() * jt;
  }
  std::vector<Matrix6d> h_ff_inv(frames);
  Eigen::MatrixXd schur = h_tt;
  for (int f = 0; f < frames; ++f) {
    h_ff_inv[f] = PseudoInverse(h_ff[f]);
    schur -= h_ft[f].transpose() * h_ff_inv[f] * h_ft[f];
  }
  const Eigen::MatrixXd schur_inv =
      schur.ldlt().solve(Eigen::MatrixXd::Identity(dim, dim));
  Eigen::MatrixXd free_cov;
  if (model == LayoutCovariance::kCornerNoise) {
    free_cov = sigma0 * sigma0 * schur_inv;
  } else {
    // The inverse of H on (frame f, tags): [[A, B], [B^T, S^-1]] with
    // B = -H_ff^-1 H_ft S^-1, A = H_ff^-1 - B H_tf H_ff^-1.
    Eigen::MatrixXd meat = Eigen::MatrixXd::Zero(dim, dim);
    Eigen::MatrixXd local(6 + dim, 6 + dim);
    for (const auto& [key, obs] : observations) {
      const int f = key[0];
      const Eigen::MatrixXd b = -h_ff_inv[f] * h_ft[f] * schur_inv;
      local.topLeftCorner(6, 6) =
          h_ff_inv[f] - b * h_ft[f].transpose() * h_ff_inv[f];
      local.topRightCorner(6, dim) = b;
      local.bottomLeftCorner(dim, 6) = b.transpose();
      local.bottomRightCorner(dim, dim) = schur_inv;
      const int n = static_cast<int>(obs.rows.size());
      Eigen::MatrixXd jacobian(n, 6 + dim);
      Eigen::VectorXd residual(n);
      for (int k = 0; k < n; ++k) {
        jacobian.row(k) = obs.rows[k];
        residual(k) = obs.residuals[k];
      }
      // The residuals the observation would have had, were it left out of
      // the fit: (I - J_c H^-1 J_c^T)^-1 r_c (jackknife-like CR3 scores).
      const Eigen::MatrixXd leverage = jacobian * local * jacobian.transpose();
      Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(
          Eigen::MatrixXd::Identity(n, n) - leverage);
      const Eigen::VectorXd kept =
          eig.eigenvalues().cwiseMax(0.05).cwiseInverse();
      const Eigen::VectorXd left_out = eig.eigenvectors() * kept.asDiagonal() *
                                       eig.eigenvectors().transpose() *
                                       residual;
      const Eigen::VectorXd score = jacobian.transpose() * left_out;
      const Eigen::VectorXd u =
          score.tail(dim) -
          h_ft[f].transpose() * (h_ff_inv[f] * score.head<6>());
      meat += u * u.transpose();
    }
    free_cov = schur_inv * meat * schur_inv;
  }
  Eigen::MatrixXd cov = Eigen::MatrixXd::Zero(6 * tags, 6 * tags);
  for (int a = 0; a < tags; ++a) {
    for (int b = 0; b < tags; ++b) {
      if (column(a) < 0 || column(b) < 0) continue;
      cov.block<6, 6>(6 * a, 6 * b) =
          free_cov.block<6, 6>(column(a), column(b));
    }
  }
  return cov;
}

// How a corner's residual moves with its offset in the tag's plane (2 x 2):
// c_in_tool = R_tag c_in_tag + u, so d r / d c_in_tag[x, y] is the
// Jacobian on the tag's translation u times R_tag's first two columns.
Eigen::Matrix2d OffsetJacobian(const Matrix26& d_tag,
                               const Eigen::Matrix3d& tool_R_tag) {
  return d_tag.rightCols<3>() * tool_R_tag.leftCols<2>();
}

// Per (tag index, corner): how many observations, the sums of z = Jd^-1 r
// (the residual in the tag's plane, mm), of |z|^2 and of Jd^-1 times the
// residual's change with the offsets once the fit has absorbed its part.
struct OffsetGroup {
  int n = 0;
  Eigen::Vector2d z_sum = Eigen::Vector2d::Zero();
  double z_sq = 0;
  Eigen::MatrixXd left;
};
using OffsetGroups = std::map<std::pair<int, int>, OffsetGroup>;

void AddOffsetEvidence(int tag, int k, const Eigen::Matrix2d& jd,
                       const Eigen::Vector2d& residual,
                       const Eigen::MatrixXd& left, OffsetGroups* groups) {
  // A tag seen edge-on says nothing about offsets in its plane.
  if (!(std::abs(jd.determinant()) > 1e-6 * jd.squaredNorm())) return;
  const Eigen::Matrix2d to_plane = jd.inverse();
  OffsetGroup& g = (*groups)[{tag, k}];
  if (g.n == 0) g.left = Eigen::MatrixXd::Zero(2, left.cols());
  const Eigen::Vector2d z = to_plane * residual;
  ++g.n;
  g.z_sum += z;
  g.z_sq += z.squaredNorm();
  g.left += to_plane * left;
}

// Per group the mean m of z over its n observations: E|m|^2 = s^2 |B|_F^2
// + var(z) / n, B the mean of the mapped left-over change.
CornerOffsetMoments MomentsOf(const OffsetGroups& groups) {
  CornerOffsetMoments out;
  for (const auto& [key, g] : groups) {
    if (g.n < 2) continue;
    const Eigen::Vector2d m = g.z_sum / g.n;
    const double var = (g.z_sq - g.n * m.squaredNorm()) / (g.n - 1);
    out.shared_mm2 += m.squaredNorm() - var / g.n;
    out.seen += (g.left / g.n).squaredNorm();
  }
  return out;
}

struct CornerOffsets {
  CornerOffsetMoments moments;
  double sigma_mm = 0;
  Eigen::MatrixXd tags_from_offsets;  // 6 per tag x 8 per tag
};

// The corner offsets shared by every view (TargetLayoutResult::
// corner_offset_sigma_mm). Model: corner k of tag i sits at its printed
// place plus d_ik (tag plane, mm) in every view, d_ik ~ N(0, s^2 I2),
// independent between corners; the residual of corner observation j is
// r_j = (I - P) (Jd d + e) with P the fit's projection (the poses and the
// layout absorb part of d) and e the noise of that view.
//  - the layout moves with d as G = -H^-1 J^T Jd (its tag rows);
//  - each observation's residual mapped into its tag's plane, z_j =
//    Jd_j^-1 r_j (mm); per (tag, corner) the mean m over its n views has
//    E|m|^2 = s^2 |B|_F^2 + var(z) / n, with B the mean of Jd_j^-1 ((I -
//    P) Jd)_j (the part of d the fit leaves in the residuals). So
//    s^2 = sum (|m|^2 - var(z) / n) / sum |B|_F^2 (moments; 0 if negative).
// The frames are eliminated by their Schur complement as in TagCovariance.
CornerOffsets CornerOffsetSystematic(const Problem& p, const Rig& rig,
                                     double tag_size_mm) {
  const int tags = static_cast<int>(p.ids.size());
  const int frames = static_cast<int>(p.frame_blocks.size());
  const int nd = 8 * tags;
  const auto column = [&](int tag) {
    return tag == p.reference ? -1 : 6 * (tag < p.reference ? tag : tag - 1);
  };
  const int dim = 6 * (tags - 1);
  struct Row {
    int corner;
    Eigen::Vector2d r;
    Matrix26 jf, jt;
    Eigen::Matrix2d jd;
  };
  std::vector<Row> rows;
  std::vector<Matrix6d> h_ff(frames, Matrix6d::Zero());
  std::vector<Eigen::MatrixXd> h_ft(frames, Eigen::MatrixXd::Zero(6, dim));
  std::vector<Eigen::MatrixXd> b_f(frames, Eigen::MatrixXd::Zero(6, nd));
  Eigen::MatrixXd h_tt = Eigen::MatrixXd::Zero(dim, dim);
  Eigen::MatrixXd b_t = Eigen::MatrixXd::Zero(dim, nd);
  for (size_t i = 0; i < p.corners.size(); ++i) {
    if (!p.corner_used[i]) continue;
    const Corner& c = p.corners[i];
    Row row{static_cast<int>(i), {}, {}, {}, {}};
    if (!CornerJacobians(c.px, TagCornerInTag(c.k, tag_size_mm),
                         rig.cameras[c.camera], p.frame_R0[c.frame],
                         p.tag_R0[c.tag], p.frame_blocks[c.frame].data(),
                         p.tag_blocks[c.tag].data(), &row.r, &row.jf,
                         &row.jt)) {
      continue;
    }
    row.jd = OffsetJacobian(row.jt, p.tag_R0[c.tag]);
    const int dcol = 8 * c.tag + 2 * c.k;
    h_ff[c.frame] += row.jf.transpose() * row.jf;
    b_f[c.frame].middleCols<2>(dcol) += row.jf.transpose() * row.jd;
    const int col = column(c.tag);
    if (col >= 0) {
      h_ft[c.frame].middleCols<6>(col) += row.jf.transpose() * row.jt;
      h_tt.block<6, 6>(col, col) += row.jt.transpose() * row.jt;
      b_t.middleRows<6>(col).middleCols<2>(dcol) += row.jt.transpose() * row.jd;
    }
    rows.push_back(row);
  }
  // H [x_f; x_t] = J^T Jd by the Schur complement on the tags.
  std::vector<Matrix6d> h_ff_inv(frames);
  Eigen::MatrixXd schur = h_tt, rhs = b_t;
  for (int f = 0; f < frames; ++f) {
    h_ff_inv[f] = PseudoInverse(h_ff[f]);
    schur -= h_ft[f].transpose() * h_ff_inv[f] * h_ft[f];
    rhs -= h_ft[f].transpose() * h_ff_inv[f] * b_f[f];
  }
  const Eigen::MatrixXd x_t = schur.ldlt().solve(rhs);
  std::vector<Eigen::MatrixXd> x_f(frames);
  for (int f = 0; f < frames; ++f) {
    x_f[f] = h_ff_inv[f] * (b_f[f] - h_ft[f] * x_t);
  }
  OffsetGroups groups;
  for (const Row& row : rows) {
    const Corner& c = p.corners[row.corner];
    Eigen::MatrixXd left = -row.jf * x_f[c.frame];
    const int col = column(c.tag);
    if (col >= 0) left -= row.jt * x_t.middleRows<6>(col);
    left.middleCols<2>(8 * c.tag + 2 * c.k) += row.jd;
    AddOffsetEvidence(c.tag, c.k, row.jd, row.r, left, &groups);
  }
  const CornerOffsetMoments moments = MomentsOf(groups);
  CornerOffsets out;
  out.moments = moments;
  out.sigma_mm = moments.SigmaMm();
  out.tags_from_offsets = Eigen::MatrixXd::Zero(6 * tags, nd);
  for (int t = 0; t < tags; ++t) {
    if (column(t) >= 0) {
      out.tags_from_offsets.middleRows<6>(6 * t) =
          -x_t.middleRows<6>(column(t));
    }
  }
  return out;
}

}  // namespace

TargetLayoutResult MeasureTargetLayout(const Rig& rig,
                                       const std::vector<LayoutFrame>& frames,
                                       const TargetLayoutOptions& options) {
  options.Check();
  for (const LayoutFrame& f : frames) {
    if (f.detections.size() != rig.cameras.size()) {
      throw InputError("frame " + std::to_string(f.frame) + " has " +
                       std::to_string(f.detections.size()) +
                       " cameras' detections; the rig has " +
                       std::to_string(rig.cameras.size()));
    }
  }
  const std::vector<TagPoses> poses = SingleTagPoses(rig, frames, options);
  int multi = 0;
  for (const TagPoses& p : poses) multi += p.size() >= 2 ? 1 : 0;
  TargetLayoutResult result;
  result.multi_tag_views = multi;
  result.frames = static_cast<int>(frames.size());
  if (multi < options.min_views) {
    throw InputError(
        "only " + std::to_string(multi) + " of " +
        std::to_string(frames.size()) +
        " views show two or more tags of the tool (at least " +
        std::to_string(options.min_views) +
        " needed): record the tool from more directions, each view showing "
        "neighbouring tags together");
  }
  const std::map<int, Rigid3> layout =
      StartLayout(poses, &result.reference_tag_id);
  Problem p =
      CollectProblem(rig, frames, poses, layout, result.reference_tag_id,
                     options, &result.frames_used);
  result.views_used = static_cast<int>(result.frames_used.size());
  if (result.views_used < options.min_views) {
    throw InputError(
        "only " + std::to_string(result.views_used) +
        " views gave a tool pose from two or more tags (at least " +
        std::to_string(options.min_views) +
        " needed): record more views of the tool");
  }
  {
    ceres::HuberLoss huber(options.huber_px);
    auto robust = BuildProblem(&p, rig, options.tag_size_mm, &huber);
    Solve(robust.get(), options.max_iterations);
  }
  result.corners_rejected = RejectOutliers(&p, rig, options);
  auto problem = BuildProblem(&p, rig, options.tag_size_mm, nullptr);
  Solve(problem.get(), options.max_iterations);

  double cost = 0;
  problem->Evaluate(ceres::Problem::EvaluateOptions(), &cost, nullptr, nullptr,
                    nullptr);
  const int residuals = problem->NumResiduals();
  const int parameters = 6 * (static_cast<int>(p.frame_blocks.size()) +
                              static_cast<int>(p.ids.size()) - 1);
  result.corners_used = residuals / 2;
  result.rms_px = std::sqrt(2 * cost / std::max(1, residuals));
  result.sigma0_px = std::sqrt(2 * cost / std::max(1, residuals - parameters));
  if (!(result.rms_px <= options.max_rms_px)) {
    std::ostringstream os;
    os << "the tag corners fit the rig with an RMS of " << result.rms_px
       << " px (at most " << options.max_rms_px
       << " expected): check --size (the edge of the tags' black square, "
          "mm), the rig file and the family";
    throw InputError(os.str());
  }

  result.target.family = options.family;
  result.target.has_tip = false;
  for (size_t i = 0; i < p.ids.size(); ++i) {
    LayoutTag tag;
    tag.id = p.ids[i];
    tag.tool_from_tag = BlockPose(p.tag_blocks[i], p.tag_R0[i]);
    std::set<int> frames_seen;
    for (size_t c = 0; c < p.corners.size(); ++c) {
      if (p.corner_used[c] && p.corners[c].tag == static_cast<int>(i)) {
        frames_seen.insert(p.corners[c].frame);
      }
    }
    tag.views = static_cast<int>(frames_seen.size());
    result.tags.push_back(tag);
  }
  Rebase(&p);
  result.covariance = TagCovariance(p, rig, options.tag_size_mm,
                                    result.sigma0_px, options.covariance);
  const CornerOffsets offsets =
      CornerOffsetSystematic(p, rig, options.tag_size_mm);
  result.corner_offset_sigma_mm = offsets.sigma_mm;
  result.corner_offset_moments = offsets.moments;
  result.tags_from_corner_offsets = offsets.tags_from_offsets;
  result.covariance += offsets.sigma_mm * offsets.sigma_mm *
                       offsets.tags_from_offsets *
                       offsets.tags_from_offsets.transpose();
  for (size_t i = 0; i < result.tags.size(); ++i) {
    for (int k = 0; k < 3; ++k) {
      const int row = 6 * static_cast<int>(i) + k;
      result.tags[i].sigma_r_deg(k) =
          std::sqrt(result.covariance(row, row)) * 180 / M_PI;
      result.tags[i].sigma_t_mm(k) =
          std::sqrt(result.covariance(row + 3, row + 3));
    }
  }
  for (const LayoutTag& t : result.tags) {
    TargetTag tag;
    tag.id = t.id;
    tag.size_mm = options.tag_size_mm;
    tag.tool_from_tag = t.tool_from_tag;
    tag.has_sigma = true;
    tag.sigma_t_mm = t.sigma_t_mm;
    tag.sigma_r_deg = t.sigma_r_deg;
    result.target.tags.push_back(tag);
  }
  for (size_t f = 0; f < p.frame_blocks.size(); ++f) {
    result.rig_from_tool.push_back(BlockPose(p.frame_blocks[f], p.frame_R0[f]));
  }
  return result;
}

Eigen::MatrixXd ToolPoseLayoutJacobian(const Rig& rig,
                                       const TargetLayoutResult& layout,
                                       const ToolPoseResult& pose,
                                       Eigen::Matrix<double, 6, 6>* information,
                                       Eigen::MatrixXd* from_corner_offsets) {
  const int tags = static_cast<int>(layout.tags.size());
  Matrix6d h = Matrix6d::Zero();
  Eigen::MatrixXd cross = Eigen::MatrixXd::Zero(6, 6 * tags);
  Eigen::MatrixXd cross_offsets = Eigen::MatrixXd::Zero(6, 8 * tags);
  const std::array<double, 6> frame_block = {0,
                                             0,
                                             0,
                                             pose.rig_from_tool.t.x(),
                                             pose.rig_from_tool.t.y(),
                                             pose.rig_from_tool.t.z()};
  for (const TagObservationResult& obs : pose.tags) {
    if (!obs.used) continue;
    int index = -1;
    for (int i = 0; i < tags; ++i) {
      if (layout.tags[i].id == obs.tag_id) index = i;
    }
    if (index < 0) continue;
    const Rigid3& tool_from_tag = layout.tags[index].tool_from_tag;
    const std::array<double, 6> tag_block = {
        0, 0, 0, tool_from_tag.t.x(), tool_from_tag.t.y(), tool_from_tag.t.z()};
    for (int k = 0; k < 4; ++k) {
      if (!obs.corner_used[k]) continue;
      Eigen::Vector2d r;
      Matrix26 jf, jt;
      if (!CornerJacobians(obs.corners_px[k],
                           TagCornerInTag(k, layout.target.tags[index].size_mm),
                           rig.cameras[obs.camera], pose.rig_from_tool.R,
                           tool_from_tag.R, frame_block.data(),
                           tag_block.data(), &r, &jf, &jt)) {
        continue;
      }
      h += jf.transpose() * jf;
      cross.middleCols<6>(6 * index) += jf.transpose() * jt;
      cross_offsets.middleCols<2>(8 * index + 2 * k) +=
          jf.transpose() * OffsetJacobian(jt, tool_from_tag.R);
    }
  }
  if (information) *information = h;
  if (from_corner_offsets)
    *from_corner_offsets = -h.ldlt().solve(cross_offsets);
  return -h.ldlt().solve(cross);
}

namespace {

// The tool poses of the pivot frames: rig_from_tool, its covariance up to
// scale (the inverse of the pose fit's J^T J), how it moves with the layout
// (ToolPoseLayoutJacobian) and the session frame number.
struct PivotPoses {
  std::vector<Rigid3> poses;
  std::vector<Eigen::Matrix<double, 6, 6>> covariances;
  std::vector<Eigen::MatrixXd> layout_jacobians;
  std::vector<Eigen::MatrixXd> offset_jacobians;  // d pose / d corner offsets
  std::vector<ToolPoseResult> results;
  std::vector<int> frames;
};

// The pivot session's evidence on the shared corner offsets (as
// CornerOffsetSystematic's on the layout session's): the same offsets move
// each pivot pose (O_i + L_i G) and the layout (G), and what the pose fit
// does not absorb stays in its residuals.
CornerOffsetMoments PivotOffsetMoments(const Rig& rig,
                                       const TargetLayoutResult& layout,
                                       const PivotPoses& p) {
  const Eigen::MatrixXd& g = layout.tags_from_corner_offsets;
  if (g.rows() != 6 * static_cast<int>(layout.tags.size())) return {};
  OffsetGroups groups;
  for (size_t i = 0; i < p.poses.size(); ++i) {
    const Eigen::MatrixXd pose_move =
        p.offset_jacobians[i] + p.layout_jacobians[i] * g;
    const Rigid3& pose = p.poses[i];
    const std::array<double, 6> frame_block = {
        0, 0, 0, pose.t.x(), pose.t.y(), pose.t.z()};
    for (const TagObservationResult& obs : p.results[i].tags) {
      if (!obs.used) continue;
      int index = -1;
      for (size_t t = 0; t < layout.tags.size(); ++t) {
        if (layout.tags[t].id == obs.tag_id) index = static_cast<int>(t);
      }
      if (index < 0) continue;
      const Rigid3& tag = layout.tags[index].tool_from_tag;
      const std::array<double, 6> tag_block = {0,         0,         0,
                                               tag.t.x(), tag.t.y(), tag.t.z()};
      for (int k = 0; k < 4; ++k) {
        if (!obs.corner_used[k]) continue;
        Eigen::Vector2d r;
        Matrix26 jf, jt;
        if (!CornerJacobians(
                obs.corners_px[k],
                TagCornerInTag(k, layout.target.tags[index].size_mm),
                rig.cameras[obs.camera], pose.R, tag.R, frame_block.data(),
                tag_block.data(), &r, &jf, &jt)) {
          continue;
        }
        const Eigen::Matrix2d jd = OffsetJacobian(jt, tag.R);
        Eigen::MatrixXd left = jf * pose_move + jt * g.middleRows<6>(6 * index);
        left.middleCols<2>(8 * index + 2 * k) += jd;
        AddOffsetEvidence(index, k, jd, r, left, &groups);
      }
    }
  }
  return MomentsOf(groups);
}

// The pivot frames whose tool pose misses the common pivot: the worst pose
// is left out while its pivot residual exceeds max(options.outlier_mm,
// options.outlier_ratio * median residual), the pivot refitted each time,
// and never below options.min_views poses. One pose off by a bad tag
// observation pulls the tip by its residual times its leverage. Returns
// the session frame numbers left out.
std::vector<int> RejectPivotOutliers(const PivotTipOptions& options,
                                     PivotPoses* poses) {
  std::vector<int> rejected;
  while (static_cast<int>(poses->poses.size()) > options.min_views) {
    const PivotResult fit = PivotCalibration(
        poses->poses, options.min_conditioning, 0, poses->covariances);
    const double limit =
        std::max(options.outlier_mm,
                 options.outlier_ratio * UpperMedian(fit.residuals_mm));
    const auto worst =
        std::max_element(fit.residuals_mm.begin(), fit.residuals_mm.end());
    if (*worst <= limit) break;
    const auto i = worst - fit.residuals_mm.begin();
    rejected.push_back(poses->frames[i]);
    poses->poses.erase(poses->poses.begin() + i);
    poses->covariances.erase(poses->covariances.begin() + i);
    poses->layout_jacobians.erase(poses->layout_jacobians.begin() + i);
    poses->offset_jacobians.erase(poses->offset_jacobians.begin() + i);
    poses->results.erase(poses->results.begin() + i);
    poses->frames.erase(poses->frames.begin() + i);
  }
  std::sort(rejected.begin(), rejected.end());
  return rejected;
}

}  // namespace

PivotTipResult MeasurePivotTip(const Rig& rig, const TargetLayoutResult& layout,
                               const std::vector<LayoutFrame>& frames,
                               const PivotTipOptions& options) {
  options.Check();
  PivotPoses p;
  for (const LayoutFrame& f : frames) {
    const ToolPoseResult r =
        EstimateToolPose(rig, layout.target, f.detections, options.pose);
    if (!r.found) continue;
    Matrix6d information;
    Eigen::MatrixXd from_offsets;
    p.layout_jacobians.push_back(
        ToolPoseLayoutJacobian(rig, layout, r, &information, &from_offsets));
    p.offset_jacobians.push_back(from_offsets);
    p.results.push_back(r);
    p.poses.push_back(r.rig_from_tool);
    p.covariances.push_back(PseudoInverse(information));
    p.frames.push_back(f.frame);
  }
  if (static_cast<int>(p.poses.size()) < options.min_views) {
    throw InputError("the tool was found in " + std::to_string(p.poses.size()) +
                     " of " + std::to_string(frames.size()) +
                     " frames (at least " + std::to_string(options.min_views) +
                     " needed): record the tool pivoting about its tip with "
                     "its tags in view");
  }
  PivotTipResult out;
  out.frames_rejected = RejectPivotOutliers(options, &p);
  out.pivot = PivotCalibration(p.poses, options.min_conditioning,
                               options.min_tilt_deg, p.covariances);
  out.views = static_cast<int>(p.poses.size());
  // d tip / d layout = sum over frames of d tip / d pose_i * d pose_i / d
  // layout; the layout's covariance through it adds to the pivot's.
  const Eigen::MatrixXd tip_from_poses =
      PivotTipJacobian(p.poses, out.pivot.tip_in_tool, out.pivot.weights);
  Eigen::MatrixXd tip_from_layout =
      Eigen::MatrixXd::Zero(3, layout.covariance.cols());
  for (size_t i = 0; i < p.poses.size(); ++i) {
    tip_from_layout +=
        tip_from_poses.middleCols<6>(6 * i) * p.layout_jacobians[i];
  }
  // The shared corner offsets move the layout and every pivot pose at once:
  // d tip / d offsets = sum_i d tip / d pose_i (d pose_i / d offsets +
  // d pose_i / d layout G); their share leaves the layout's covariance.
  // Their sigma from both sessions' residuals.
  CornerOffsetMoments moments = PivotOffsetMoments(rig, layout, p);
  moments.shared_mm2 += layout.corner_offset_moments.shared_mm2;
  moments.seen += layout.corner_offset_moments.seen;
  out.corner_offset_sigma_mm = moments.SigmaMm();
  const double s2 = out.corner_offset_sigma_mm * out.corner_offset_sigma_mm;
  Eigen::MatrixXd layout_random = layout.covariance;
  Eigen::Matrix3d systematic = Eigen::Matrix3d::Zero();
  const Eigen::MatrixXd& g = layout.tags_from_corner_offsets;
  if (g.rows() == layout.covariance.rows()) {
    layout_random -= layout.corner_offset_sigma_mm *
                     layout.corner_offset_sigma_mm * g * g.transpose();
    Eigen::MatrixXd tip_from_offsets = Eigen::MatrixXd::Zero(3, g.cols());
    for (size_t i = 0; i < p.poses.size(); ++i) {
      tip_from_offsets += tip_from_poses.middleCols<6>(6 * i) *
                          (p.offset_jacobians[i] + p.layout_jacobians[i] * g);
    }
    systematic = s2 * tip_from_offsets * tip_from_offsets.transpose();
  }
  const Eigen::Matrix3d layout_cov =
      tip_from_layout * layout_random * tip_from_layout.transpose();
  const Eigen::Matrix3d total =
      out.pivot.tip_covariance + layout_cov + systematic;
  for (int k = 0; k < 3; ++k) {
    out.systematic_sigma_mm(k) = std::sqrt(std::max(0.0, systematic(k, k)));
    out.layout_sigma_mm(k) = std::sqrt(std::max(0.0, layout_cov(k, k)));
    out.tip_sigma_mm(k) = std::sqrt(std::max(0.0, total(k, k)));
  }
  return out;
}

std::vector<LayoutFrame> DetectSessionTags(
    const Session& session, const Rig& rig, const AprilTagOptions& detector,
    BayerPattern bayer, const std::function<void(int, int)>& progress) {
  const int nc = static_cast<int>(rig.cameras.size());
  if (session.cameras.size() != rig.cameras.size()) {
    throw InputError(session.dir + ": the session has " +
                     std::to_string(session.cameras.size()) +
                     " cameras, the rig " + std::to_string(nc));
  }
  detector.Check();
  const std::vector<std::unique_ptr<AprilTagDetector>> detectors =
      CameraDetectors(rig, detector);
  std::vector<LayoutFrame> frames;
  const int total = static_cast<int>(session.frames.size());
  for (const SessionFrame& sf : session.frames) {
    LayoutFrame f;
    f.frame = sf.frame;
    f.detections.resize(nc);
    ForEachCamera(nc, [&](int c) {
      f.detections[c] = detectors[c]->Detect(
          ReadCameraImage(sf.images[c], rig.cameras[c].intrinsics, bayer));
    });
    frames.push_back(std::move(f));
    if (progress) progress(static_cast<int>(frames.size()), total);
  }
  return frames;
}

}  // namespace kincal
