#include "calib/fit.h"

#include <ceres/ceres.h>

#include <Eigen/Geometry>
#include <chrono>
#include <map>
#include <memory>
#include <set>

#include "data/error.h"
#include "data/rigid3.h"

namespace kincal {
namespace {

// Residual of one measurement.
//   kMeasured:   r = meas_from_base * tip_in_base(q; rows, errors, drift) -
//   p_in_meas kFixedPoint: r = tip_in_base(q; rows, errors, drift) -
//   point_in_base
// Parameter blocks, in order: the n+1 row geometry blocks (tool last), the n
// joint error blocks, the drift block, then meas_from_base (6) or
// point_in_base (3). The chain is copied for its structure (row kinds, axes);
// its values are never read here.
class TipResidual {
 public:
  TipResidual(const Chain& chain, const Measurement& m)
      : chain_(chain), m_(m) {}

  template <typename T>
  bool operator()(T const* const* params, T* residual) const {
    const int n = chain_.num_joints();
    const T* const* rows = params;
    const T* const* joint_errors = params + n + 1;
    const T* drift = params[2 * n + 1];
    const T* target = params[2 * n + 2];
    const Vec3<T> tip_in_base =
        TipInBase<T>(chain_, rows, joint_errors, drift, m_.input);
    if (m_.kind == Measurement::kMeasured) {
      const Vec3<T> p_in_meas = ApplyFrame(target, tip_in_base);
      for (int k = 0; k < 3; ++k) residual[k] = p_in_meas[k] - m_.p_in_meas[k];
    } else {
      for (int k = 0; k < 3; ++k) residual[k] = tip_in_base[k] - target[k];
    }
    return true;
  }

 private:
  const Chain chain_;
  const Measurement m_;
};

// TipResidual as a Ceres cost function whose Jacobian is taken by
// forward-mode autodiff over only the entries asked for (`entries`, per
// block in TipResidual's order), in chunks of kStride; the other columns of
// the blocks Ceres asks for are zero. Ceres's DynamicAutoDiffCostFunction
// differentiates every entry of every block it is asked for: with the
// 35-entry joint-error blocks that is 28 passes through the chain per pose
// for a 5-joint robot in ResidualJacobian, against 3 here for 18 geometry
// parameters and the frame. Ceres passes null for constant blocks; the
// entries a SubsetManifold holds are multiplied by zero, so their columns
// need not be computed.
class TipCost : public ceres::CostFunction {
 public:
  static constexpr int kStride = 8;
  using Entries = std::vector<std::vector<int>>;

  TipCost(const Chain& chain, const Measurement& m, Entries entries)
      : functor_(chain, m), entries_(std::move(entries)) {
    const int n = chain.num_joints();
    for (int r = 0; r <= n; ++r)
      mutable_parameter_block_sizes()->push_back(kRowBlockSize);
    for (int j = 0; j < n; ++j)
      mutable_parameter_block_sizes()->push_back(kJointErrorBlockSize);
    mutable_parameter_block_sizes()->push_back(kDriftBlockSize);
    mutable_parameter_block_sizes()->push_back(
        m.kind == Measurement::kMeasured ? kFrameBlockSize : 3);
    set_num_residuals(3);
    entries_.resize(parameter_block_sizes().size());
  }

  bool Evaluate(double const* const* params, double* residuals,
                double** jacobians) const override {
    if (jacobians == nullptr) return functor_(params, residuals);
    using Jet = ceres::Jet<double, kStride>;
    const std::vector<int32_t>& sizes = parameter_block_sizes();
    const int num_blocks = static_cast<int>(sizes.size());
    std::vector<int> offset(num_blocks + 1, 0);
    for (int b = 0; b < num_blocks; ++b) offset[b + 1] = offset[b] + sizes[b];
    std::vector<Jet> jets(offset[num_blocks]);
    std::vector<const Jet*> blocks(num_blocks);
    std::vector<std::pair<int, int>> active;  // (block, entry)
    for (int b = 0; b < num_blocks; ++b) {
      for (int e = 0; e < sizes[b]; ++e)
        jets[offset[b] + e] = Jet(params[b][e]);
      blocks[b] = jets.data() + offset[b];
      if (jacobians[b] == nullptr) continue;
      std::fill(jacobians[b], jacobians[b] + 3 * sizes[b], 0.0);
      for (int e : entries_[b]) active.emplace_back(b, e);
    }
    if (active.empty()) return functor_(params, residuals);
    const int num_active = static_cast<int>(active.size());
    for (int first = 0; first < num_active; first += kStride) {
      const int last = std::min(num_active, first + kStride);
      for (int c = first; c < last; ++c)
        jets[offset[active[c].first] + active[c].second].v[c - first] = 1.0;
      Jet r[3];
      if (!functor_(blocks.data(), r)) return false;
      for (int k = 0; k < 3; ++k) residuals[k] = r[k].a;
      for (int c = first; c < last; ++c) {
        const int b = active[c].first, e = active[c].second;
        for (int k = 0; k < 3; ++k)
          jacobians[b][k * sizes[b] + e] = r[k].v[c - first];
        jets[offset[b] + e].v[c - first] = 0.0;
      }
    }
    return true;
  }

