#include "plan/plan.h"

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <sstream>

#include "calib/chain.h"
#include "calib/fit.h"
#include "calib/identifiability.h"
#include "data/error.h"
#include "data/provenance.h"
#include "data/rigid3.h"

namespace kincal {
namespace {

using Poses = std::vector<std::vector<double>>;

std::vector<double> InternalJoints(const Chain& chain,
                                   const std::vector<double>& q);

Eigen::Matrix4d BaseFromTip(const Chain& chain, const std::vector<double>& q) {
  return BaseFromTipAt(chain, InternalJoints(chain, q));
}

std::vector<double> InternalJoints(const Chain& chain,
                                   const std::vector<double>& q) {
  std::vector<double> qi(q.size());
  for (size_t j = 0; j < q.size(); ++j) {
    qi[j] = chain.ReadingToInternal(static_cast<int>(j), q[j]);
  }
  return qi;
}

// The robot with every joint's limits moved inwards by `margin` of its range.
Robot WithLimitMargin(const Robot& robot, double margin) {
  Robot inner = robot;
  for (RobotRow& row : inner.joints) {
    const double keep = margin * (row.upper - row.lower);
    row.lower += keep;
    row.upper -= keep;
  }
  return inner;
}

PoseInput MakeInput(const Chain& chain, const std::vector<double>& q) {
  PoseInput in;
  const size_t n = q.size();
  in.q.resize(n);
  for (size_t j = 0; j < n; ++j) {
    in.q[j] = chain.ReadingToInternal(static_cast<int>(j), q[j]);
  }
  in.s.assign(n, 0.0);
  in.tau.assign(n, 0.0);
  return in;
}

class Sampler {
 public:
  Sampler(const Robot& robot, uint64_t seed, double extreme = 0)
      : robot_(robot), rng_(seed), extreme_(extreme) {}
  // Uniform within the limits; with probability `extreme` per joint, at a
  // limit instead (lower or upper, equally likely).
  std::vector<double> Draw() {
    std::vector<double> q(robot_.joints.size());
    std::uniform_real_distribution<double> unit(0, 1);
    for (size_t j = 0; j < q.size(); ++j) {
      const RobotRow& row = robot_.joints[j];
      const double r = unit(rng_);
      if (r < extreme_) {
        q[j] = r < 0.5 * extreme_ ? row.lower : row.upper;
      } else {
        q[j] = row.lower + unit(rng_) * (row.upper - row.lower);
      }
    }
    return q;
  }
  std::mt19937_64& rng() { return rng_; }

