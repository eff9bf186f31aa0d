#ifndef KINCAL_DIAGNOSE_CLEARANCE_H_
#define KINCAL_DIAGNOSE_CLEARANCE_H_

// The seed paper's joint motion error test (Wang, Cao, Liu 2013, Section 4,
// Fig. 4/5/6), as the paper describes it:
//
//   1. With the robot model as given (nominal or calibrated) and the
//      base-to-measuring-frame transform estimated first, compute the
//      deviation of every pose, eps_i = |f(t0 + dt_i) - b'_i| (Fig. 4).
//   2. Take the worst pose; sweep each joint's reading within +-gamma (deg
//      for revolute, mm for prismatic joints) with the others fixed; record
//      the curve eps(offset) (Fig. 5) and its minimum. The joint whose sweep
//      removes the error is the suspect (on BH-7 it was j3).
//   3. Repeat on the next-worst poses and aggregate: the suspect is the joint
//      with the smallest median error_min / error_before over them, if that
//      is at most reduction_threshold and no joint was the best joint
//      (smallest error_min) at more of the poses.
//
// Its weakness (measured in docs/DIAGNOSE.md): the error of one pose is a 3D
// vector e; sweeping joint j moves the tip along its Jacobian column J_j, so
// min over offset |e + J_j d| = |e| sin(angle(e, J_j)): almost any joint
// reduces one pose's error, noise included. `diagnose model` tests a model
// of the clearance against all poses instead.

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "calib/fit.h"
#include "data/observations.h"
#include "data/robot.h"
#include "data/svg_plot.h"

namespace kincal {

struct ClearanceOptions {
  // Sweep half-range in reading units (deg | mm), the paper's gamma.
  double gamma = 3.0;
  // Grid points per side; the minimum is refined by a parabola.
  int steps_per_side = 60;
  // Poses examined (the worst one plus the next-worst: step 3).
  int worst_poses = 5;
  // A joint "removes" a pose's error when error_min / error_before is at
  // most this.
  double reduction_threshold = 0.5;
  // Calibrate the geometry on the same data first (the paper runs Section 4
  // after its Section 1-3 calibration). On by default: with a nominal robot
  // the geometric error swamps a clearance (measured: j3 named in 10-43 % of
  // cases instead of 70-90 %, docs/DIAGNOSE.md). false = the robot as given.
  bool calibrate_geometry = true;

  void Check() const;  // InputError on invalid values
};

// One joint's sweep at one pose (Fig. 5).
struct SweepCurve {
  int joint = 0;
  std::vector<double> offset;    // reading units (deg | mm)
  std::vector<double> error_mm;  // eps at each offset
  double error_before_mm = 0.0;  // eps at offset 0
  double error_min_mm = 0.0;
  double at_offset = 0.0;  // reading units
};

struct PoseSweep {
  int row = 0;  // index in the observations
  std::string pose;
  double error_mm = 0.0;
  std::vector<SweepCurve> joints;  // one per joint
  int best_joint = -1;             // smallest error_min
};

struct ClearanceResult {
  std::vector<std::string> joint_names;
  std::vector<std::string> joint_units;  // "deg" | "mm"
  double gamma = 0.0;
  // Fig. 4/6: deviation of every measured pose, in visit order.
  std::vector<int> rows;
  std::vector<std::string> poses;
  std::vector<double> errors_mm;
  ErrorStats stats;
  // Worst pose first, then the next-worst (step 3).
  std::vector<PoseSweep> sweeps;
  // Per joint, over the examined poses: how often it was the best joint, and
  // the median of error_min / error_before.
  std::vector<int> wins;
  std::vector<double> median_ratio;
  int suspect = -1;  // joint index, -1 = none
};

// Runs the test. Throws InputError when fewer than 3 distinct measured poses
// are present (the measuring frame cannot be estimated).
ClearanceResult DiagnoseClearance(const Robot& robot, const Observations& obs,
                                  const ClearanceOptions& options);

// JSON per the spec (worst_pose, joints[joint, error_before_mm, error_min_mm,
// at_offset], suspect) plus the chart data (deviations, curves, votes).
nlohmann::json ClearanceJson(const ClearanceResult& result);
// Long-format CSV: kind,pose,joint,offset,error_mm with kind "deviation"
// (Fig. 4, one row per pose) or "sweep" (Fig. 5, one row per grid point).
std::string ClearanceCsv(const ClearanceResult& result);
// The seed's Fig. 4: the error eps_i of every pose as bars, with the RMS.
Plot DeviationPlot(const ClearanceResult& result);
// The seed's Fig. 5 for result.sweeps[k] (k = 0: the worst pose): each
// joint's sweep. The ends of a +-gamma sweep reach tens of mm and would
// flatten the minimum near zero the test is about, so y runs from 0 to 3x
// the pose's error (curves leaving the frame are clipped).
Plot SweepPlot(const ClearanceResult& result, size_t k);
// Two stacked plots: per-pose deviations and the worst pose's curves.
std::string ClearanceSvg(const ClearanceResult& result);

}  // namespace kincal

#endif  // KINCAL_DIAGNOSE_CLEARANCE_H_
