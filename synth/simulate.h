#ifndef KINCAL_SYNTH_SIMULATE_H_
#define KINCAL_SYNTH_SIMULATE_H_

// Seeded synthetic sessions for any robot: the true robot is the nominal one
// plus random geometric deviations and optional injected effects from the
// spec's catalogue; poses are random within joint limits or single-point
// groups (the tip held at a fixed point with varying needle orientation, by
// inverse kinematics); measured tip points are given in an unknown measuring
// frame with Gaussian noise.

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "calib/chain.h"
#include "data/observations.h"
#include "data/robot.h"

namespace kincal {

// An injected effect, magnitude in the spec's units:
//   backlash (deg|mm, full width), compliance (deg at the largest |torque| of
//   the poses), cyclic (deg amplitude, random phase; cyclic2 / cyclic3 for
//   the 2nd / 3rd harmonic of the joint angle), gain (1), axis_tilt
//   (deg, Hayati beta of the row before `joint`), drift (mm per hour, random
//   direction), elastostatic (deg at the largest |link-mass torque| of the
//   poses), thermal (mm per hour growth of the joint's row length),
//   mount_compliance (deg base tilt at the largest gravity moment, isotropic).
//   The fixed-point IK and the rendered tip pose ignore thermal and mount.
struct Effect {
  std::string cause;
  std::string joint;  // empty for drift
  double magnitude = 0.0;
};

// Parses "cause:joint:magnitude" (or "drift:magnitude"); InputError if bad.
Effect ParseEffect(const std::string& text, const Robot& robot);

struct SimulateOptions {
  enum Mode { kRandom, kFixedPoint };
  Mode mode = kRandom;
  int poses = 240;               // kRandom: number of poses
  int fixed_points = 1;          // kFixedPoint: number of points
  int poses_per_point = 30;      // kFixedPoint: poses per point
  bool measure_points = true;    // write x,y,z (kFixedPoint may omit them)
  double noise_mm = 0.03;        // per axis, measured points / tip placement
  double sigma_length_mm = 0.5;  // true deviations of geometric parameters
  double sigma_angle_deg = 0.2;
  double frame_distance_mm = 1000.0;  // measuring frame origin from the base
  double seconds_per_pose = 20.0;     // time column t (0 = no t column)
  std::vector<Effect> effects;
  uint64_t seed = 1;
  // When not empty, only these geometric parameters (names as j3.a) deviate
  // from nominal; e.g. to compare estimates with truth parameter by parameter.
  std::vector<std::string> perturbed;
  // When set, the measuring frame meas_from_base ([rotation vector rad, mm])
  // instead of a random one (the random draws still happen, so the rest of
  // the session is the same for the same seed).
  std::optional<std::array<double, 6>> meas_from_base;
  // kRandom: when not empty, these joint readings (file units, robot order,
  // one vector per pose) are the poses, in this order, instead of random
  // ones (`poses` is ignored); the truth is drawn as without them, so a
  // subset of a seed's random poses keeps that seed's true robot.
  std::vector<std::vector<double>> readings;
};

struct SimulatedSession {
  Robot nominal;
  Robot truth;  // true geometry; injected effects as extensions / beta
  std::array<double, 6> meas_from_base{};  // true frame, [rad..., mm...]
  Observations observations;
  std::vector<Effect> effects;  // as injected (magnitudes in spec units)
  // Per effect, the model parameters chosen (e.g. compliance per torque).
  std::vector<std::string> effect_notes;
  // True pose of the tip frame per row (base frame, mm), effects included:
  // what a camera watching the tool sees.
  std::vector<Eigen::Matrix4d> base_from_tip;
};

SimulatedSession Simulate(const Robot& nominal, const SimulateOptions& options);

// Inverse kinematics for position only: joint values (internal units) that
// put the tip of `chain` (with its error models, for pose input `in`) at
// `target_in_base`, starting from `q_start`; Levenberg-Marquardt with
// autodiff. Returns false when it does not converge below `tolerance_mm` or
// leaves the limits (if given, internal units).
bool SolvePositionIk(const Chain& chain, const Eigen::Vector3d& target_in_base,
                     const std::vector<double>& lower,
                     const std::vector<double>& upper, PoseInput* in,
                     double tolerance_mm = 1e-9);

}  // namespace kincal

#endif  // KINCAL_SYNTH_SIMULATE_H_