 private:
  const TipResidual functor_;
  Entries entries_;
};

// A known distance between two fixed points:
//   r = weight * (|point_a - point_b| - distance)
struct DistanceResidual {
  DistanceResidual(double distance_mm, double weight)
      : distance_mm_(distance_mm), weight_(weight) {}
  template <typename T>
  bool operator()(const T* point_a, const T* point_b, T* residual) const {
    using std::sqrt;
    const T dx = point_a[0] - point_b[0], dy = point_a[1] - point_b[1],
            dz = point_a[2] - point_b[2];
    residual[0] =
        T(weight_) * (sqrt(dx * dx + dy * dy + dz * dz) - distance_mm_);
    return true;
  }
  static ceres::CostFunction* Create(double distance_mm, double weight) {
    return new ceres::AutoDiffCostFunction<DistanceResidual, 1, 3, 3>(
        new DistanceResidual(distance_mm, weight));
  }

 private:
  const double distance_mm_;
  const double weight_;
};

// A soft pull of one entry of a parameter block towards a centre:
//   r = weight * (x[index] - center) / scale
class PriorResidual : public ceres::CostFunction {
 public:
  PriorResidual(int block_size, int index, double center, double scale,
                double weight)
      : index_(index), center_(center), factor_(weight / scale) {
    set_num_residuals(1);
    mutable_parameter_block_sizes()->push_back(block_size);
  }
  bool Evaluate(double const* const* params, double* residual,
                double** jacobians) const override {
    residual[0] = factor_ * (params[0][index_] - center_);
    if (jacobians != nullptr && jacobians[0] != nullptr) {
      for (int k = 0; k < parameter_block_sizes()[0]; ++k)
        jacobians[0][k] = k == index_ ? factor_ : 0.0;
    }
    return true;
  }

