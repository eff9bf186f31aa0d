#include "vision/pivot.h"

#include <Eigen/Dense>
#include <cmath>
#include <sstream>

#include "data/error.h"

namespace kincal {

PivotResult PivotCalibration(const std::vector<Rigid3>& rig_from_tool,
                             double min_conditioning) {
  const int n = static_cast<int>(rig_from_tool.size());
  if (n < 3) {
    throw InputError("pivot calibration: expected at least 3 tool poses, got " +
                     std::to_string(n));
  }
  Eigen::MatrixXd A(3 * n, 6);
  Eigen::VectorXd b(3 * n);
  for (int i = 0; i < n; ++i) {
    A.block<3, 3>(3 * i, 0) = rig_from_tool[i].R;
    A.block<3, 3>(3 * i, 3) = -Eigen::Matrix3d::Identity();
    b.segment<3>(3 * i) = -rig_from_tool[i].t;
  }
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(
      A, Eigen::ComputeThinU | Eigen::ComputeThinV);
  const Eigen::VectorXd s = svd.singularValues();
  PivotResult r;
  r.conditioning = s(s.size() - 1) / s(0);
  if (!(r.conditioning >= min_conditioning)) {
    std::ostringstream os;
    os << "pivot calibration: the " << n
       << " poses do not determine the tip (conditioning " << r.conditioning
       << " < " << min_conditioning
       << "): tilt the tool about two different axes while pivoting";
    throw InputError(os.str());
  }
  const Eigen::VectorXd x = svd.solve(b);
  r.tip_in_tool = x.head<3>();
  r.pivot_in_rig = x.tail<3>();
  double sum = 0;
  for (int i = 0; i < n; ++i) {
    const double e = (rig_from_tool[i] * r.tip_in_tool - r.pivot_in_rig).norm();
    r.residuals_mm.push_back(e);
    sum += e * e;
    r.max_mm = std::max(r.max_mm, e);
  }
  r.rms_mm = std::sqrt(sum / n);
  return r;
}

}  // namespace kincal
