#include "diagnose/compare.h"

#include <cmath>

#include "calib/chain.h"
#include "data/error.h"

namespace kincal {
namespace {

nlohmann::json Num(double v) {
  return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr);
}

nlohmann::json MagnitudeJson(const Magnitude& m) {
  return {{"clearance", Num(m.value)},
          {"sigma", Num(m.sigma)},
          {"ci95", {Num(m.ci_low), Num(m.ci_high)}}};
}

}  // namespace

double NormalUpperQuantile(double p) {
  Require(p > 0 && p < 1, "probability must be in (0, 1)");
  // P(Z > z) = erfc(z / sqrt 2) / 2, decreasing in z: bisection.
  double lo = -40, hi = 40;
  for (int it = 0; it < 200; ++it) {
    const double mid = 0.5 * (lo + hi);
    (0.5 * std::erfc(mid / std::sqrt(2.0)) > p ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

CompareResult CompareClearance(const Robot& robot, const Observations& before,
                               const Observations& after) {
  const Chain chain = Chain::FromRobot(robot);
  std::vector<std::string> labels;
  for (int j = 0; j < chain.num_joints(); ++j) {
    labels.push_back("backlash:" + chain.rows[j].name);
  }
  CompareResult r;
  const std::vector<Magnitude> b =
      FitCandidates(robot, before, labels, &r.before_sigma0_mm);
  const std::vector<Magnitude> a =
      FitCandidates(robot, after, labels, &r.after_sigma0_mm);
  int compared = 0;
  for (size_t j = 0; j < labels.size(); ++j) {
    if (std::isfinite(b[j].sigma) && std::isfinite(a[j].sigma)) ++compared;
  }
  if (compared == 0) {
    throw InputError(before.source, 0, 0,
                     "no joint's clearance can be determined in both "
                     "sessions: the joints must move in both directions "
                     "between poses (rows in visit order)");
  }
  r.z_critical = NormalUpperQuantile(0.025 / compared);
  r.verdict = "unchanged";
  for (size_t j = 0; j < labels.size(); ++j) {
    JointClearanceChange c;
    c.joint = chain.rows[j].name;
    c.unit = chain.rows[j].type == JointType::kRevolute ? "deg" : "mm";
    c.before = b[j];
    c.after = a[j];
    c.difference = a[j].value - b[j].value;
    const double s = std::hypot(a[j].sigma, b[j].sigma);
    c.z = s > 0 ? c.difference / s : std::numeric_limits<double>::quiet_NaN();
    c.changed = std::isfinite(c.z) && std::abs(c.z) > r.z_critical;
    if (c.changed) r.verdict = "changed";
    r.joints.push_back(c);
  }
  return r;
}

nlohmann::json CompareJson(const CompareResult& r) {
  nlohmann::json joints = nlohmann::json::array();
  for (const JointClearanceChange& c : r.joints) {
    joints.push_back({{"joint", c.joint},
                      {"unit", c.unit},
                      {"before", MagnitudeJson(c.before)},
                      {"after", MagnitudeJson(c.after)},
                      {"difference", Num(c.difference)},
                      {"z", Num(c.z)},
                      {"changed", c.changed}});
  }
  return {{"verdict", r.verdict},
          {"joints", joints},
          {"z_critical", r.z_critical},
          {"before_sigma0_mm", Num(r.before_sigma0_mm)},
          {"after_sigma0_mm", Num(r.after_sigma0_mm)}};
}

}  // namespace kincal
