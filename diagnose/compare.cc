#include "diagnose/compare.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

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

// The poses of both sessions by label: the before session's order, then
// labels only the after session has.
struct PosePair {
  std::string label;
  const Iso9283Pose* before = nullptr;
  const Iso9283Pose* after = nullptr;
};

std::vector<PosePair> PairPoses(const CompareResult& r) {
  std::vector<PosePair> pairs;
  for (const Iso9283Pose& p : r.iso9283_before.poses) {
    pairs.push_back({p.label, &p, nullptr});
  }
  for (const Iso9283Pose& p : r.iso9283_after.poses) {
    auto it = std::find_if(pairs.begin(), pairs.end(), [&](const PosePair& q) {
      return q.label == p.label;
    });
    if (it == pairs.end()) {
      pairs.push_back({p.label, nullptr, &p});
    } else {
      it->after = &p;
    }
  }
  return pairs;
}

nlohmann::json Iso9283ComparisonJson(const CompareResult& r) {
  nlohmann::json poses = nlohmann::json::array();
  auto field = [](const Iso9283Pose* p, double Iso9283Pose::*member) {
    return p ? Num(p->*member) : nlohmann::json(nullptr);
  };
  for (const PosePair& p : PairPoses(r)) {
    poses.push_back({{"pose", p.label},
                     {"ap_before_mm", field(p.before, &Iso9283Pose::ap_mm)},
                     {"ap_after_mm", field(p.after, &Iso9283Pose::ap_mm)},
                     {"rp_before_mm", field(p.before, &Iso9283Pose::rp_mm)},
                     {"rp_after_mm", field(p.after, &Iso9283Pose::rp_mm)}});
  }
  return {{"poses", poses},
          {"ap_max_before_mm", Num(r.iso9283_before.ap_max_mm)},
          {"ap_max_after_mm", Num(r.iso9283_after.ap_max_mm)},
          {"rp_max_before_mm", Num(r.iso9283_before.rp_max_mm)},
          {"rp_max_after_mm", Num(r.iso9283_after.rp_max_mm)},
          {"frame", "registered_on_poses"}};
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
  if (HasIso9283Rows(before) && HasIso9283Rows(after)) {
    r.iso9283_before = ComputeIso9283(robot, before);
    r.iso9283_after = ComputeIso9283(robot, after);
    r.has_iso9283 = true;
  }
  const std::vector<Magnitude> b =
      FitCandidates(robot, before, labels, &r.before_sigma0_mm);
  const std::vector<Magnitude> a =
      FitCandidates(robot, after, labels, &r.after_sigma0_mm);
  int compared = 0;
  for (size_t j = 0; j < labels.size(); ++j) {
    if (std::isfinite(b[j].sigma) && std::isfinite(a[j].sigma)) ++compared;
  }
  // ISO 9283 cycles alone (five poses) rarely determine a clearance: the
  // comparison is then the ISO figures' only.
  const bool iso_only = compared == 0 && r.has_iso9283;
  if (compared == 0 && !iso_only) {
    throw InputError(before.source, 0, 0,
                     "no joint's clearance can be determined in both "
                     "sessions: the joints must move in both directions "
                     "between poses (rows in visit order)");
  }
  r.z_critical = iso_only ? std::numeric_limits<double>::quiet_NaN()
                          : NormalUpperQuantile(0.025 / compared);
  r.verdict = iso_only ? "not_determined" : "unchanged";
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
  nlohmann::json out = {{"verdict", r.verdict},
                        {"joints", joints},
                        {"z_critical", Num(r.z_critical)},
                        {"before_sigma0_mm", Num(r.before_sigma0_mm)},
                        {"after_sigma0_mm", Num(r.after_sigma0_mm)}};
  if (r.has_iso9283) out["iso9283"] = Iso9283ComparisonJson(r);
  return out;
}

std::string CompareIso9283Text(const CompareResult& r) {
  if (!r.has_iso9283) return "";
  std::string out =
      "  ISO 9283 (each session's frame registered on its own poses):\n";
  char line[160];
  std::snprintf(line, sizeof(line), "  %-8s %12s %12s %12s %12s\n", "pose",
                "AP before", "AP after", "RP before", "RP after");
  out += line;
  for (const PosePair& p : PairPoses(r)) {
    std::snprintf(line, sizeof(line), "  %-8s %12.4f %12.4f %12.4f %12.4f\n",
                  p.label.c_str(), p.before ? p.before->ap_mm : NAN,
                  p.after ? p.after->ap_mm : NAN,
                  p.before ? p.before->rp_mm : NAN,
                  p.after ? p.after->rp_mm : NAN);
    out += line;
  }
  std::snprintf(line, sizeof(line), "  %-8s %12.4f %12.4f %12.4f %12.4f\n",
                "max", r.iso9283_before.ap_max_mm, r.iso9283_after.ap_max_mm,
                r.iso9283_before.rp_max_mm, r.iso9283_after.rp_max_mm);
  return out + line;
}

}  // namespace kincal
