#ifndef KINCAL_DATA_IMPORT_MUKCA_H_
#define KINCAL_DATA_IMPORT_MUKCA_H_

// Importer for the MUKCa single-point data (platonics-delft/
// kinematics_calibration): a Franka Panda's end-effector ball seated in one
// of two sockets 50 mm apart, many joint configurations per socket.
//
// A recording folder (e.g. data/panda_6/front) holds hole_0.csv and
// hole_1.csv: comma separated, no header, one joint set per line, 7 columns
// in rad (panda_joint1..7). The *_pose.csv files beside them are the
// controller's own FK and are not read.
//
// Each line becomes an observations row with `fixed_point` = hole_0 or
// hole_1, joint readings in degrees and no measured point (there is no
// external metrology: the constraints are "same point" and, with
// `--fixed-distance hole_0,hole_1,50`, the known distance).

#include <string>
#include <vector>

#include "data/observations.h"

namespace kincal {

// panda_joint1 .. panda_joint7: the movable joints of the Panda URDF.
std::vector<std::string> PandaJointNames();

// Reads <dir>/hole_0.csv and <dir>/hole_1.csv (hole_0 rows first). Pose ids
// are "hole_0_<k>" / "hole_1_<k>" (k = 0-based line). `joint_names` (7)
// name the columns. Throws InputError (file:line:column) when a file is
// missing, a line has the wrong number of fields, or a cell is not a number.
Observations ReadMukcaDir(
    const std::string& dir,
    const std::vector<std::string>& joint_names = PandaJointNames());

// One hole file's text; `label` becomes the fixed_point of every row.
void ParseMukcaHole(const std::string& text, const std::string& file_label,
                    const std::string& label, Observations* obs);

}  // namespace kincal

#endif  // KINCAL_DATA_IMPORT_MUKCA_H_
