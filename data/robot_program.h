#ifndef KINCAL_DATA_ROBOT_PROGRAM_H_
#define KINCAL_DATA_ROBOT_PROGRAM_H_

// Joint programs for robot controllers, from rows of joint readings: the
// snippets docs/LAB.md shows, moving through the rows in order (no
// socket, no recording): URScript (Universal Robots, movej in radians),
// KRL (KUKA, E6AXIS in deg), RAPID (ABB, jointtarget in deg, MoveAbsJ) and
// a Franka joint list (C++ std::array<double, 7> in radians for libfranka's
// MotionGenerator). Written as a start to adapt and check on the robot:
// speeds are conservative and nothing was run on a real controller.

#include <string>
#include <vector>

#include "data/robot.h"

namespace kincal {

enum class ProgramFormat { kUrscript, kKrl, kRapid, kFranka };

// "urscript" | "krl" | "rapid" | "franka"; InputError otherwise.
ProgramFormat ParseProgramFormat(const std::string& name);
// The file extension the controller expects (".script", ".src", ".mod",
// ".cpp").
std::string ProgramExtension(ProgramFormat format);

// The program moving through `rows` (robot order, reading units) with `ids`
// as comments; `comment` lines go in the header. Throws InputError when the
// robot does not fit the format (prismatic joints; URScript needs 6 joints,
// KRL and RAPID 1..6 robot axes plus up to 6 external ones, Franka 7).
std::string FormatJointProgram(ProgramFormat format, const Robot& robot,
                               const std::vector<std::string>& ids,
                               const std::vector<std::vector<double>>& rows,
                               const std::vector<std::string>& comment);

}  // namespace kincal

#endif  // KINCAL_DATA_ROBOT_PROGRAM_H_
