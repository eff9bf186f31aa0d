#ifndef KINCAL_CAMCAL_PLAUSIBILITY_H_
#define KINCAL_CAMCAL_PLAUSIBILITY_H_

// Is a calibration board given in millimetres? camcal reads board sizes in
// mm; a board given in metres (aprilgrid:6x6:0.03:0.3) calibrates just as
// well, but every translation of the rig comes out 1000 times too small and
// track later finds no tool pose. Two checks name the likely cause:
//  - before any image is read: a square or tag under 1 mm;
//  - after the solve: the board seen closer than 20 mm to the first camera
//    (median over the used views), or a stereo baseline under 1 mm.
// A size of exactly 1 states lengths in squares (or tags): the rig is then
// in board units, not mm, and the checks do not apply.

#include <string>

#include "camcal/calibrate_cameras.h"

namespace kincal {

struct BoardPlausibilityOptions {
  double min_size_mm = 1.0;       // square or tag edge
  double min_distance_mm = 20.0;  // median board-to-camera distance
  double min_baseline_mm = 1.0;   // stereo only
};

// Why a board of edge `size` (as given on the command line; `spec_text` the
// whole --target value) is not in mm, with the fix; empty when plausible
// or when size is exactly 1 (squares).
std::string BoardSizeImplausible(double size, const std::string& spec_text,
                                 const BoardPlausibilityOptions& options = {});

// Median distance (board units) from the first camera to the board origin
// over the views the solve used; NaN when there is none.
double MedianBoardDistance(const CalibrationSummary& summary);

// Why the solved rig puts the board or the cameras implausibly close
// (metres read as mm), with the fix; empty when plausible or size is 1.
std::string SolvedRigImplausible(const CalibrationSummary& summary, double size,
                                 const std::string& spec_text,
                                 const BoardPlausibilityOptions& options = {});

}  // namespace kincal

#endif  // KINCAL_CAMCAL_PLAUSIBILITY_H_
