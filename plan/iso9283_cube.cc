#include "plan/iso9283_cube.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <random>
#include <sstream>

#include "calib/chain.h"
#include "calib/inverse_kinematics.h"
#include "data/error.h"
#include "data/provenance.h"
#include "data/rigid3.h"

namespace kincal {
namespace {

using Joints = std::vector<double>;
using Limits = std::vector<std::array<double, 2>>;

constexpr int kLabels = 5;

std::string Label(int index) { return "P" + std::to_string(index + 1); }

std::string FormatPoint(const Eigen::Vector3d& p, const char* format) {
  char buf[128];
  std::snprintf(buf, sizeof(buf), format, p.x(), p.y(), p.z());
  return buf;
}

std::string Mm(const Eigen::Vector3d& p) {
  return FormatPoint(p, "(%.1f, %.1f, %.1f) mm");
}

std::string Deg(const Eigen::Matrix3d& rotation) {
  return FormatPoint(RotationVectorFromMatrix(rotation) * 180.0 / M_PI,
                     "(%.2f, %.2f, %.2f) deg");
}

void CheckInputs(const Robot& robot, const IsoCubeOptions& options) {
  for (const RobotRow& row : robot.joints) {
    if (!row.HasLimits() || !(row.upper > row.lower)) {
      throw InputError("robot '" + robot.name + "': joint '" + row.name +
                       "' has no limits (or an empty range); the ISO 9283 "
                       "cube needs `limits: [lo, hi]` on every joint");
    }
  }
  if (!(options.cube_mm > 0) || !std::isfinite(options.cube_mm)) {
    throw InputError("--cube: expected the cube's edge length in mm (> 0)");
  }
  if (options.cycles < 1) throw InputError("--cycles: expected at least 1");
  if (!(options.limit_margin >= 0 && options.limit_margin <= 0.45)) {
    throw InputError(
        "--limit-margin: expected a fraction of the range in [0, 0.45]");
  }
  if (options.orientation_deg && robot.joints.size() < 6) {
    throw InputError("--orientation: robot '" + robot.name + "' has " +
                     std::to_string(robot.joints.size()) +
                     " joints; an orientation is held by arms with six or "
                     "more (the cube's positions are planned without one)");
  }
  if (options.samples < 1 || options.max_seeds < 1) {
    throw InputError("ISO 9283 cube: samples and seeds must be positive");
  }
}

// Each joint's limits moved inwards by `margin` of its range.
Limits InnerLimits(const Robot& robot, double margin) {
  Limits limits;
  for (const RobotRow& row : robot.joints) {
    const double keep = margin * (row.upper - row.lower);
    limits.push_back({row.lower + keep, row.upper - keep});
  }
  return limits;
}

Joints Internal(const Chain& chain, const Joints& q) {
  Joints qi(q.size());
  for (size_t j = 0; j < q.size(); ++j) {
    qi[j] = chain.ReadingToInternal(static_cast<int>(j), q[j]);
  }
  return qi;
}

Eigen::Matrix4d PoseAt(const Chain& chain, const Joints& q) {
  return ModelPoseAtReadings(chain, q, IkContext{}, false);
}

// Random configurations within `limits`, clear of obstacles and of
// themselves, until `count` are found or `max_draws` were drawn.
struct Samples {
  std::vector<Joints> feasible;
  long draws = 0;
  std::map<std::string, long> contacts;  // rejections by what was met
};

Samples DrawFeasible(const Chain& chain, const Limits& limits,
                     const IsoCubeOptions& options) {
  Samples out;
  std::mt19937_64 rng(options.seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  while (static_cast<int>(out.feasible.size()) < options.samples &&
         out.draws < options.max_draws) {
    ++out.draws;
    Joints q(limits.size());
    for (size_t j = 0; j < q.size(); ++j) {
      q[j] = limits[j][0] + unit(rng) * (limits[j][1] - limits[j][0]);
    }
    const Contact contact =
        FindContact(chain, Internal(chain, q), options.safety);
    if (contact.kind == Contact::kNone) {
      out.feasible.push_back(q);
    } else {
      ++out.contacts[contact.Describe(options.safety)];
    }
  }
  if (out.feasible.empty()) {
    std::string met;
    for (const auto& [what, count] : out.contacts) {
      met += (met.empty() ? "" : ", ") + what + " " + std::to_string(count);
    }
    throw InputError(
        "ISO 9283 cube: no configuration within the limits "
        "less the margin is clear of the obstacles in " +
        std::to_string(out.draws) + " random draws (" + met + ")");
  }
  return out;
}

Eigen::Vector3d MedianTip(const Chain& chain,
                          const std::vector<Joints>& configurations) {
  std::vector<double> xs[3];
  for (const Joints& q : configurations) {
    const Eigen::Vector3d tip = PoseAt(chain, q).block<3, 1>(0, 3);
    for (int k = 0; k < 3; ++k) xs[k].push_back(tip[k]);
  }
  Eigen::Vector3d median;
  for (int k = 0; k < 3; ++k) {
    std::nth_element(xs[k].begin(), xs[k].begin() + xs[k].size() / 2,
                     xs[k].end());
    median[k] = xs[k][xs[k].size() / 2];
  }
  return median;
}

// One seed's try: the poses solved so far and, when one failed, why.
struct Attempt {
  std::array<IsoCubePose, kLabels> poses;
  Eigen::Vector3d center = Eigen::Vector3d::Zero();
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  int passed = 0;       // poses and moves that passed, in checking order
  std::string failure;  // empty: all passed
};

// Why an inverse-kinematics solve missed its target: a joint limit when
// the same solve without limits (`free_reached`) gets there, else out of
// reach.
std::string IkFailure(const Robot& robot, const IkResult& ik, bool free_reached,
                      const Limits& limits, bool with_rotation) {
  char miss[96];
  if (with_rotation) {
    std::snprintf(miss, sizeof(miss), "%.3g mm and %.3g deg",
                  ik.position_error_mm, ik.rotation_error_deg);
  } else {
    std::snprintf(miss, sizeof(miss), "%.3g mm", ik.position_error_mm);
  }
  if (free_reached && !ik.at_limit.empty()) {
    const std::string& name = ik.at_limit.front();
    std::string range;
    for (size_t j = 0; j < robot.joints.size(); ++j) {
      if (robot.joints[j].name != name) continue;
      char buf[96];
      std::snprintf(
          buf, sizeof(buf), "[%.6g, %.6g] %s", limits[j][0], limits[j][1],
          robot.joints[j].type == JointType::kPrismatic ? "mm" : "deg");
      range = buf;
    }
    return "is beyond a joint limit: joint '" + name +
           "' stops at its limits less the margin " + range +
           " (the inverse kinematics ends " + miss + " from the target)";
  }
  return std::string("is unreachable") +
         (with_rotation ? " with the tool orientation" : "") +
         ": the inverse kinematics ends " + miss + " from it";
}

// The first contact on the joint-space move from `a` to `b` (end points
// excluded), at `checks` evenly spaced intermediate points.
Contact MoveContact(const Chain& chain, const Joints& a, const Joints& b,
                    const IsoCubeOptions& options) {
  for (int k = 1; k <= options.path_checks; ++k) {
    const double t = static_cast<double>(k) / (options.path_checks + 1);
    Joints q(a.size());
    for (size_t j = 0; j < a.size(); ++j) q[j] = a[j] + t * (b[j] - a[j]);
    const Contact c = FindContact(chain, Internal(chain, q), options.safety);
    if (c.kind != Contact::kNone) return c;
  }
  return Contact{};
}

struct Problem {
  const Robot& robot;
  const Chain& chain;
  const IsoCubeOptions& options;
  Limits limits;  // less the margin
  bool with_rotation = false;
};

// Solves one position from `seed`; false (and `attempt->failure`) when it
// is unreachable, beyond a limit or in collision.
bool SolvePosition(const Problem& pr, int index, const Joints& seed,
                   Attempt* attempt) {
  IkTarget target;
  target.position_mm = attempt->poses[index].position_mm;
  target.has_rotation = pr.with_rotation;
  target.rotation = attempt->rotation;
  IkOptions ik_options;
  ik_options.limits = pr.limits;
  ik_options.use_error_model = false;  // the nominal controller's geometry
  ik_options.tolerance_mm = 1e-7;
  ik_options.tolerance_deg = 1e-7;
  ik_options.max_iterations = 400;
  const IkResult ik = SolveIk(pr.chain, target, seed, IkContext{}, ik_options);
  const std::string where =
      Label(index) + " at " + Mm(attempt->poses[index].position_mm) + " ";
  if (!ik.reached) {
    IkOptions free_options = ik_options;
    free_options.limits.clear();
    const bool free_reached =
        !ik.at_limit.empty() &&
        SolveIk(pr.chain, target, seed, IkContext{}, free_options).reached;
    attempt->failure = where + IkFailure(pr.robot, ik, free_reached, pr.limits,
                                         pr.with_rotation);
    return false;
  }
  const Contact contact =
      FindContact(pr.chain, Internal(pr.chain, ik.q), pr.options.safety);
  if (contact.kind != Contact::kNone) {
    attempt->failure =
        where + "is in collision: " + contact.Describe(pr.options.safety) +
        " is met";
    return false;
  }
  attempt->poses[index].joints = ik.q;
  ++attempt->passed;
  return true;
}

// Shifts each revolute joint of all five poses by the same whole number of
// turns toward the middle of its range, as far as the limits allow: the
// same tip poses and moves, readings nearest the middle.
void WrapTurns(const Robot& robot, const Limits& limits,
               std::array<IsoCubePose, kLabels>* poses) {
  for (size_t j = 0; j < robot.joints.size(); ++j) {
    if (robot.joints[j].type != JointType::kRevolute) continue;
    double lo = (*poses)[0].joints[j], hi = lo, sum = 0;
    for (const IsoCubePose& pose : *poses) {
      lo = std::min(lo, pose.joints[j]);
      hi = std::max(hi, pose.joints[j]);
      sum += pose.joints[j];
    }
    const double middle = 0.5 * (limits[j][0] + limits[j][1]);
    double turns = std::round((middle - sum / kLabels) / 360.0);
    // The whole set stays within the limits.
    turns = std::min(turns, std::floor((limits[j][1] - hi) / 360.0));
    turns = std::max(turns, std::ceil((limits[j][0] - lo) / 360.0));
    for (IsoCubePose& pose : *poses) pose.joints[j] += 360.0 * turns;
  }
}

// P1 from the seed, P2..P5 from P1's solution, then the moves of a cycle
// (P1 -> P5 -> P4 -> P3 -> P2 -> P1).
Attempt TrySeed(const Problem& pr, const Joints& seed) {
  Attempt attempt;
  const Eigen::Matrix4d seed_pose = PoseAt(pr.chain, seed);
  attempt.center = pr.options.center_mm
                       ? *pr.options.center_mm
                       : Eigen::Vector3d(seed_pose.block<3, 1>(0, 3));
  attempt.rotation =
      pr.options.orientation_deg
          ? RotationMatrixFromVector(*pr.options.orientation_deg * M_PI / 180)
          : Eigen::Matrix3d(seed_pose.block<3, 3>(0, 0));
  const auto positions = IsoCubePositions(attempt.center, pr.options.cube_mm);
  for (int i = 0; i < kLabels; ++i) {
    attempt.poses[i].label = Label(i);
    attempt.poses[i].position_mm = positions[i];
  }
  if (!SolvePosition(pr, 0, seed, &attempt)) return attempt;
  for (int i = 1; i < kLabels; ++i) {
    if (!SolvePosition(pr, i, attempt.poses[0].joints, &attempt)) {
      return attempt;
    }
  }
  int from = 0;
  for (int to : IsoCubeCycleOrder()) {
    const Contact c = MoveContact(pr.chain, attempt.poses[from].joints,
                                  attempt.poses[to].joints, pr.options);
    if (c.kind != Contact::kNone) {
      attempt.failure = "the move from " + Label(from) + " to " + Label(to) +
                        " is in collision: " + c.Describe(pr.options.safety) +
                        " is met";
      return attempt;
    }
    ++attempt.passed;
    from = to;
  }
  WrapTurns(pr.robot, pr.limits, &attempt.poses);
  return attempt;
}

// The feasible configurations ordered by the distance of their tips to
// `goal`, nearest first, at most `count`.
std::vector<Joints> NearestSeeds(const Chain& chain,
                                 const std::vector<Joints>& configurations,
                                 const Eigen::Vector3d& goal, int count) {
  std::vector<std::pair<double, size_t>> by_distance;
  for (size_t i = 0; i < configurations.size(); ++i) {
    const Eigen::Vector3d tip =
        PoseAt(chain, configurations[i]).block<3, 1>(0, 3);
    by_distance.push_back({(tip - goal).norm(), i});
  }
  std::sort(by_distance.begin(), by_distance.end());
  std::vector<Joints> seeds;
  for (size_t k = 0; k < by_distance.size() && static_cast<int>(k) < count;
       ++k) {
    seeds.push_back(configurations[by_distance[k].second]);
  }
  return seeds;
}

std::string NoFitMessage(const Problem& pr, const Attempt& best, int tried) {
  std::ostringstream msg;
  msg << "the ISO 9283 cube of " << pr.options.cube_mm
      << " mm does not fit: " << best.failure << " (the seed that got "
      << "furthest of " << tried << " tried; cube centre " << Mm(best.center);
  if (pr.with_rotation) msg << ", tool orientation " << Deg(best.rotation);
  msg << "); try a smaller --cube";
  if (!pr.options.center_mm) msg << ", a --cube-center";
  if (pr.with_rotation) msg << ", another --orientation";
  msg << ", a smaller --limit-margin or fewer obstacles";
  return msg.str();
}

}  // namespace

std::array<Eigen::Vector3d, 4> IsoCubePlaneCorners(
    const Eigen::Vector3d& center_mm, double cube_mm) {
  const double h = cube_mm / 2;
  return {center_mm + h * Eigen::Vector3d(-1, -1, -1),   // C1
          center_mm + h * Eigen::Vector3d(+1, -1, -1),   // C2
          center_mm + h * Eigen::Vector3d(+1, +1, +1),   // C7
          center_mm + h * Eigen::Vector3d(-1, +1, +1)};  // C8
}

std::array<Eigen::Vector3d, 5> IsoCubePositions(
    const Eigen::Vector3d& center_mm, double cube_mm) {
  const auto c = IsoCubePlaneCorners(center_mm, cube_mm);
  // 10 % of the diagonal from each corner toward the opposite one.
  auto near = [](const Eigen::Vector3d& corner, const Eigen::Vector3d& other) {
    return Eigen::Vector3d(corner + 0.1 * (other - corner));
  };
  return {center_mm, near(c[0], c[2]), near(c[1], c[3]), near(c[2], c[0]),
          near(c[3], c[1])};
}

std::array<int, 5> IsoCubeCycleOrder() { return {4, 3, 2, 1, 0}; }

IsoCubePlan PlanIsoCube(const Robot& robot, const IsoCubeOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  CheckInputs(robot, options);
  const Chain chain = Chain::FromRobot(robot);
  Problem pr{robot, chain, options, InnerLimits(robot, options.limit_margin),
             robot.joints.size() >= 6};
  const Samples samples = DrawFeasible(chain, pr.limits, options);
  const Eigen::Vector3d goal = options.center_mm
                                   ? *options.center_mm
                                   : MedianTip(chain, samples.feasible);
  const std::vector<Joints> seeds =
      NearestSeeds(chain, samples.feasible, goal, options.max_seeds);
  Attempt best;
  best.passed = -1;
  best.failure = "no seed configuration";
  int tried = 0;
  for (const Joints& seed : seeds) {
    ++tried;
    Attempt attempt = TrySeed(pr, seed);
    if (attempt.failure.empty()) {
      best = attempt;
      break;
    }
    if (attempt.passed > best.passed) best = attempt;
  }
  if (!best.failure.empty()) {
    throw InputError(NoFitMessage(pr, best, tried));
  }
  IsoCubePlan plan;
  plan.cube_mm = options.cube_mm;
  plan.center_mm = best.center;
  plan.fixed_orientation = pr.with_rotation;
  plan.rotation = best.rotation;
  plan.poses = best.poses;
  plan.cycles = options.cycles;
  for (int c = 0; c < options.cycles; ++c) {
    for (int index : IsoCubeCycleOrder()) plan.rows.push_back(index);
  }
  plan.seeds_tried = tried;
  plan.draws = samples.draws;
  plan.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
          .count();
  return plan;
}

std::string FormatIsoCubeCsv(const Robot& robot, const IsoCubePlan& plan) {
  std::ostringstream out;
  out << "# " << CommandLine() << "\n";
  out << "# ISO 9283 pose test: cube " << plan.cube_mm << " mm centred at "
      << FormatPoint(plan.center_mm, "(%.6f, %.6f, %.6f)")
      << " mm (base frame)";
  if (plan.fixed_orientation) {
    out << ", tool orientation "
        << FormatPoint(RotationVectorFromMatrix(plan.rotation) * 180 / M_PI,
                       "(%.6f, %.6f, %.6f)")
        << " deg (rotation vector)";
  }
  out << "; " << plan.cycles
      << " cycles of P5 P4 P3 P2 P1; move to P1 before the first row\n";
  out << "pose";
  for (const RobotRow& row : robot.joints) out << "," << row.name;
  out << ",fixed_point\n";
  char buf[64];
  for (size_t i = 0; i < plan.rows.size(); ++i) {
    const IsoCubePose& pose = plan.poses[plan.rows[i]];
    out << i;
    for (double v : pose.joints) {
      std::snprintf(buf, sizeof(buf), ",%.9f", v);
      out << buf;
    }
    out << "," << pose.label << "\n";
  }
  return out.str();
}

}  // namespace kincal
