#ifndef KINCAL_CALIB_FIT_RECORD_H_
#define KINCAL_CALIB_FIT_RECORD_H_

// The record a calibrated robot file carries of what it was fitted on
// (robot.yaml `nominal:`, `fitted_on:`, `covariance:`; data/robot.h
// FitRecord): written by calibrate and diagnose, read by compensate.

#include <Eigen/Core>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "calib/chain.h"
#include "calib/fit.h"
#include "data/observations.h"
#include "data/robot.h"

namespace kincal {

// The largest gap between consecutive readings of one joint.
struct TravelGap {
  double lo = 0.0, hi = 0.0;    // the travel (reading units)
  double from = 0.0, to = 0.0;  // the largest gap between readings
};

// The largest gap between consecutive readings of `joint` (index in
// obs.joint_names) over `rows` (empty = all); from == to with fewer than two
// readings.
TravelGap LargestGap(const Observations& obs, int joint,
                     const std::vector<int>& rows = {});

// A gap wide enough that a function fitted along the travel is not held
// there: over `fraction` of the travel and `min_gap` reading units.
constexpr double kWideGapFraction = 0.1;
constexpr double kWideGapMin = 5.0;
bool IsWideGap(const TravelGap& g, double fraction = kWideGapFraction,
               double min_gap = kWideGapMin);

struct FitRecordInput {
  const Observations* obs = nullptr;  // the rows the model was fitted on
  std::vector<int> rows;              // their indices; empty = all rows
  const FitSummary* fit = nullptr;    // covariance source; may be null
  // Without a FitSummary (fit null): the parameters and their covariance in
  // internal units, in `params`' order (the bundle's); both may be null.
  const std::vector<ParamInfo>* params = nullptr;
  const Eigen::MatrixXd* covariance = nullptr;
  const ModelState* state = nullptr;  // its measuring frame; may be null
  double heldout_rms_mm = std::numeric_limits<double>::quiet_NaN();
  double systematic_rms_mm = std::numeric_limits<double>::quiet_NaN();
};

// The record: the rows' joint travel, its wide gaps (IsWideGap) and the
// temperature range, the thermal
// input (temp_c when the rows' temperatures vary, else hours), the fit's
// measuring frame, the covariance of the robot's and the frame's parameters
// in interface units (fixed points left out: they are not part of the robot;
// the frame stays, as the targets are located through it).
FitRecord MakeFitRecord(const FitRecordInput& input);

// The bases of `chain`'s periodic transmission rows with non-zero
// coefficients (FitRecord
// periodic_bases: kPeriodicTerms rows, columns up to the last non-zero one),
// so a robot file's covariance can name the fitted coefficients
// <joint>.transmission<k>.
std::vector<std::pair<std::string, Eigen::MatrixXd>> PeriodicBases(
    const Chain& chain);

// The inverse on reading: every periodic row of `chain` named in
// rec.periodic_bases gets that basis and the coefficients c with B c = its
// Fourier coefficients (least squares), so the covariance's
// <joint>.transmission<k> address them. Throws InputError when a basis
// names no periodic row or cannot reproduce the row's Fourier coefficients
// (a file edited by hand).
void ApplyPeriodicBases(const FitRecord& rec, Chain* chain);

// `calibrated` with the record and `nominal`'s rows as its nominal.
Robot WithFitRecord(const Robot& calibrated, const Robot& nominal,
                    const FitRecordInput& input);

}  // namespace kincal

#endif  // KINCAL_CALIB_FIT_RECORD_H_