 private:
  int index_;
  double center_, factor_;
};

// The parameter block pointers of one measurement, in TipResidual's order.
std::vector<double*> BlocksOf(ModelState* s, const Measurement& m) {
  std::vector<double*> blocks;
  for (auto& row : s->chain.rows) blocks.push_back(row.p.data());
  for (auto& e : s->chain.joint_errors) blocks.push_back(e.data());
  blocks.push_back(s->chain.drift.data());
  blocks.push_back(m.kind == Measurement::kMeasured
                       ? s->FrameBlock(m.frame)
                       : s->points_in_base.at(m.point).data());
  return blocks;
}

bool IsAngle(const Chain& chain, const ParamInfo& p) {
  if (p.kind != ParamKind::kRow) return p.angle;
  if (chain.convention == Convention::kUrdf) return p.index >= 3;
  return p.index == 0 || p.index >= 3;
}

double Seconds(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
      .count();
}

}  // namespace

double RowBound(const Chain& center, const ParamInfo& p) {
  return IsAngle(center, p) ? center.bound_angle_rad : center.bound_length_mm;
}

double RowBound(const Chain& center, const ParamInfo& p,
                const FitOptions& options) {
  auto it = options.bound_override.find(p.name);
  return it != options.bound_override.end() ? it->second : RowBound(center, p);
}

std::vector<Measurement> MakeMeasurements(const Chain& nominal,
                                          const Observations& obs,
                                          ModelState* state) {
  const std::vector<PoseInput> inputs = MakePoseInputs(nominal, obs);
  std::vector<Measurement> out;
  for (size_t i = 0; i < obs.rows.size(); ++i) {
    const Observation& o = obs.rows[i];
    Measurement m;
    m.row = static_cast<int>(i);
    m.input = inputs[i];
    if (o.has_point) {
      m.kind = Measurement::kMeasured;
      m.p_in_meas = o.p_in_meas;
    } else if (!o.fixed_point.empty()) {
      m.kind = Measurement::kFixedPoint;
      m.point = state->PointIndex(o.fixed_point);
      if (m.point < 0) {
        state->point_labels.push_back(o.fixed_point);
        state->points_in_base.push_back({0.0, 0.0, 0.0});
        m.point = static_cast<int>(state->point_labels.size()) - 1;
      }
    } else {
      continue;
    }
    out.push_back(m);
  }
  return out;
}

int AssignSeriesFrames(const Observations& obs,
                       std::vector<Measurement>* measurements,
                       ModelState* state) {
  const std::vector<std::string> names = obs.SeriesNames();
  if (names.size() < 2) return 1;
  std::map<std::string, int> frame_of;
  for (size_t f = 0; f < names.size(); ++f)
    frame_of[names[f]] = static_cast<int>(f);
  for (Measurement& m : *measurements) {
    if (m.kind == Measurement::kMeasured)
      m.frame = frame_of.at(obs.rows.at(m.row).series);
  }
  state->frame_series = names;
  state->more_frames.resize(names.size() - 1, state->meas_from_base);
  return static_cast<int>(names.size());
}

Eigen::Vector3d Residual(const ModelState& state, const Measurement& m) {
  const Eigen::Vector3d tip = TipInBase(state.chain, m.input);
  if (m.kind == Measurement::kMeasured) {
    return ApplyFrame(state.FrameBlock(m.frame), Vec3<double>(tip)) -
           m.p_in_meas;
  }
  const auto& p = state.points_in_base.at(m.point);
  return tip - Eigen::Vector3d(p[0], p[1], p[2]);
}

namespace {

// The tip residual of every measurement (with the robust loss) and the
// known distances' residuals.
void AddResiduals(const std::vector<Measurement>& measurements,
                  const FitOptions& options, ModelState* state,
                  ceres::Problem* problem) {
  // The free entries of each block: the only columns the tip residuals
  // differentiate.
  std::map<const double*, std::vector<int>> free_entries;
  for (const ParamInfo& p : options.free) {
    free_entries[ParamAddress(state, p) - p.index].push_back(p.index);
  }
  for (const Measurement& m : measurements) {
    ceres::LossFunction* loss = nullptr;
    if (options.loss == "huber") {
      loss = new ceres::HuberLoss(options.loss_scale_mm);
    } else if (options.loss == "cauchy") {
      loss = new ceres::CauchyLoss(options.loss_scale_mm);
    } else {
      KINCAL_CHECK(options.loss == "none", "unknown loss " << options.loss);
    }
    const std::vector<double*> blocks = BlocksOf(state, m);
    TipCost::Entries entries(blocks.size());
    for (size_t b = 0; b < blocks.size(); ++b) {
      auto it = free_entries.find(blocks[b]);
      if (it != free_entries.end()) entries[b] = it->second;
    }
    problem->AddResidualBlock(new TipCost(state->chain, m, std::move(entries)),
                              loss, blocks);
  }
  for (const PointDistance& d : options.distances) {
    problem->AddResidualBlock(DistanceResidual::Create(d.distance_mm, d.weight),
                              nullptr, state->points_in_base.at(d.a).data(),
                              state->points_in_base.at(d.b).data());
  }
}

// Holds every entry that is not free (whole blocks constant, or a subset
// manifold); `params` gets the free parameters the data reach. Returns the
// free entries of each block.
std::map<double*, std::vector<bool>> HoldFrozenEntries(
    const FitOptions& options, ModelState* state, ceres::Problem* problem,
    std::vector<ParamInfo>* params) {
  std::map<double*, std::vector<bool>> free_mask;
  for (const ParamInfo& p : options.free) {
    double* address = ParamAddress(state, p);
    double* block = address - p.index;
    if (!problem->HasParameterBlock(block)) continue;  // not in this data
    auto& mask = free_mask[block];
    mask.resize(problem->ParameterBlockSize(block), false);
    mask[p.index] = true;
    params->push_back(p);
  }
  std::vector<double*> blocks;
  problem->GetParameterBlocks(&blocks);
  for (double* block : blocks) {
    auto it = free_mask.find(block);
    if (it == free_mask.end()) {
      problem->SetParameterBlockConstant(block);
      continue;
    }
    std::vector<int> constant;
    for (size_t k = 0; k < it->second.size(); ++k) {
      if (!it->second[k]) constant.push_back(static_cast<int>(k));
    }
    if (!constant.empty()) {
      problem->SetManifold(
          block, new ceres::SubsetManifold(static_cast<int>(it->second.size()),
                                           constant));
    }
  }
  return free_mask;
}

// With options.bounds_center: the free row entries boxed (and started
// inside the box) and, with a prior weight, pulled towards the centre.
void BoxAndPrior(const FitOptions& options,
                 const std::vector<ParamInfo>& params, ModelState* state,
                 ceres::Problem* problem) {
  if (options.bounds_center == nullptr) return;
  const Chain& c = *options.bounds_center;
  for (const ParamInfo& p : params) {
    if (p.kind != ParamKind::kRow) continue;
    double* address = ParamAddress(state, p);
    const double center = c.rows.at(p.block).p.at(p.index);
    const double bound = RowBound(c, p, options);
    problem->SetParameterLowerBound(address - p.index, p.index, center - bound);
    problem->SetParameterUpperBound(address - p.index, p.index, center + bound);
    // Start inside the box.
    *address = std::min(std::max(*address, center - bound), center + bound);
  }
  if (!(options.prior_weight > 0)) return;
  for (const ParamInfo& p : params) {
    if (p.kind != ParamKind::kRow) continue;
    double* block = ParamAddress(state, p) - p.index;
    problem->AddResidualBlock(
        new PriorResidual(problem->ParameterBlockSize(block), p.index,
                          c.rows.at(p.block).p.at(p.index),
                          RowBound(c, p, options), options.prior_weight),
        nullptr, block);
  }
}

// Levenberg-Marquardt (dense QR) to the options' tolerances.
void SolveProblem(const FitOptions& options, ceres::Problem* problem,
                  FitSummary* summary) {
  if (summary->params.empty()) {
    summary->converged = true;
    summary->termination = "nothing to fit";
    return;
  }
  ceres::Solver::Options solver;
  solver.linear_solver_type = ceres::DENSE_QR;
  solver.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
  solver.max_num_iterations = options.max_iterations;
  solver.function_tolerance = options.function_tolerance;
  solver.parameter_tolerance = options.parameter_tolerance;
  solver.gradient_tolerance = 1e-14;
  solver.num_threads = options.num_threads;
  solver.logging_type = ceres::SILENT;
  ceres::Solver::Summary ceres_summary;
  ceres::Solve(solver, problem, &ceres_summary);
  summary->converged = ceres_summary.IsSolutionUsable() &&
                       ceres_summary.termination_type == ceres::CONVERGENCE;
  summary->termination = ceres_summary.message;
  summary->iterations = static_cast<int>(ceres_summary.iterations.size());
}

// The free parameters' covariance sigma0^2 (J^T J)^+ (ceres::Covariance,
// dense SVD) and their 1-sigma in interface units; left empty (sigmas NaN)
// when it cannot be computed.
void ComputeCovariance(const std::map<double*, std::vector<bool>>& free_mask,
                       ModelState* state, ceres::Problem* problem,
                       FitSummary* summary) {
  const int num_params = static_cast<int>(summary->params.size());
  ceres::Covariance::Options cov_options;
  cov_options.algorithm_type = ceres::DENSE_SVD;
  cov_options.null_space_rank = -1;
  cov_options.min_reciprocal_condition_number = 1e-14;
  ceres::Covariance covariance(cov_options);
  std::vector<double*> free_blocks;
  for (const auto& kv : free_mask) free_blocks.push_back(kv.first);
  std::vector<std::pair<const double*, const double*>> pairs;
  for (size_t a = 0; a < free_blocks.size(); ++a) {
    for (size_t b = a; b < free_blocks.size(); ++b) {
      pairs.emplace_back(free_blocks[a], free_blocks[b]);
    }
  }
  if (!covariance.Compute(pairs, problem)) return;
  summary->covariance.setZero(num_params, num_params);
  const double scale = summary->sigma0_mm * summary->sigma0_mm;
  for (int i = 0; i < num_params; ++i) {
    const ParamInfo& pi = summary->params[i];
    double* bi = ParamAddress(state, pi) - pi.index;
    const int si = problem->ParameterBlockSize(bi);
    for (int j = 0; j < num_params; ++j) {
      const ParamInfo& pj = summary->params[j];
      double* bj = ParamAddress(state, pj) - pj.index;
      const int sj = problem->ParameterBlockSize(bj);
      std::vector<double> block(si * sj);
      const bool ok = covariance.GetCovarianceBlock(bi, bj, block.data());
      if (ok) {
        summary->covariance(i, j) = scale * block[pi.index * sj + pj.index];
      }
    }
  }
  for (int i = 0; i < num_params; ++i) {
    const double var = summary->covariance(i, i);
    const double sigma_internal = var >= 0 ? std::sqrt(var) : NAN;
    summary->sigmas[i] = summary->params[i].angle
                             ? summary->params[i].ToInterface(sigma_internal)
                             : sigma_internal;
  }
}

}  // namespace

FitSummary Fit(const std::vector<Measurement>& measurements,
               const FitOptions& options, ModelState* state) {
  const auto start = std::chrono::steady_clock::now();
  KINCAL_CHECK(!measurements.empty(), "no measurements to fit");
  FitSummary summary;
  ceres::Problem problem;
  AddResiduals(measurements, options, state, &problem);
  const std::map<double*, std::vector<bool>> free_mask =
      HoldFrozenEntries(options, state, &problem, &summary.params);
  BoxAndPrior(options, summary.params, state, &problem);

  auto rms = [&]() {
    double sum = 0.0;
    summary.residual_mm.clear();
    for (const Measurement& m : measurements) {
      const double e = Residual(*state, m).norm();
      summary.residual_mm.push_back(e);
      sum += e * e;
    }
    return std::sqrt(sum / measurements.size());
  };
  summary.initial_rms_mm = rms();
  SolveProblem(options, &problem, &summary);
  summary.final_rms_mm = rms();

  const int num_params = static_cast<int>(summary.params.size());
  const int dof = 3 * static_cast<int>(measurements.size()) - num_params;
  double sum_sq = 0.0;
  for (double e : summary.residual_mm) sum_sq += e * e;
  summary.sigma0_mm = dof > 0 ? std::sqrt(sum_sq / dof) : 0.0;

  summary.values.resize(num_params);
  summary.sigmas.assign(num_params, std::numeric_limits<double>::quiet_NaN());
  for (int i = 0; i < num_params; ++i) {
    summary.values[i] =
        summary.params[i].ToInterface(ParamValue(*state, summary.params[i]));
  }
  if (options.compute_covariance && num_params > 0 && dof > 0)
    ComputeCovariance(free_mask, state, &problem, &summary);
  summary.seconds = Seconds(start);
  return summary;
}

Eigen::MatrixXd ResidualJacobian(const std::vector<Measurement>& measurements,
                                 const ModelState& state,
                                 const std::vector<ParamInfo>& params,
                                 const std::vector<PointDistance>& distances) {
  ModelState s = state;  // BlocksOf needs mutable pointers; values unchanged
  Eigen::MatrixXd jac = Eigen::MatrixXd::Zero(
      3 * measurements.size() + distances.size(), params.size());
  for (size_t i = 0; i < measurements.size(); ++i) {
    const Measurement& m = measurements[i];
    const std::vector<double*> blocks = BlocksOf(&s, m);
    TipCost::Entries entries(blocks.size());
    for (const ParamInfo& p : params) {
      const double* address = ParamAddress(&s, p);
      for (size_t b = 0; b < blocks.size(); ++b) {
        if (address == blocks[b] + p.index) entries[b].push_back(p.index);
      }
    }
    std::unique_ptr<ceres::CostFunction> cost(
        new TipCost(s.chain, m, std::move(entries)));
    const auto& sizes = cost->parameter_block_sizes();
    std::vector<std::vector<double>> jac_blocks(blocks.size());
    std::vector<double*> jac_ptrs(blocks.size());
    for (size_t b = 0; b < blocks.size(); ++b) {
      jac_blocks[b].assign(3 * sizes[b], 0.0);
      jac_ptrs[b] = jac_blocks[b].data();
    }
    double residual[3];
    cost->Evaluate(blocks.data(), residual, jac_ptrs.data());
    for (size_t c = 0; c < params.size(); ++c) {
      const double* address = ParamAddress(&s, params[c]);
      for (size_t b = 0; b < blocks.size(); ++b) {
        if (address >= blocks[b] && address < blocks[b] + sizes[b]) {
          const int k = static_cast<int>(address - blocks[b]);
          for (int r = 0; r < 3; ++r) {
            jac(3 * i + r, c) = jac_blocks[b][r * sizes[b] + k];
          }
        }
      }
    }
  }
  for (size_t i = 0; i < distances.size(); ++i) {
    const PointDistance& d = distances[i];
    std::unique_ptr<ceres::CostFunction> cost(
        DistanceResidual::Create(d.distance_mm, d.weight));
    double* blocks[2] = {s.points_in_base.at(d.a).data(),
                         s.points_in_base.at(d.b).data()};
    double ja[3], jb[3], residual;
    double* jac_ptrs[2] = {ja, jb};
    cost->Evaluate(blocks, &residual, jac_ptrs);
    const int row = static_cast<int>(3 * measurements.size() + i);
    for (size_t c = 0; c < params.size(); ++c) {
      if (params[c].kind != ParamKind::kPoint) continue;
      if (params[c].block == d.a) jac(row, c) += ja[params[c].index];
      if (params[c].block == d.b) jac(row, c) += jb[params[c].index];
    }
  }
  return jac;
}

namespace {

// The rigid meas_from_base (Umeyama, no scale) carrying `src` (model tips)
// onto `dst` (measured points); InputError when fewer than 3 or collinear.
std::array<double, kFrameBlockSize> RegisterRigid(
    const std::vector<Eigen::Vector3d>& src,
    const std::vector<Eigen::Vector3d>& dst, const std::string& series) {
  Eigen::Matrix3Xd a(3, src.size()), b(3, dst.size());
  for (size_t i = 0; i < src.size(); ++i) {
    a.col(i) = src[i];
    b.col(i) = dst[i];
  }
  const Eigen::Matrix3Xd centered = a.colwise() - a.rowwise().mean();
  const Eigen::JacobiSVD<Eigen::Matrix3Xd> svd(centered);
  if (src.size() < 3 ||
      svd.singularValues()(1) < 1e-6 * svd.singularValues()(0)) {
    throw InputError(
        "the measured tip points" +
        (series.empty() ? std::string() : " of series '" + series + "'") +
        " are fewer than 3 or all on one line: the base-to-measuring-frame "
        "transform cannot be determined");
  }
  const Eigen::Matrix4d meas_from_base = Eigen::umeyama(a, b, false);
  return PoseBlockFromRigid3(Rigid3::FromMatrix(meas_from_base));
}

}  // namespace

void InitializeFrameAndPoints(const std::vector<Measurement>& measurements,
                              ModelState* state) {
  // Fixed points: centroid of the model's tips of each group.
  std::vector<Eigen::Vector3d> sums(state->points_in_base.size(),
                                    Eigen::Vector3d::Zero());
  std::vector<int> counts(state->points_in_base.size(), 0);
  // Measured rows per frame: model tips and measured points.
  std::map<int, std::pair<std::vector<Eigen::Vector3d>,
                          std::vector<Eigen::Vector3d>>>
      frames;
  for (const Measurement& m : measurements) {
    const Eigen::Vector3d tip = TipInBase(state->chain, m.input);
    if (m.kind == Measurement::kFixedPoint) {
      sums[m.point] += tip;
      counts[m.point] += 1;
    } else {
      frames[m.frame].first.push_back(tip);
      frames[m.frame].second.push_back(m.p_in_meas);
    }
  }
  for (size_t i = 0; i < sums.size(); ++i) {
    if (counts[i] > 0) {
      const Eigen::Vector3d c = sums[i] / counts[i];
      state->points_in_base[i] = {c.x(), c.y(), c.z()};
    }
  }
  if (frames.empty()) return;
  const int num_frames = frames.rbegin()->first + 1;
  if (state->NumFrames() < num_frames)
    state->more_frames.resize(num_frames - 1, state->meas_from_base);
  for (const auto& [frame, points] : frames) {
    const std::string series =
        frame < static_cast<int>(state->frame_series.size())
            ? state->frame_series[frame]
            : std::string();
    const std::array<double, kFrameBlockSize> block =
        RegisterRigid(points.first, points.second, series);
    std::copy(block.begin(), block.end(), state->FrameBlock(frame));
  }
}

int DistinctPoses(const std::vector<Measurement>& measurements) {
  std::set<std::vector<double>> seen;
  for (const Measurement& m : measurements) seen.insert(m.input.q);
  return static_cast<int>(seen.size());
}

ErrorStats ComputeErrorStats(const std::vector<double>& e) {
  ErrorStats s;
  s.n = static_cast<int>(e.size());
  if (e.empty()) return s;
  double sum = 0, sum_sq = 0;
  for (double v : e) {
    sum += v;
    sum_sq += v * v;
    s.max_mm = std::max(s.max_mm, v);
  }
  s.mean_mm = sum / s.n;
  s.rms_mm = std::sqrt(sum_sq / s.n);
  double var = 0;
  for (double v : e) var += (v - s.mean_mm) * (v - s.mean_mm);
  s.std_mm = std::sqrt(var / s.n);
  return s;
}

}  // namespace kincal
