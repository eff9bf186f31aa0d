#include "data/observation_checks.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "data/error.h"

namespace kincal {
namespace {

std::string Num(double v, const char* format = "%.4g") {
  char buf[64];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}

const char* Unit(const RobotRow& joint) {
  return joint.type == JointType::kPrismatic ? "mm" : "deg";
}

// Largest extent of the measured points' bounding box over x, y, z, and the
// largest span of any joint's readings, over the rows with a point and no
// fixed-point label.
struct PointSpread {
  int rows = 0;
  int first_line = 0;
  double point_span = 0.0;
  double joint_span = 0.0;
};

PointSpread SpreadOfPointRows(const Observations& obs) {
  PointSpread s;
  Eigen::Vector3d lo =
      Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d hi = -lo;
  std::vector<double> qlo, qhi;
  for (const Observation& row : obs.rows) {
    if (!row.has_point || !row.fixed_point.empty()) continue;
    if (s.rows++ == 0) {
      s.first_line = row.line;
      qlo = qhi = row.q;
    }
    lo = lo.cwiseMin(row.p_in_meas);
    hi = hi.cwiseMax(row.p_in_meas);
    for (size_t k = 0; k < row.q.size() && k < qlo.size(); ++k) {
      qlo[k] = std::min(qlo[k], row.q[k]);
      qhi[k] = std::max(qhi[k], row.q[k]);
    }
  }
  if (s.rows == 0) return s;
  s.point_span = (hi - lo).maxCoeff();
  for (size_t k = 0; k < qlo.size(); ++k)
    s.joint_span = std::max(s.joint_span, qhi[k] - qlo[k]);
  return s;
}

void CheckPointsNotMetres(const Robot& robot, const Observations& obs,
                          const ObservationCheckOptions& options) {
  const PointSpread s = SpreadOfPointRows(obs);
  const double reach = LinkLengthSumMm(robot);
  if (s.rows < 3 || s.point_span >= options.metre_span ||
      reach <= options.metre_min_reach_mm ||
      s.joint_span <= options.metre_min_joint_span)
    return;
  throw InputError(
      obs.source, s.first_line, 0,
      "the measured points x,y,z span only " + Num(s.point_span) +
          " units over " + std::to_string(s.rows) +
          " poses while the joints move up to " + Num(s.joint_span) +
          " and the robot's links add up to " + Num(reach, "%.0f") +
          " mm: the points look like metres; observations.csv wants "
          "millimetres (multiply x,y,z by 1000)");
}

}  // namespace

double LinkLengthSumMm(const Robot& robot) {
  double sum = 0.0;
  auto add = [&sum](const RobotRow& r) {
    sum += std::abs(r.a_mm) + std::abs(r.d_mm) + r.xyz_mm.norm();
  };
  for (const RobotRow& r : robot.joints) add(r);
  add(robot.tool);
  return sum;
}

void CheckReadingWithinLimits(const RobotRow& joint, double reading,
                              const std::string& source, int line,
                              const std::string& robot_label, double margin) {
  if (!joint.HasLimits()) return;
  if (reading >= joint.lower - margin && reading <= joint.upper + margin)
    return;
  throw InputError(
      source, line, 0,
      "joint " + joint.name + " reads " + Num(reading) + " " + Unit(joint) +
          ", outside its limits [" + Num(joint.lower) + ", " +
          Num(joint.upper) + "] " + Unit(joint) + " in " + robot_label +
          ": a wrong column, wrong units or a corrupted reading; correct or "
          "delete the row (or fix the limits in the robot file)");
}

void CheckJointUnits(const Robot& robot,
                     const std::vector<std::vector<double>>& rows,
                     const std::string& source, Warnings* warnings,
                     const ObservationCheckOptions& options) {
  if (static_cast<int>(rows.size()) < options.radian_min_rows) return;
  double largest = 0.0, widest_span = 0.0;
  bool any_revolute = false;
  for (size_t k = 0; k < robot.joints.size(); ++k) {
    if (robot.joints[k].type != JointType::kRevolute) continue;
    any_revolute = true;
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (const std::vector<double>& q : rows) {
      if (k >= q.size()) return;
      largest = std::max(largest, std::abs(q[k]));
      lo = std::min(lo, q[k]);
      hi = std::max(hi, q[k]);
    }
    widest_span = std::max(widest_span, hi - lo);
  }
  if (!any_revolute || largest > options.radian_bound ||
      widest_span <= options.radian_min_span)
    return;
  warnings->Add(
      "joint_units_radians",
      source + ": every revolute joint reading lies within +-" +
          Num(largest, "%.2f") + " over " + std::to_string(rows.size()) +
          " rows: they look like radians; kincal reads degrees (multiply "
          "the revolute joint columns by 180/pi = 57.2958)");
}

void CheckObservationsAgainstRobot(const Robot& robot, const Observations& obs,
                                   const std::string& robot_label,
                                   Warnings* warnings,
                                   const ObservationCheckOptions& options) {
  std::vector<std::vector<double>> rows;
  rows.reserve(obs.rows.size());
  for (const Observation& row : obs.rows) {
    for (size_t k = 0; k < robot.joints.size() && k < row.q.size(); ++k)
      CheckReadingWithinLimits(robot.joints[k], row.q[k], obs.source, row.line,
                               robot_label, options.limit_margin);
    rows.push_back(row.q);
  }
  CheckPointsNotMetres(robot, obs, options);
  CheckJointUnits(robot, rows, obs.source, warnings, options);
}

}  // namespace kincal
