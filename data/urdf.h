#ifndef KINCAL_DATA_URDF_H_
#define KINCAL_DATA_URDF_H_

#include <string>

#include "data/robot.h"

namespace kincal {

// Builds a serial chain (Robot with convention kUrdf) from a URDF file: the
// joints on the path from `root_link` to `tip_link`. Empty root = the tree's
// root; empty tip = the deepest leaf when the path is unique (a chain).
// Fixed joints are folded into the next movable joint's origin; those after
// the last movable joint become the tool row. URDF metres and radians become
// mm and degrees; `continuous` joints are revolute without limits. Bounds
// (admissible deviation from nominal): 20 mm and 10 degrees.
// Throws InputError (file:line) on malformed files or a broken path.
Robot ReadUrdfChain(const std::string& path, const std::string& root_link = "",
                    const std::string& tip_link = "");
Robot ParseUrdfChain(const std::string& xml, const std::string& file_label,
                     const std::string& root_link = "",
                     const std::string& tip_link = "");

// Reads a robot from robot.yaml, or from a URDF file when the path ends in
// ".urdf" (chain from `root_link` to `tip_link`, see ReadUrdfChain).
Robot ReadRobot(const std::string& path, const std::string& root_link = "",
                const std::string& tip_link = "");

}  // namespace kincal

#endif  // KINCAL_DATA_URDF_H_