 private:
  const Robot& robot_;
  std::mt19937_64 rng_;
  double extreme_ = 0;
};

bool WithinLimits(const Robot& robot, const std::vector<double>& q) {
  for (size_t j = 0; j < q.size(); ++j) {
    if (!(q[j] >= robot.joints[j].lower && q[j] <= robot.joints[j].upper)) {
      return false;
    }
  }
  return true;
}

// Position-only inverse kinematics in reading units: damped Gauss-Newton
// with a numeric Jacobian from `q`. True when within 1e-6 mm (limits are
// the caller's check).
bool SolveTipAt(const Chain& chain, const Eigen::Vector3d& target,
                std::vector<double>* q) {
  const int n = static_cast<int>(q->size());
  for (int it = 0; it < 60; ++it) {
    const Eigen::Vector3d p = BaseFromTip(chain, *q).block<3, 1>(0, 3);
    const Eigen::Vector3d e = target - p;
    if (e.norm() < 1e-6) return true;
    Eigen::MatrixXd jac(3, n);
    for (int j = 0; j < n; ++j) {
      std::vector<double> qq = *q;
      const double h = 1e-6;
      qq[j] += h;
      jac.col(j) = (BaseFromTip(chain, qq).block<3, 1>(0, 3) - p) / h;
    }
    const Eigen::Matrix3d a =
        jac * jac.transpose() + 1e-6 * Eigen::Matrix3d::Identity();
    const Eigen::VectorXd dq = jac.transpose() * a.ldlt().solve(e);
    double scale = 1.0;  // at most 20 reading units per step
    const double big = dq.cwiseAbs().maxCoeff();
    if (big > 20) scale = 20 / big;
    for (int j = 0; j < n; ++j) (*q)[j] += scale * dq[j];
  }
  return false;
}

double LogDet3(const Eigen::Matrix3d& m) {
  const double d = m.determinant();
  return d > 0 ? std::log(d) : -std::numeric_limits<double>::infinity();
}

// Fedorov exchange on blocks of 3 rows of `a` (scaled Jacobian, 3 rows per
// candidate). The greedy start maximises log det; the exchange then
// maximises log det (`marginal` empty) or minimises the sum of the log
// marginal variances of the columns in `marginal` (the log of the product of
// their sigmas), using the Woodbury update of the covariance per candidate.
// Returns the chosen candidate indices.
std::vector<int> ExchangeDesign(const Eigen::MatrixXd& a, int n,
                                const std::vector<int>& marginal,
                                int max_passes, int* swaps) {
  const int p = static_cast<int>(a.cols());
  const int c = static_cast<int>(a.rows() / 3);
  const double lambda = 1e-9 * a.squaredNorm() / std::max(1, c);
  Eigen::MatrixXd m = lambda * Eigen::MatrixXd::Identity(p, p);
  std::vector<char> in_design(c, 0);
  std::vector<int> design;
  // Score of adding each candidate to information `mm` (larger = better).
  auto scores = [&](const Eigen::MatrixXd& mm, bool d_optimal) {
    const Eigen::MatrixXd minv =
        mm.llt().solve(Eigen::MatrixXd::Identity(p, p));
    const Eigen::MatrixXd pa = a * minv;
    std::vector<double> g(c);
    for (int k = 0; k < c; ++k) {
      const auto b = pa.middleRows(3 * k, 3);
      const Eigen::Matrix3d s =
          Eigen::Matrix3d::Identity() + b * a.middleRows(3 * k, 3).transpose();
      if (d_optimal) {
        g[k] = LogDet3(s);
        continue;
      }
      const Eigen::Matrix3d sinv = s.inverse();
      double f = 0;
      for (int col : marginal) {
        const Eigen::Vector3d v = b.col(col);
        f += std::log(std::max(minv(col, col) - v.dot(sinv * v), 1e-300));
      }
      g[k] = -f;
    }
    return g;
  };
  for (int k = 0; k < n; ++k) {
    const std::vector<double> g = scores(m, true);
    int best = -1;
    for (int i = 0; i < c; ++i) {
      if (!in_design[i] && (best < 0 || g[i] > g[best])) best = i;
    }
    design.push_back(best);
    in_design[best] = 1;
    m += a.middleRows(3 * best, 3).transpose() * a.middleRows(3 * best, 3);
  }
  *swaps = 0;
  for (int pass = 0; pass < max_passes; ++pass) {
    bool improved = false;
    for (int slot = 0; slot < n; ++slot) {
      const int old = design[slot];
      const Eigen::MatrixXd reduced =
          m - a.middleRows(3 * old, 3).transpose() * a.middleRows(3 * old, 3);
      const std::vector<double> g = scores(reduced, marginal.empty());
      int best = old;
      for (int i = 0; i < c; ++i) {
        if (!in_design[i] && g[i] > g[best] + 1e-9) best = i;
      }
      if (best != old) {
        in_design[old] = 0;
        in_design[best] = 1;
        design[slot] = best;
        m = reduced +
            a.middleRows(3 * best, 3).transpose() * a.middleRows(3 * best, 3);
        improved = true;
        ++*swaps;
      }
    }
    if (!improved) break;
  }
  return design;
}

double ParamScale(const Chain& chain, const ParamInfo& p) {
  return p.angle ? chain.bound_angle_rad : chain.bound_length_mm;
}

bool IsRobotParam(const ParamInfo& p) {
  return p.kind != ParamKind::kFrame && p.kind != ParamKind::kPoint;
}

// The rig looks, from a working distance where the largest tag is about 70
// px wide, along the mean direction the tags face, at the densest cluster of
// tag-facing tool positions.
Rigid3 PlaceRigAuto(const Robot& robot, const Chain& chain, const Rig& rig,
                    const Target& target, const Rigid3& tip_from_tool,
                    uint64_t seed) {
  Sampler sampler(robot, seed);
  Eigen::Vector3d tags_in_tool = Eigen::Vector3d::Zero();
  double size = 0;
  for (const TargetTag& t : target.tags) {
    tags_in_tool += t.tool_from_tag.t;
    size = std::max(size, t.size_mm);
  }
  tags_in_tool /= std::max<size_t>(1, target.tags.size());
  std::vector<Eigen::Vector3d> centres, normals;
  Eigen::Vector3d mean_z = Eigen::Vector3d::Zero();
  for (int i = 0; i < 1000; ++i) {
    const Rigid3 base_from_tool =
        Rigid3::FromMatrix(BaseFromTip(chain, sampler.Draw())) * tip_from_tool;
    centres.push_back(base_from_tool * tags_in_tool);
    normals.push_back(base_from_tool.R.col(2));
    mean_z += normals.back();
  }
  Eigen::Vector3d z =
      mean_z.norm() > 300 ? mean_z.normalized() : Eigen::Vector3d(0, 0, -1);
  const CameraIntrinsics& cam = rig.cameras.at(0).intrinsics;
  const double distance = std::max(300.0, cam.fx * size / 70.0);
  const double radius =
      0.3 * distance * std::min(cam.width / cam.fx, cam.height / cam.fy);
  std::vector<int> facing;
  for (size_t i = 0; i < centres.size(); ++i) {
    if (normals[i].dot(z) > std::cos(M_PI / 4)) facing.push_back(i);
  }
  Eigen::Vector3d look_at = Eigen::Vector3d::Zero();
  int best_count = -1;
  for (int i : facing) {
    int count = 0;
    for (int k : facing) count += (centres[k] - centres[i]).norm() < radius;
    if (count > best_count) {
      best_count = count;
      look_at = centres[i];
    }
  }
  const Eigen::Vector3d e = std::abs(z.z()) < 0.9 ? Eigen::Vector3d::UnitZ()
                                                  : Eigen::Vector3d::UnitX();
  const Eigen::Vector3d x = z.cross(e).normalized();
  const Eigen::Vector3d y = z.cross(x);
  Rigid3 rig_from_base;
  rig_from_base.R.row(0) = x.transpose();
  rig_from_base.R.row(1) = y.transpose();
  rig_from_base.R.row(2) = z.transpose();
  rig_from_base.t = -(rig_from_base.R * (look_at - distance * z));
  return rig_from_base;
}

std::vector<Measurement> MakeDesignMeasurements(const Chain& chain,
                                                const Poses& poses,
                                                bool fixed_point) {
  std::vector<Measurement> ms;
  for (size_t i = 0; i < poses.size(); ++i) {
    Measurement m;
    m.row = static_cast<int>(i);
    m.kind = fixed_point ? Measurement::kFixedPoint : Measurement::kMeasured;
    m.point = fixed_point ? 0 : -1;
    m.input = MakeInput(chain, poses[i]);
    ms.push_back(m);
  }
  return ms;
}

struct Problem {
  Chain chain;
  ModelState state;
  bool fixed_point = false;
};

}  // namespace

int VisibleTags(const Rig& rig, const Target& target,
                const Rigid3& rig_from_tool, const PlanOptions& options) {
  const double cos_max = std::cos(options.max_obliquity_deg * M_PI / 180);
  int visible = 0;
  for (const TargetTag& tag : target.tags) {
    bool all = true;
    for (const Camera& camera : rig.cameras) {
      const Rigid3 cam_from_tag =
          camera.cam_from_rig * rig_from_tool * tag.tool_from_tag;
      const CameraIntrinsics& in = camera.intrinsics;
      // Tag z points into the tag, away from a viewer that sees its face.
      const Eigen::Vector3d ray = cam_from_tag.t.normalized();
      if (cam_from_tag.R.col(2).dot(ray) < cos_max) {
        all = false;
        break;
      }
      std::array<Eigen::Vector2d, 4> px;
      for (int k = 0; k < 4 && all; ++k) {
        const Eigen::Vector3d p =
            camera.cam_from_rig * (rig_from_tool * tag.CornerInTool(k));
        if (p.z() <= 1.0) {
          all = false;
          break;
        }
        px[k] = Project(in, p);
        if (!(px[k].x() >= options.margin_px &&
              px[k].y() >= options.margin_px &&
              px[k].x() <= in.width - 1 - options.margin_px &&
              px[k].y() <= in.height - 1 - options.margin_px)) {
          all = false;
        }
      }
      if (!all) break;
      for (int k = 0; k < 4; ++k) {
        if ((px[k] - px[(k + 1) % 4]).norm() < options.min_tag_px) {
          all = false;
          break;
        }
      }
      if (!all) break;
    }
    visible += all;
  }
  return visible;
}

double JointTravel(const Robot& robot, const Poses& poses) {
  double total = 0;
  for (size_t i = 1; i < poses.size(); ++i) {
    double step = 0;
    for (size_t j = 0; j < robot.joints.size(); ++j) {
      const double range = robot.joints[j].upper - robot.joints[j].lower;
      step = std::max(step, std::abs(poses[i][j] - poses[i - 1][j]) / range);
    }
    total += step;
  }
  return total;
}

Poses OrderPoses(const Robot& robot, Poses poses) {
  const int n = static_cast<int>(poses.size());
  if (n < 3) return poses;
  auto dist = [&](int a, int b) {
    double step = 0;
    for (size_t j = 0; j < robot.joints.size(); ++j) {
      const double range = robot.joints[j].upper - robot.joints[j].lower;
      step = std::max(step, std::abs(poses[a][j] - poses[b][j]) / range);
    }
    return step;
  };
  // Start nearest to the middle of the ranges.
  int start = 0;
  double best = std::numeric_limits<double>::infinity();
  for (int i = 0; i < n; ++i) {
    double d = 0;
    for (size_t j = 0; j < robot.joints.size(); ++j) {
      const double mid = 0.5 * (robot.joints[j].upper + robot.joints[j].lower);
      const double range = robot.joints[j].upper - robot.joints[j].lower;
      d = std::max(d, std::abs(poses[i][j] - mid) / range);
    }
    if (d < best) {
      best = d;
      start = i;
    }
  }
  std::vector<int> order{start};
  std::vector<char> used(n, 0);
  used[start] = 1;
  for (int k = 1; k < n; ++k) {
    int next = -1;
    for (int i = 0; i < n; ++i) {
      if (!used[i] &&
          (next < 0 || dist(order.back(), i) < dist(order.back(), next))) {
        next = i;
      }
    }
    used[next] = 1;
    order.push_back(next);
  }
  // 2-opt on the open path (the first pose stays first).
  for (bool improved = true; improved;) {
    improved = false;
    for (int i = 1; i < n - 1; ++i) {
      for (int k = i + 1; k < n; ++k) {
        const double before = dist(order[i - 1], order[i]) +
                              (k + 1 < n ? dist(order[k], order[k + 1]) : 0.0);
        const double after = dist(order[i - 1], order[k]) +
                             (k + 1 < n ? dist(order[i], order[k + 1]) : 0.0);
        if (after < before - 1e-12) {
          std::reverse(order.begin() + i, order.begin() + k + 1);
          improved = true;
        }
      }
    }
  }
  Poses out;
  for (int i : order) out.push_back(poses[i]);
  return out;
}

namespace {

Problem MakeProblem(const Robot& robot, const PlanResult& plan,
                    const PlanOptions& options) {
  Problem pr;
  pr.chain = Chain::FromRobot(robot);
  pr.state.chain = pr.chain;
  pr.fixed_point = options.fixed_point;
  pr.state.meas_from_base = PoseBlockFromRigid3(plan.rig_from_base);
  if (options.fixed_point) {
    pr.state.point_labels = {"P"};
    const Eigen::Vector3d& p = plan.fixed_point_in_base;
    pr.state.points_in_base = {{p.x(), p.y(), p.z()}};
  }
  return pr;
}

}  // namespace

DesignQuality PredictQuality(const Robot& robot, const PlanResult& plan,
                             const Poses& poses, const PlanOptions& options) {
  const Problem pr = MakeProblem(robot, plan, options);
  const std::vector<Measurement> ms =
      MakeDesignMeasurements(pr.chain, poses, pr.fixed_point);
  const Eigen::MatrixXd j = ResidualJacobian(ms, pr.state, plan.params);
  const int p = static_cast<int>(plan.params.size());
  DesignQuality q;
  Eigen::VectorXd scale(p);
  for (int k = 0; k < p; ++k) scale[k] = ParamScale(pr.chain, plan.params[k]);
  const Eigen::MatrixXd info = j.transpose() * j;
  const Eigen::MatrixXd scaled = scale.asDiagonal() * info * scale.asDiagonal();
  Eigen::LDLT<Eigen::MatrixXd> ldlt(scaled);
  const Eigen::VectorXd d = ldlt.vectorD();
  const bool ok = ldlt.info() == Eigen::Success &&
                  d.minCoeff() > 1e-12 * std::max(1.0, d.maxCoeff());
  q.log_det =
      ok ? d.array().log().sum() : -std::numeric_limits<double>::infinity();
  q.joint_travel = JointTravel(robot, poses);
  {
    Eigen::MatrixXd js = j;
    for (int k = 0; k < p; ++k) js.col(k) *= scale[k];
    const Eigen::VectorXd sv =
        Eigen::JacobiSVD<Eigen::MatrixXd>(js).singularValues();
    if (sv.size() > 0 && sv[0] > 0) {
      const double smin = sv[sv.size() - 1];
      q.o1 = std::exp(sv.array().max(1e-300).log().mean()) /
             std::sqrt(static_cast<double>(poses.size()));
      q.o3 = smin / sv[0];
      q.o4 = smin * smin / sv[0];
    }
  }
  const double inf = std::numeric_limits<double>::infinity();
  if (!ok) {
    q.sigma.assign(p, inf);
    q.tip_rms_mm = inf;
    return q;
  }
  const Eigen::MatrixXd cov_scaled =
      ldlt.solve(Eigen::MatrixXd::Identity(p, p)) * options.noise_mm *
      options.noise_mm;
  const Eigen::MatrixXd cov =
      scale.asDiagonal() * cov_scaled * scale.asDiagonal();
  for (int k = 0; k < p; ++k) {
    q.sigma.push_back(plan.params[k].ToInterface(std::sqrt(cov(k, k))));
  }
  // Tip error on the evaluation poses: in the measuring frame (frame
  // uncertainty included), or in the base frame for fixed-point designs.
  std::vector<int> cols;
  std::vector<ParamInfo> eval_params;
  for (int k = 0; k < p; ++k) {
    if (!pr.fixed_point || IsRobotParam(plan.params[k])) {
      cols.push_back(k);
      eval_params.push_back(plan.params[k]);
    }
  }
  Eigen::MatrixXd sub(cols.size(), cols.size());
  for (size_t a = 0; a < cols.size(); ++a) {
    for (size_t b = 0; b < cols.size(); ++b) sub(a, b) = cov(cols[a], cols[b]);
  }
  ModelState eval_state = pr.state;
  const std::vector<Measurement> ems =
      MakeDesignMeasurements(pr.chain, plan.evaluation_poses, false);
  const Eigen::MatrixXd je = ResidualJacobian(ems, eval_state, eval_params);
  const double total = (je * sub * je.transpose()).trace();
  q.tip_rms_mm = std::sqrt(total / std::max<size_t>(1, ems.size()));
  return q;
}

namespace {

// InputError for inputs plan cannot work with: joints without limits or
// with empty ranges, too few poses or candidates, a rig without a target.
void CheckPlanInputs(const Robot& robot, const PlanOptions& options) {
  for (const RobotRow& row : robot.joints) {
    if (!row.HasLimits()) {
      throw InputError("robot '" + robot.name + "': joint '" + row.name +
                       "' has no limits; plan needs `limits: [lo, hi]` on "
                       "every joint");
    }
    if (!(row.upper > row.lower)) {
      throw InputError("robot '" + robot.name + "': joint '" + row.name +
                       "' has an empty range of limits");
    }
  }
  if (options.n < 2) throw InputError("--n: expected at least 2 poses");
  if ((options.rig == nullptr) != (options.target == nullptr)) {
    throw InputError("--rig and --target go together");
  }
  if (options.candidates < options.n) {
    throw InputError("--candidates must be at least --n");
  }
  if (!(options.limit_margin >= 0 && options.limit_margin <= 0.45)) {
    throw InputError(
        "--limit-margin: expected a fraction of the range in "
        "[0, 0.45]");
  }
  if (!(options.safety.link_radius_mm >= 0 &&
        options.safety.link_radius_mm <= 1000)) {
    throw InputError("--link-radius: expected 0 to 1000 mm");
  }
}

// The fixed point: the tip of a feasible pose whose tip is nearest the
// median of 200 feasible tips. Adds the draws it made to `*draws`.
template <typename Feasible>
Eigen::Vector3d ChooseFixedPoint(const Chain& chain, const PlanOptions& options,
                                 Sampler* sampler, const Feasible& feasible,
                                 long* draws) {
  Poses first;
  while (static_cast<int>(first.size()) < 200 && *draws < options.max_draws) {
    ++*draws;
    std::vector<double> q = sampler->Draw();
    if (feasible(q)) first.push_back(q);
  }
  if (first.size() < 20) {
    throw InputError("no feasible poses found in " + std::to_string(*draws) +
                     " random draws: are the tags visible from the rig, is "
                     "there room between the obstacles?");
  }
  std::vector<double> xs[3];
  std::vector<Eigen::Vector3d> tips;
  for (const auto& q : first) {
    tips.push_back(BaseFromTip(chain, q).block<3, 1>(0, 3));
    for (int k = 0; k < 3; ++k) xs[k].push_back(tips.back()[k]);
  }
  Eigen::Vector3d median;
  for (int k = 0; k < 3; ++k) {
    std::nth_element(xs[k].begin(), xs[k].begin() + xs[k].size() / 2,
                     xs[k].end());
    median[k] = xs[k][xs[k].size() / 2];
  }
  size_t best = 0;
  for (size_t i = 0; i < tips.size(); ++i) {
    if ((tips[i] - median).norm() < (tips[best] - median).norm()) best = i;
  }
  return tips[best];
}

// Geometric mean over the robot parameters of sigma / the robot's bound.
double RobotSigmaGeometricMean(const Robot& robot,
                               const std::vector<ParamInfo>& params,
                               const std::vector<double>& sigma) {
  double sum = 0;
  int count = 0;
  for (size_t k = 0; k < params.size(); ++k) {
    if (!IsRobotParam(params[k])) continue;
    const double bound =
        params[k].angle ? robot.bound_angle_deg : robot.bound_length_mm;
    sum += std::log(sigma[k] / bound);
    ++count;
  }
  return std::exp(sum / std::max(1, count));
}

// Draws after which a plan with no feasible pose at all stops looking.
constexpr long kHopelessDraws = 20000;

// "rejected 12 at the limits' margin, 30 for collisions (plane 'table' 25,
// self-collision 5), 0 with no tags visible".
std::string DescribeRejections(const PlanResult& plan) {
  std::string out = "rejected " + std::to_string(plan.rejected_limits) +
                    " outside the limits minus the margin, " +
                    std::to_string(plan.rejected_collision) + " for collisions";
  if (!plan.collisions.empty()) {
    std::string what;
    for (const auto& [name, count] : plan.collisions) {
      what += (what.empty() ? "" : ", ") + name + " " + std::to_string(count);
    }
    out += " (" + what + ")";
  }
  return out + ", " + std::to_string(plan.rejected_visibility) +
         " with too few tags visible";
}

// The design's candidates (indices): the travel coverage for kCoverage,
// else the D-optimal / sigma exchange on the bound-scaled Jacobian of the
// plan's identifiable parameters (plan->swaps counts its exchanges).
std::vector<int> ChooseDesign(const Robot& inner, const Problem& pr,
                              const std::vector<Measurement>& ms,
                              const Poses& candidates,
                              const PlanOptions& options, PlanResult* plan) {
  if (options.criterion == PlanOptions::kCoverage)
    return CoverageDesign(inner, candidates, options.n);
  const int p = static_cast<int>(plan->params.size());
  Eigen::MatrixXd jac = ResidualJacobian(ms, pr.state, plan->params);
  for (int k = 0; k < p; ++k) {
    jac.col(k) *= ParamScale(pr.chain, plan->params[k]);
  }
  std::vector<int> marginal;
  if (options.criterion == PlanOptions::kSigma) {
    for (int k = 0; k < p; ++k) {
      if (IsRobotParam(plan->params[k])) marginal.push_back(k);
    }
  }
  return ExchangeDesign(jac, options.n, marginal, options.max_swap_passes,
                        &plan->swaps);
}

}  // namespace

PlanResult PlanPoses(const Robot& robot, const PlanOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  CheckPlanInputs(robot, options);
  PlanResult plan;
  const Chain chain = Chain::FromRobot(robot);
  Rigid3 tip_from_tool;
  if (options.rig != nullptr) {
    tip_from_tool = TipFromTool(*options.target);
    plan.rig_from_base =
        options.rig_from_base
            ? *options.rig_from_base
            : PlaceRigAuto(robot, chain, *options.rig, *options.target,
                           tip_from_tool, options.seed + 7);
  }
  auto visible = [&](const std::vector<double>& q) {
    if (options.rig == nullptr) return true;
    const Rigid3 rig_from_tool = plan.rig_from_base *
                                 Rigid3::FromMatrix(BaseFromTip(chain, q)) *
                                 tip_from_tool;
    return VisibleTags(*options.rig, *options.target, rig_from_tool, options) >=
           options.min_tags;
  };

  // Inside the limits minus the margin, clear of obstacles and of itself,
  // tags visible; each rejection counted by its constraint.
  const Robot inner = WithLimitMargin(robot, options.limit_margin);
  auto feasible = [&](const std::vector<double>& q) {
    if (!WithinLimits(inner, q)) {
      ++plan.rejected_limits;
      return false;
    }
    const Contact contact =
        FindContact(chain, InternalJoints(chain, q), options.safety);
    if (contact.kind != Contact::kNone) {
      ++plan.rejected_collision;
      ++plan.collisions[contact.Describe(options.safety)];
      return false;
    }
    if (!visible(q)) {
      ++plan.rejected_visibility;
      return false;
    }
    return true;
  };

  Sampler sampler(inner, options.seed);
  if (options.fixed_point) {
    plan.fixed_point_in_base =
        ChooseFixedPoint(chain, options, &sampler, feasible, &plan.draws);
  }
  // Feasible poses from `s`: random draws (fixed point: random starts of the
  // inverse kinematics).
  auto collect = [&](Sampler* s, int count) {
    Poses out;
    long tries = 0;
    const long max_tries = options.fixed_point
                               ? std::min<long>(options.max_draws, 50L * count)
                               : options.max_draws;
    while (static_cast<int>(out.size()) < count && tries < max_tries) {
      ++tries;
      std::vector<double> q = s->Draw();
      if (options.fixed_point &&
          !SolveTipAt(chain, plan.fixed_point_in_base, &q)) {
        continue;
      }
      if (feasible(q)) out.push_back(q);
      if (out.empty() && tries >= kHopelessDraws) break;
    }
    plan.draws += tries;
    if (static_cast<int>(out.size()) < count) {
      throw InputError("found only " + std::to_string(out.size()) +
                       " feasible poses (need " + std::to_string(count) +
                       ") in " + std::to_string(tries) + " random draws; " +
                       DescribeRejections(plan) +
                       ": widen the joint limits or --limit-margin, move the "
                       "obstacles, check that the tags can face the cameras, "
                       "or lower --candidates");
    }
    return out;
  };
  // Uniform feasible poses: the evaluation set and the random design.
  auto stage = [&](const std::string& what) {
    if (options.progress) options.progress(what);
  };
  stage("drawing feasible random poses");
  Poses uniform = collect(&sampler, options.evaluation_poses + options.n);
  plan.evaluation_poses.assign(uniform.begin(),
                               uniform.begin() + options.evaluation_poses);
  plan.random_poses.assign(uniform.begin() + options.evaluation_poses,
                           uniform.end());
  Sampler extreme(inner, options.seed + 1,
                  options.fixed_point ? 0.0 : options.extreme_fraction);
  stage("drawing " + std::to_string(options.candidates) +
        " feasible candidates");
  Poses candidates = collect(&extreme, options.candidates);
  plan.feasible_candidates = static_cast<int>(candidates.size());

  Problem pr = MakeProblem(robot, plan, options);
  const std::vector<Measurement> ms =
      MakeDesignMeasurements(pr.chain, candidates, pr.fixed_point);
  std::vector<ParamInfo> cand_params =
      pr.fixed_point ? PointParams(pr.state) : FrameParams();
  for (const ParamInfo& p : GeometryParams(pr.chain)) cand_params.push_back(p);
  stage("identifiability over the candidates");
  const Identifiability ident =
      AnalyzeIdentifiability(ms, pr.state, cand_params);
  plan.params = ident.identifiable;
  plan.unidentifiable = ident.UnidentifiableNames();
  if (ident.RobotParameterCount() == 0) {
    throw InputError("no robot parameter is identifiable from these poses");
  }
  const int p = static_cast<int>(plan.params.size());
  if (3 * options.n < p + 1) {
    throw InputError("--n " + std::to_string(options.n) + ": " +
                     std::to_string(p) +
                     " identifiable parameters need at least " +
                     std::to_string(p / 3 + 1) + " poses");
  }
  stage("choosing " + std::to_string(options.n) +
        (options.criterion == PlanOptions::kCoverage
             ? " poses (greedy travel coverage)"
             : " poses (greedy, then Fedorov exchange)"));
  const std::vector<int> chosen =
      ChooseDesign(inner, pr, ms, candidates, options, &plan);
  Poses design;
  for (int i : chosen) design.push_back(candidates[i]);
  stage("ordering the poses for short joint motions");
  plan.poses = OrderPoses(robot, design);
  plan.random_poses = OrderPoses(robot, plan.random_poses);
  plan.planned_coverage = TravelCoverage(inner, plan.poses);
  plan.random_coverage = TravelCoverage(inner, plan.random_poses);
  stage("predicting sigma (planned and random poses)");

  plan.planned = PredictQuality(robot, plan, plan.poses, options);
  plan.random = PredictQuality(robot, plan, plan.random_poses, options);
  plan.planned_sigma_gmean =
      RobotSigmaGeometricMean(robot, plan.params, plan.planned.sigma);
  plan.random_sigma_gmean =
      RobotSigmaGeometricMean(robot, plan.params, plan.random.sigma);
  plan.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
          .count();
  return plan;
}

std::string FormatPosesCsv(const Robot& robot, const Poses& poses) {
  std::ostringstream out;
  out << "# " << CommandLine() << "\n";
  out << "pose";
  for (const RobotRow& row : robot.joints) out << "," << row.name;
  out << "\n";
  char buf[64];
  for (size_t i = 0; i < poses.size(); ++i) {
    out << i;
    for (double v : poses[i]) {
      std::snprintf(buf, sizeof(buf), ",%.6f", v);
      out << buf;
    }
    out << "\n";
  }
  return out.str();
}

}  // namespace kincal
