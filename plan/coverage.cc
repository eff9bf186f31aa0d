#include "plan/coverage.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "calib/fit_record.h"

namespace kincal {
namespace {

constexpr double kTurnDeg = 360.0;

// One joint's travel and how a reading maps onto it.
struct Travel {
  bool circular = false;
  double lo = 0, hi = 0;
  double Length() const { return hi - lo; }
  double Map(double q) const {
    if (circular) {
      const double a = std::fmod(q, kTurnDeg);
      return a < 0 ? a + kTurnDeg : a;
    }
    return std::min(std::max(q, lo), hi);
  }
};

Travel TravelOf(const RobotRow& joint) {
  Travel t;
  t.circular = joint.type == JointType::kRevolute &&
               joint.upper - joint.lower >= kTurnDeg;
  t.lo = t.circular ? 0.0 : joint.lower;
  t.hi = t.circular ? kTurnDeg : joint.upper;
  return t;
}

// The gap of `sorted` (mapped readings) that holds x: [a, b] (circular:
// b may exceed 360, a may be below 0, so that a <= x <= b).
void GapAround(const Travel& t, const std::vector<double>& sorted, double x,
               double* a, double* b) {
  const auto next = std::lower_bound(sorted.begin(), sorted.end(), x);
  if (!t.circular) {
    *a = next == sorted.begin() ? t.lo : *(next - 1);
    *b = next == sorted.end() ? t.hi : *next;
    return;
  }
  if (sorted.empty()) {  // the whole turn, from x round to x
    *a = x;
    *b = x + kTurnDeg;
    return;
  }
  *a = next == sorted.begin() ? sorted.back() - kTurnDeg : *(next - 1);
  *b = next == sorted.end() ? sorted.front() + kTurnDeg : *next;
}

}  // namespace

std::vector<JointCoverage> TravelCoverage(
    const Robot& robot, const std::vector<std::vector<double>>& poses) {
  std::vector<JointCoverage> out;
  for (size_t j = 0; j < robot.joints.size(); ++j) {
    const Travel t = TravelOf(robot.joints[j]);
    std::vector<double> v;
    for (const std::vector<double>& q : poses) v.push_back(t.Map(q[j]));
    std::sort(v.begin(), v.end());
    JointCoverage c;
    c.joint = robot.joints[j].name;
    c.circular = t.circular;
    c.lo = t.lo;
    c.hi = t.hi;
    if (v.empty()) {
      c.from = t.lo;
      c.to = t.hi;
    } else if (t.circular) {  // the wrap first, then the inner gaps
      c.from = v.back();
      c.to = v.front() + kTurnDeg;
    } else {  // the ends first, then the inner gaps
      c.from = t.lo;
      c.to = v.front();
      if (t.hi - v.back() > c.Gap()) {
        c.from = v.back();
        c.to = t.hi;
      }
    }
    for (size_t i = 1; i < v.size(); ++i) {
      if (v[i] - v[i - 1] > c.Gap()) {
        c.from = v[i - 1];
        c.to = v[i];
      }
    }
    TravelGap g;
    g.lo = t.lo;
    g.hi = t.hi;
    g.from = c.from;
    g.to = c.to;
    c.wide = IsWideGap(g);
    out.push_back(c);
  }
  return out;
}

std::vector<int> CoverageDesign(
    const Robot& robot, const std::vector<std::vector<double>>& candidates,
    int n) {
  const int joints = static_cast<int>(robot.joints.size());
  std::vector<Travel> travel;
  for (const RobotRow& joint : robot.joints) travel.push_back(TravelOf(joint));
  std::vector<std::vector<double>> chosen_values(joints);
  std::vector<bool> taken(candidates.size(), false);
  std::vector<int> chosen;
  const int want = std::min<int>(n, static_cast<int>(candidates.size()));
  while (static_cast<int>(chosen.size()) < want) {
    int best = -1;
    double best_gain = -std::numeric_limits<double>::infinity();
    for (size_t c = 0; c < candidates.size(); ++c) {
      if (taken[c]) continue;
      double gain = 0;
      for (int j = 0; j < joints; ++j) {
        const Travel& t = travel[j];
        if (!(t.Length() > 0)) continue;
        const double x = t.Map(candidates[c][j]);
        double a = 0, b = 0;
        GapAround(t, chosen_values[j], x, &a, &b);
        gain += ((b - a) * (b - a) - (x - a) * (x - a) - (b - x) * (b - x)) /
                (t.Length() * t.Length());
      }
      if (gain > best_gain) {
        best_gain = gain;
        best = static_cast<int>(c);
      }
    }
    taken[best] = true;
    chosen.push_back(best);
    for (int j = 0; j < joints; ++j) {
      std::vector<double>& v = chosen_values[j];
      const double x = travel[j].Map(candidates[best][j]);
      v.insert(std::lower_bound(v.begin(), v.end(), x), x);
    }
  }
  return chosen;
}

}  // namespace kincal
