#ifndef KINCAL_CALIB_MODEL_STATE_H_
#define KINCAL_CALIB_MODEL_STATE_H_

// Everything a fit can change, and the names of its parameters
// (docs/CONVENTIONS.md, "Parameter names"): the chain (row geometry, joint
// error models, drift), the measuring frame meas_from_base, and the fixed
// points of single-point data. One parameter block per physical thing.

#include <Eigen/Core>
#include <array>
#include <string>
#include <vector>

#include "calib/chain.h"

namespace kincal {

struct ModelState {
  Chain chain;
  // meas_from_base: [rx, ry, rz] angle-axis (rad), [tx, ty, tz] (mm).
  // The measuring frame of frame 0 (every row, for data of one series).
  std::array<double, kFrameBlockSize> meas_from_base{};
  // Frames 1.. (data of several series, spec v3 column `series`: one
  // measuring frame per series, the robot shared), same layout.
  std::vector<std::array<double, kFrameBlockSize>> more_frames;
  // The series label of each frame (frame_series[i] for frame i); empty for
  // data of one series.
  std::vector<std::string> frame_series;
  // Fixed points (the seed's single-point experiment), in the base frame.
  std::vector<std::string> point_labels;
  std::vector<std::array<double, 3>> points_in_base;

  int PointIndex(const std::string& label) const;  // -1 when absent
  // Frames: 1 + more_frames.size(); frame i's block (0: meas_from_base).
  int NumFrames() const { return 1 + static_cast<int>(more_frames.size()); }
  double* FrameBlock(int frame) {
    return frame == 0 ? meas_from_base.data()
                      : more_frames.at(frame - 1).data();
  }
  const double* FrameBlock(int frame) const {
    return frame == 0 ? meas_from_base.data()
                      : more_frames.at(frame - 1).data();
  }
};

enum class ParamKind { kRow, kJointError, kDrift, kFrame, kPoint };

// One scalar parameter: where it lives and how it is named and shown.
struct ParamInfo {
  std::string name;  // e.g. "j3.a", "tool.d", "frame.rx", "j3.backlash"
  ParamKind kind = ParamKind::kRow;
  int block = 0;       // row / joint / point index (0 for frame and drift)
  int index = 0;       // index inside the block
  bool angle = false;  // internal radians, shown in degrees

  double ToInterface(double internal) const;  // rad -> deg for angles
  double FromInterface(double value) const;
  // The unit of ToInterface's value: "deg" or "mm" for geometry, frame and
  // points; per family for the error model ("1" for a gain, "deg/mm" for a
  // compliance per mm of unit-mass torque, "deg/(N m)" for elastostatic and
  // mount compliances, "1/K or 1/h" for thermal growth, "mm/h" for drift).
  std::string InterfaceUnit() const;
};

double* ParamAddress(ModelState* state, const ParamInfo& p);
double ParamValue(const ModelState& state, const ParamInfo& p);

// The geometric parameters of every row, in chain order: dh/mdh rows give
// theta, d, a, alpha (beta only through AxisTiltParam); urdf rows give x, y,
// z, roll, pitch, yaw. BH-7: 6 rows x 4 = 24.
std::vector<ParamInfo> GeometryParams(const Chain& chain);
// Hayati beta of row `row` (tilts the axis of joint row+1 / the tool).
ParamInfo AxisTiltParam(const Chain& chain, int row);
// Rows whose next axis is nominally parallel (|alpha| < 1e-6, not urdf): the
// rows where a beta is meaningful.
std::vector<int> ParallelAxisRows(const Chain& chain);
// Frame 0's parameters: frame.rx, .ry, .rz, .x, .y, .z.
std::vector<ParamInfo> FrameParams();
// Every frame's parameters (block = frame index): FrameParams() for one
// frame; with several, frame.<series>.rx, ... named by state.frame_series.
std::vector<ParamInfo> AllFrameParams(const ModelState& state);
std::vector<ParamInfo> PointParams(const ModelState& state);
// Joint error model parameters (index: JointErrorIndex) and drift.
ParamInfo JointErrorParam(const Chain& chain, int joint, int index);
std::vector<ParamInfo> DriftParams();
// Mount compliance (global block kMountIso, kMountCos, kMountSin), rad per
// N m (shown as deg per N m).
std::vector<ParamInfo> MountParams();

// Finds a parameter by name among all parameters the state has; throws
// InputError listing close names when unknown.
ParamInfo FindParam(const ModelState& state, const std::string& name);

}  // namespace kincal

#endif  // KINCAL_CALIB_MODEL_STATE_H_
