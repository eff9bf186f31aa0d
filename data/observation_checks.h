#ifndef KINCAL_DATA_OBSERVATION_CHECKS_H_
#define KINCAL_DATA_OBSERVATION_CHECKS_H_

// Checks of joint readings and measured points against the robot they are
// meant for: the inputs that parse but cannot be right (refused with
// InputError, exit 2) or look wrong (a Warning). The rule per check is in
// docs/CONVENTIONS.md "Errors and output":
//   - a reading outside its joint's limits by more than the margin: refused,
//     naming file:line and the joint (no check when the robot has no limits);
//   - measured points that span less than 2 units while the joints move and
//     the robot's links are hundreds of mm long: metres, refused ("multiply
//     by 1000");
//   - every revolute reading within +-2 pi while the joints move: radians,
//     a warning (joint_units_radians), since a tiny-motion data set in
//     degrees is possible, if unlikely.

#include <string>
#include <vector>

#include "data/observations.h"
#include "data/robot.h"
#include "data/warnings.h"

namespace kincal {

struct ObservationCheckOptions {
  // Readings may pass a limit by this much (deg for revolute, mm for
  // prismatic joints) before they are refused: encoders report a little past
  // the software limit.
  double limit_margin = 2.0;
  // Measured points whose bounding box is smaller than this (in the file's
  // units) on every axis look like metres...
  double metre_span = 2.0;
  // ...when the robot's summed link lengths exceed this, mm...
  double metre_min_reach_mm = 100.0;
  // ...and some joint moves more than this (deg or mm) across those rows.
  double metre_min_joint_span = 5.0;
  // Radians: every revolute reading within +-radian_bound while some
  // revolute joint spans more than radian_min_span (0.5 rad = 29 deg, a small
  // calibration excursion; 0.5 deg would be no excursion at all)...
  double radian_bound = 6.3;
  double radian_min_span = 0.5;
  // ...over at least this many rows.
  int radian_min_rows = 3;
};

// One reading of one row against the joint's limits: InputError at
// `source`:`line` naming the joint when it lies outside them by more than
// the margin; nothing when the joint has no limits. `robot_label` names the
// robot file in the message.
void CheckReadingWithinLimits(const RobotRow& joint, double reading,
                              const std::string& source, int line,
                              const std::string& robot_label,
                              double margin = 2.0);

// Every revolute reading within +-2 pi while they move: a joint_units_radians
// warning in `warnings`. `rows` are joint vectors in robot order.
void CheckJointUnits(const Robot& robot,
                     const std::vector<std::vector<double>>& rows,
                     const std::string& source, Warnings* warnings,
                     const ObservationCheckOptions& options = {});

// All the checks above on an observations file: limits (InputError), points
// in metres (InputError), radians (warning).
void CheckObservationsAgainstRobot(const Robot& robot, const Observations& obs,
                                   const std::string& robot_label,
                                   Warnings* warnings,
                                   const ObservationCheckOptions& options = {});

// The robot's summed link lengths (|a|, |d|, |xyz| of every row and the
// tool), mm: an upper bound of its reach.
double LinkLengthSumMm(const Robot& robot);

}  // namespace kincal

#endif  // KINCAL_DATA_OBSERVATION_CHECKS_H_
