#ifndef KINCAL_CALIB_POSE_COVERAGE_H_
#define KINCAL_CALIB_POSE_COVERAGE_H_

// Whether the poses of a data set can determine the robot (issue 21, item
// 4): tips tracked by cameras often come from poses whose joints moved
// little (the tool must stay in view), and a tips-only calibration is then
// ill-conditioned. Method: the identifiability scan of calib/identifiability.h
// (frame and geometry parameters, the statistical criterion at a tracker's
// tip noise) on the data's poses, and on as many poses drawn uniformly over
// the joints' limits (seeded, `seed`); a parameter those determine and the
// data's poses do not is undetermined by the poses, not by the model. The
// joints whose seen travel is a small part of their range are named with it.

#include <cstdint>
#include <string>
#include <vector>

#include "data/observations.h"
#include "data/robot.h"

namespace kincal {

struct PoseCoverageOptions {
  // Tip noise of the statistical criterion (mm; a tracker's 0.05 mm).
  double noise_sigma_mm = 0.05;
  uint64_t seed = 1;
  // A joint whose seen travel is under this fraction of its range (limits;
  // 360 deg for a revolute joint without limits) is named as small.
  double small_travel_fraction = 0.25;

  void Check() const;  // InputError naming the bad option
};

struct JointTravel {
  std::string joint;
  double seen = 0;   // max - min of the readings with a tip (deg or mm)
  double range = 0;  // upper - lower (360 deg without limits; 0 prismatic)
  bool small = false;
};

struct PoseCoverage {
  std::vector<JointTravel> travel;  // every joint, chain order
  // Parameters (calibrate's names, e.g. "j5.theta") determined by poses
  // over the limits but not by the data's.
  std::vector<std::string> undetermined;
  bool ok() const { return undetermined.empty(); }
};

// Rows with a measured tip count (fixed-point rows and rows without a tip do
// not); fewer than two such rows give an empty (ok) result.
PoseCoverage CheckPoseCoverage(const Robot& nominal, const Observations& obs,
                               const PoseCoverageOptions& options = {});

// The warning's text: the undetermined parameters, the joints with small
// travel and their seen travel against the range, and the fix (the image
// bundle, `kincal bundle`, or poses from `kincal plan --rig`).
std::string PoseCoverageMessage(const PoseCoverage& coverage);

}  // namespace kincal

#endif  // KINCAL_CALIB_POSE_COVERAGE_H_
