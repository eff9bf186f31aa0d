#ifndef KINCAL_PLAN_PLAN_H_
#define KINCAL_PLAN_PLAN_H_

// Pose planning for calibration (`kincal plan`): which N robot poses to
// visit so that the identifiable parameters are best determined.
//
// Design of experiments on the identification Jacobian J (3 rows per pose:
// the tip in the measuring frame, columns = the identifiable parameters and
// the measuring frame, as calib/fit.h's ResidualJacobian). The criterion is
// D-optimality, log det(J^T J) (equivalently the product of the singular
// values, Borm and Menq's O1 to the power of the parameter count): it is
// invariant to the units of the parameters and it is the volume of the
// confidence ellipsoid. Candidates are random feasible poses (within joint
// limits less `limit_margin` of each range, the links' capsules clear of
// the obstacles and of each other (plan/safety.h) and, with a rig, every
// candidate has at least `min_tags` tags of the target fully visible, not
// too oblique and not too small in both cameras); the design is built greedily
// and then improved by Fedorov exchange (swap a design pose for a candidate
// while log det grows). The chosen poses are ordered as a short path
// (nearest-neighbour tour plus 2-opt on the joint motion, each joint normalised
// by its range).
//
// Predictions assume independent Gaussian noise of `noise_mm` on each
// coordinate of each measured tip: Cov = noise^2 (J^T J)^-1. The predicted
// tip error is the RMS over evaluation poses (random feasible ones) of the
// calibrated model's tip error, sqrt(trace(J_e Cov J_e^T)).
//
// Fixed-point mode (the seed's single-point experiment): the tip is held at
// one point (chosen near the middle of the feasible tips) and the needle
// orientation varies; candidates come from position inverse kinematics from
// random starts; the measurement is the point constraint (no x, y, z).

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "calib/model_state.h"
#include "camcal/rig.h"
#include "data/robot.h"
#include "plan/coverage.h"
#include "plan/safety.h"
#include "vision/target.h"

namespace kincal {

struct PlanOptions {
  int n = 60;                  // poses to plan
  uint64_t seed = 1;           // all randomness
  int candidates = 2000;       // feasible random candidates to choose from
  int evaluation_poses = 300;  // for the predicted tip error
  double noise_mm = 0.05;      // per coordinate of a measured tip
  bool fixed_point = false;    // the seed's single-point experiment
  int max_swap_passes = 20;    // Fedorov exchange passes
  // Told the stage being computed (may be empty).
  std::function<void(const std::string&)> progress;
  // kDOptimal: maximise log det(J^T J). kSigma: minimise the product of the
  // predicted sigmas of the robot's parameters (frame / point excluded).
  // kCoverage: a campaign for `diagnose model`: every joint's readings
  // spread over its travel (plan/coverage.h CoverageDesign), so that joint
  // errors along the travel are supported everywhere.
  enum Criterion { kDOptimal, kSigma, kCoverage };
  Criterion criterion = kSigma;
  // Candidate poses put each joint at one of its limits with this
  // probability (extreme poses carry the most information).
  double extreme_fraction = 0.3;
  // Every pose keeps this fraction of each joint's range from both limits
  // (extreme candidates go to the limit minus the margin); [0, 0.45].
  double limit_margin = 0.05;
  // Obstacles, link capsules and self-collision (plan/safety.h).
  SafetyOptions safety;

  // Visibility (both set, or neither).
  const Rig* rig = nullptr;
  const Target* target = nullptr;
  // rig_from_base; when absent, the rig is placed looking at the middle of
  // the tips along the mean direction the tags face (see PlaceRigAuto).
  std::optional<Rigid3> rig_from_base;
  double max_obliquity_deg = 60;  // angle between tag normal and view ray
  double margin_px = 10;          // corners at least this far inside
  double min_tag_px = 20;         // shortest projected tag edge
  int min_tags = 1;               // tags visible in both cameras
  // Upper bound on random draws while collecting feasible candidates.
  int max_draws = 2000000;
};

// How good a set of poses is, predicted from the Jacobian.
struct DesignQuality {
  std::vector<double> sigma;  // per PlanResult::params, interface units
  double tip_rms_mm = 0;      // predicted, over the evaluation poses
  double log_det = 0;         // of the Jacobian scaled by the bounds
  // Observability indices of the bound-scaled Jacobian (singular values
  // s_1 >= ... >= s_m, n poses): Borm and Menq's O1 = (s_1...s_m)^(1/m) /
  // sqrt(n), O3 = s_m / s_1 (inverse condition number), Nahvi and
  // Hollerbach's O4 = s_m^2 / s_1 (noise amplification index).
  double o1 = 0, o3 = 0, o4 = 0;
  double joint_travel = 0;  // sum over moves of max_j |dq_j| / range_j
};

struct PlanResult {
  std::vector<std::vector<double>> poses;         // reading units, visit order
  std::vector<std::vector<double>> random_poses;  // N random feasible
  std::vector<ParamInfo> params;  // identifiable, with frame / point
  std::vector<std::string> unidentifiable;
  DesignQuality planned, random;
  // Geometric means of sigma over the robot's own parameters (not frame.*,
  // point.*) in units of their admissible deviation (robot bounds).
  double planned_sigma_gmean = 0, random_sigma_gmean = 0;
  Rigid3 rig_from_base;  // used for visibility (identity without)
  Eigen::Vector3d fixed_point_in_base = Eigen::Vector3d::Zero();
  int feasible_candidates = 0;
  long draws = 0;  // random poses drawn to find them
  // Draws rejected, by constraint: outside the limits minus the margin
  // (fixed point: inverse kinematics solutions; free draws are drawn
  // inside), meeting an obstacle or another link, no tags visible.
  long rejected_limits = 0, rejected_collision = 0, rejected_visibility = 0;
  // Collisions by what was met ("plane 'table'", "self-collision", ...).
  std::map<std::string, long> collisions;
  int swaps = 0;
  // Each joint's travel coverage (plan/coverage.h) by the planned and by
  // the random poses, over the limits minus the margin.
  std::vector<JointCoverage> planned_coverage, random_coverage;
  std::vector<std::vector<double>> evaluation_poses;  // reading units
  double seconds = 0;
};

// Throws InputError when a joint has no limits, n is too small for the
// identifiable parameters, or too few feasible poses are found (the message
// says how many draws each constraint rejected).
PlanResult PlanPoses(const Robot& robot, const PlanOptions& options);

// Number of target tags fully visible in every camera of the rig for a tool
// at rig_from_tool (the criteria of PlanOptions).
int VisibleTags(const Rig& rig, const Target& target,
                const Rigid3& rig_from_tool, const PlanOptions& options);

// Predicted quality of `poses` (reading units) for the parameters of a plan
// (frame or fixed point included as in `result`), on `result`'s evaluation
// poses.
DesignQuality PredictQuality(const Robot& robot, const PlanResult& plan,
                             const std::vector<std::vector<double>>& poses,
                             const PlanOptions& options);

// Orders poses (reading units) as a short open path starting nearest to the
// middle of the joint ranges: nearest neighbour, then 2-opt.
std::vector<std::vector<double>> OrderPoses(
    const Robot& robot, std::vector<std::vector<double>> poses);
double JointTravel(const Robot& robot,
                   const std::vector<std::vector<double>>& poses);

// POSES.csv: "# <command>" then pose,<joint names> and one row per pose.
std::string FormatPosesCsv(const Robot& robot,
                           const std::vector<std::vector<double>>& poses);

}  // namespace kincal

#endif  // KINCAL_PLAN_PLAN_H_
