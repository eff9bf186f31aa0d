#ifndef KINCAL_DIAGNOSE_COMPARE_H_
#define KINCAL_DIAGNOSE_COMPARE_H_

// `kincal diagnose compare BEFORE.csv AFTER.csv --robot R.yaml`: the joint
// clearance check after maintenance (the seed's Fig. 4 -> Fig. 6). Each
// session gets its own fit of frame + identifiable geometry + the clearance
// (backlash width) of every joint whose approach direction changes in the
// data, all jointly; the clearances carry 95 % intervals from the fit's
// covariance. A joint has changed when |b_after - b_before| exceeds
// z * sqrt(sigma_before^2 + sigma_after^2), with z the two-sided 95 % point
// Bonferroni-corrected over the compared joints.
//
// When both sessions have fixed_point labels with measured x,y,z (ISO 9283
// cycles, diagnose/iso9283.h), the ISO 9283 pose accuracy AP and
// repeatability RP of each are added, per pose and their maxima (each
// session's measuring frame registered on its own poses). When no joint's
// clearance can be determined in both sessions (ISO cycles alone: five
// poses), the verdict is "not_determined" and the ISO figures are the
// comparison; without ISO cycles that is an InputError.

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "data/observations.h"
#include "data/robot.h"
#include "diagnose/iso9283.h"
#include "diagnose/model_diagnosis.h"

namespace kincal {

struct JointClearanceChange {
  std::string joint;
  std::string unit;  // deg | mm
  Magnitude before, after;
  double difference = 0.0;  // after - before
  double z = 0.0;           // difference / its sigma
  bool changed = false;
};

struct CompareResult {
  std::vector<JointClearanceChange> joints;
  double z_critical = 0.0;
  double before_sigma0_mm = 0.0, after_sigma0_mm = 0.0;
  std::string verdict;       // "changed" | "unchanged" | "not_determined"
  bool has_iso9283 = false;  // both sessions have ISO 9283 cycles
  Iso9283Result iso9283_before, iso9283_after;
};

CompareResult CompareClearance(const Robot& robot, const Observations& before,
                               const Observations& after);

// The clearance figures, and with ISO 9283 cycles "iso9283": {poses: [{pose,
// ap_before_mm, ap_after_mm, rp_before_mm, rp_after_mm}], ap_max_before_mm,
// ap_max_after_mm, rp_max_before_mm, rp_max_after_mm} (null where a pose is
// in one session only).
nlohmann::json CompareJson(const CompareResult& result);

// The ISO 9283 figures before / after in words (empty without them).
std::string CompareIso9283Text(const CompareResult& result);

// Upper point of the standard normal: z with P(Z > z) = p.
double NormalUpperQuantile(double p);

}  // namespace kincal

#endif  // KINCAL_DIAGNOSE_COMPARE_H_
