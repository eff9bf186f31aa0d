#ifndef KINCAL_REPORT_RESIDUALS_H_
#define KINCAL_REPORT_RESIDUALS_H_

// What a robot model gets wrong on observations, for the report: the 3D
// residual of every usable row in the base frame (measuring frame registered
// as `kincal evaluate` does), and how strongly its size depends on each
// joint, on pairs of joints, on time and temperature.

#include <Eigen/Core>
#include <string>
#include <vector>

#include "calib/fit.h"
#include "data/observations.h"
#include "data/robot.h"

namespace kincal {

struct ResidualSet {
  std::string label;
  std::vector<int> rows;                     // indices in the observations
  std::vector<Eigen::Vector3d> tip_in_base;  // model tip, mm
  std::vector<Eigen::Vector3d> e_in_base;    // model - measured, mm
  std::vector<double> norm_mm;               // |e|
  ErrorStats stats;
};

// Registers the measuring frame (and fixed points) for `robot` held fixed
// and returns its residuals. InputError when nothing can be evaluated.
ResidualSet ComputeResiduals(const Robot& robot, const Observations& obs,
                             const std::string& label);

// Share of the variance of `value` explained by the means of `bins`
// equal-count bins of `x` (correlation ratio eta^2, 0..1).
double ExplainedByBins(const std::vector<double>& x,
                       const std::vector<double>& value, int bins);
// The same over a bins x bins grid of (x, y) (equal-count per axis).
double ExplainedByGrid(const std::vector<double>& x,
                       const std::vector<double>& y,
                       const std::vector<double>& value, int bins);

// Share of the variance of the residual vectors `e` explained by their
// means in a bins x bins equal-count grid of (x, y): sum over cells of
// n_c |mean_c - mean|^2 over sum |e_i - mean|^2. Chance level for
// structure-free data is about (bins^2 - 1) / n.
double VectorExplainedByGrid(const std::vector<double>& x,
                             const std::vector<double>& y,
                             const std::vector<Eigen::Vector3d>& e, int bins);

// The systematic part over (x, y): |mean residual vector| in each cell of a
// bins x bins equal-width grid with at least `min_count` poses. Outputs the
// cell centres, the magnitudes (mm) and the cell size.
void MeanVectorGrid(const std::vector<double>& x, const std::vector<double>& y,
                    const std::vector<Eigen::Vector3d>& e, int bins,
                    int min_count, std::vector<double>* cx,
                    std::vector<double>* cy, std::vector<double>* magnitude,
                    double* cell_w, double* cell_h);

// Mean of `value` in `bins` equal-count bins of `x`: bin centres (mean x) and
// means, for a trend line over a scatter.
void BinnedMeans(const std::vector<double>& x, const std::vector<double>& value,
                 int bins, std::vector<double>* cx, std::vector<double>* mean);

// The seed's Section 3 curves for measured points: each geometry parameter
// alone moved over -range..range (mm | deg) around the robot's value, the
// measuring frame held at its registration, RMS |error| at each offset.
// Parameters named in `skip` and curves flatter than 1e-6 mm are left out.
struct MeasuredCurve {
  std::string name, unit;
  std::vector<double> offsets, rms_mm;
};
std::vector<MeasuredCurve> MeasuredSensitivity(
    const Robot& robot, const Observations& obs, double range, int steps,
    const std::vector<std::string>& skip);

}  // namespace kincal

#endif  // KINCAL_REPORT_RESIDUALS_H_
