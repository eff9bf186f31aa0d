#ifndef KINCAL_CALIB_INVERSE_KINEMATICS_H_
#define KINCAL_CALIB_INVERSE_KINEMATICS_H_

// Inverse kinematics through the whole model: the joint readings that put
// the tip of a chain (geometry and every error-model family: the joint
// errors act on the readings, the thermal, drift and mount terms on the tip)
// at a target position, and for arms with six or more joints optionally at a
// target orientation. Damped least squares from a seed, so a redundant arm
// takes the solution nearest the seed and every arm stays in the seed's
// configuration (elbow, wrist); joint limits are respected.
//
//   minimise |p(q) - p_t|^2 + w^2 |log(R(q) R_t^T)|^2 over readings q,
//   step dq = J^T (J J^T + lambda^2 I)^-1 (-r), lambda adapted (LM),
//
// with J by central differences of the model (the gravity torques and the
// other pose inputs are recomputed at every q, PoseInputAt).

#include <Eigen/Core>
#include <array>
#include <limits>
#include <string>
#include <vector>

#include "calib/chain.h"

namespace kincal {

// A tip target in the robot's base frame.
struct IkTarget {
  Eigen::Vector3d position_mm = Eigen::Vector3d::Zero();
  bool has_rotation = false;
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();  // base_from_tip
};

// The inputs of the error model beside the readings (see PoseInput): the
// approach direction of every joint (+1, -1, 0 unknown; empty = all 0), the
// hours since the session start and the thermal input.
struct IkContext {
  std::vector<double> s;
  double t_h = 0.0;
  double thermal_x = 0.0;
};

struct IkOptions {
  // Joint limits per joint in reading units (mm | deg); NaN = none. Empty =
  // no limits.
  std::vector<std::array<double, 2>> limits;
  // Weight of the orientation residual, mm per rad: 100 mm makes 1 mrad
  // count as 0.1 mm.
  double rotation_weight_mm = 100.0;
  double tolerance_mm = 1e-6;   // position residual at convergence
  double tolerance_deg = 1e-6;  // orientation residual at convergence
  int max_iterations = 200;
  // Largest change of a joint per iteration (deg | mm).
  double max_step = 10.0;
  // false: geometry only (the nominal controller's kinematics).
  bool use_error_model = true;
};

struct IkResult {
  bool reached = false;
  std::vector<double> q;  // readings (mm | deg), the best found
  double position_error_mm = 0.0;
  double rotation_error_deg = 0.0;  // 0 without a rotation target
  int iterations = 0;
  // Joints that end on a limit (names), when a limit stopped the solve.
  std::vector<std::string> at_limit;
};

// Solves for the readings from `seed_readings` (reading units).
IkResult SolveIk(const Chain& chain, const IkTarget& target,
                 const std::vector<double>& seed_readings,
                 const IkContext& context, const IkOptions& options);

// The model's base_from_tip for readings (reading units) in `context`: the
// forward map SolveIk inverts.
Eigen::Matrix4d ModelPoseAtReadings(const Chain& chain,
                                    const std::vector<double>& readings,
                                    const IkContext& context,
                                    bool use_error_model = true);

// The approach directions of a move from `from` to `to` (readings), keeping
// `previous`'s sign for joints that do not move (the spec's rule for s).
std::vector<double> ApproachDirections(const std::vector<double>& from,
                                       const std::vector<double>& to,
                                       const std::vector<double>& previous);

// Limits of a robot's joints (reading units, NaN where absent).
std::vector<std::array<double, 2>> JointLimits(const Robot& robot);

}  // namespace kincal

#endif  // KINCAL_CALIB_INVERSE_KINEMATICS_H_
