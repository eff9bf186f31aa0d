#include "vision/pivot.h"

#include <Eigen/Dense>
#include <cmath>
#include <sstream>

#include "data/error.h"

namespace kincal {
namespace {

// Covariance of the pivot solution, robust to pose errors that differ from
// pose to pose in size and direction: (A^T A)^-1 (sum_i A_i^T e_i e_i^T A_i)
// (A^T A)^-1 over the poses i (3 rows each), e_i = (I - A_i (A^T A)^-1
// A_i^T)^-1 r_i, the residual pose i would have had left out of the fit.
Eigen::MatrixXd PoseClusteredCovariance(const Eigen::MatrixXd& A,
                                        const Eigen::VectorXd& residual,
                                        const Eigen::MatrixXd& ata_inv) {
  Eigen::MatrixXd meat = Eigen::MatrixXd::Zero(6, 6);
  for (int i = 0; i < A.rows() / 3; ++i) {
    const Eigen::Matrix<double, 3, 6> rows = A.middleRows<3>(3 * i);
    const Eigen::Matrix3d keep =
        Eigen::Matrix3d::Identity() - rows * ata_inv * rows.transpose();
    const Eigen::Vector3d left_out =
        keep.ldlt().solve(Eigen::Vector3d(residual.segment<3>(3 * i)));
    const Eigen::Matrix<double, 6, 1> score = rows.transpose() * left_out;
    meat += score * score.transpose();
  }
  return ata_inv * meat * ata_inv;
}

Eigen::Matrix3d Skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return m;
}

// W_i = (B_i C_i B_i^T)^-1, B_i = [-[R_i tip]x  I]: how pose i's errors
// (covariance C_i, order (a, dt)) move its residual R_i tip + t_i - pivot.
std::vector<Eigen::Matrix3d> PoseWeights(
    const std::vector<Rigid3>& rig_from_tool, const Eigen::Vector3d& tip,
    const std::vector<Eigen::Matrix<double, 6, 6>>& covariances) {
  std::vector<Eigen::Matrix3d> weights;
  for (size_t i = 0; i < rig_from_tool.size(); ++i) {
    Eigen::Matrix<double, 3, 6> b;
    b.leftCols<3>() = -Skew(rig_from_tool[i].R * tip);
    b.rightCols<3>() = Eigen::Matrix3d::Identity();
    const Eigen::Matrix3d c = b * covariances[i] * b.transpose();
    weights.push_back(c.ldlt().solve(Eigen::Matrix3d::Identity()));
  }
  // Only the weights' shape matters: scaled to a mean trace of 3 so that
  // residuals keep their size in mm on average.
  double trace = 0;
  for (const Eigen::Matrix3d& w : weights) trace += w.trace();
  for (Eigen::Matrix3d& w : weights) w *= 3.0 * weights.size() / trace;
  return weights;
}

// The stacked system [R_i  -I] x = -t_i, each 3-row block multiplied by
// L_i^T, W_i = L_i L_i^T, so that plain least squares on it is the fit
// weighted by W_i.
void WeightedSystem(const std::vector<Rigid3>& rig_from_tool,
                    const std::vector<Eigen::Matrix3d>& weights,
                    Eigen::MatrixXd* A, Eigen::VectorXd* b) {
  const int n = static_cast<int>(rig_from_tool.size());
  A->resize(3 * n, 6);
  b->resize(3 * n);
  for (int i = 0; i < n; ++i) {
    const Eigen::Matrix3d lt =
        Eigen::LLT<Eigen::Matrix3d>(weights[i]).matrixL().transpose();
    A->block<3, 3>(3 * i, 0) = lt * rig_from_tool[i].R;
    A->block<3, 3>(3 * i, 3) = -lt;
    b->segment<3>(3 * i) = -lt * rig_from_tool[i].t;
  }
}

}  // namespace

double PivotTiltRangeDeg(const std::vector<Rigid3>& rig_from_tool) {
  const int n = static_cast<int>(rig_from_tool.size());
  if (n < 2) return 0;
  // Mean rotation: the nearest rotation to the mean matrix.
  Eigen::Matrix3d sum = Eigen::Matrix3d::Zero();
  for (const Rigid3& p : rig_from_tool) sum += p.R;
  Eigen::JacobiSVD<Eigen::Matrix3d> mean_svd(
      sum, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d mean = mean_svd.matrixU() * mean_svd.matrixV().transpose();
  if (mean.determinant() < 0) return 0;  // rotations all over the sphere
  // Rotation vectors of each pose relative to the mean, in the rig frame.
  Eigen::MatrixXd w(n, 3);
  for (int i = 0; i < n; ++i) {
    w.row(i) = RotationVectorFromMatrix(rig_from_tool[i].R * mean.transpose())
                   .transpose();
  }
  const Eigen::RowVector3d centre = w.colwise().mean();
  const Eigen::MatrixXd centred = w.rowwise() - centre;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(centred.transpose() *
                                                     centred);
  // Eigenvalues ascending: column 1 is the second principal axis.
  const Eigen::VectorXd along = centred * eig.eigenvectors().col(1);
  return (along.maxCoeff() - along.minCoeff()) * 180.0 / M_PI;
}

PivotResult PivotCalibration(
    const std::vector<Rigid3>& rig_from_tool, double min_conditioning,
    double min_tilt_range_deg,
    const std::vector<Eigen::Matrix<double, 6, 6>>& pose_covariances) {
  const int n = static_cast<int>(rig_from_tool.size());
  if (n < 3) {
    throw InputError("pivot calibration: expected at least 3 tool poses, got " +
                     std::to_string(n));
  }
  KINCAL_CHECK(pose_covariances.empty() ||
                   static_cast<int>(pose_covariances.size()) == n,
               "PivotCalibration: one covariance per pose");
  const double tilt = PivotTiltRangeDeg(rig_from_tool);
  if (tilt < min_tilt_range_deg) {
    std::ostringstream os;
    os << "pivot calibration: the tool was tilted over " << tilt
       << " deg in its second direction (at least " << min_tilt_range_deg
       << " deg needed to locate the tip): tilt the tool more around the "
          "divot, at least +-15 deg in two directions";
    throw InputError(os.str());
  }
  PivotResult r;
  r.weights.assign(n, Eigen::Matrix3d::Identity());
  Eigen::MatrixXd A;
  Eigen::VectorXd b;
  WeightedSystem(rig_from_tool, r.weights, &A, &b);
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(
      A, Eigen::ComputeThinU | Eigen::ComputeThinV);
  r.conditioning =
      svd.singularValues()(5) / std::max(svd.singularValues()(0), 1e-300);
  if (!(r.conditioning >= min_conditioning)) {
    std::ostringstream os;
    os << "pivot calibration: the " << n
       << " poses do not determine the tip (conditioning " << r.conditioning
       << " < " << min_conditioning
       << "): tilt the tool about two different axes while pivoting";
    throw InputError(os.str());
  }
  Eigen::VectorXd x = svd.solve(b);
  // The weights depend on the tip: a few rounds from the unweighted one.
  for (int round = 0; round < 3 && !pose_covariances.empty(); ++round) {
    r.weights = PoseWeights(rig_from_tool, x.head<3>(), pose_covariances);
    WeightedSystem(rig_from_tool, r.weights, &A, &b);
    svd.compute(A, Eigen::ComputeThinU | Eigen::ComputeThinV);
    x = svd.solve(b);
  }
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
  r.tilt_range_deg = tilt;
  if (3 * n > 6) {
    // (A^T A)^-1 = V S^-2 V^T of the (weighted) system.
    const Eigen::VectorXd s = svd.singularValues();
    const Eigen::MatrixXd V = svd.matrixV();
    const Eigen::VectorXd inv_s2 = s.array().square().inverse();
    const Eigen::MatrixXd ata_inv = V * inv_s2.asDiagonal() * V.transpose();
    const Eigen::MatrixXd cov = PoseClusteredCovariance(A, b - A * x, ata_inv);
    r.tip_covariance = cov.topLeftCorner<3, 3>();
    for (int k = 0; k < 3; ++k) {
      r.tip_sigma_mm(k) = std::sqrt(cov(k, k));
      r.pivot_sigma_mm(k) = std::sqrt(cov(3 + k, 3 + k));
    }
  }
  return r;
}

Eigen::MatrixXd PivotTipJacobian(const std::vector<Rigid3>& rig_from_tool,
                                 const Eigen::Vector3d& tip_in_tool,
                                 const std::vector<Eigen::Matrix3d>& weights) {
  const int n = static_cast<int>(rig_from_tool.size());
  const std::vector<Eigen::Matrix3d> w =
      weights.empty()
          ? std::vector<Eigen::Matrix3d>(n, Eigen::Matrix3d::Identity())
          : weights;
  // A^T W, and the tip's rows of -(A^T W A)^-1 A^T W.
  Eigen::MatrixXd atw(6, 3 * n);
  for (int i = 0; i < n; ++i) {
    atw.block<3, 3>(0, 3 * i) = rig_from_tool[i].R.transpose() * w[i];
    atw.block<3, 3>(3, 3 * i) = -w[i];
  }
  Eigen::MatrixXd ata = Eigen::MatrixXd::Zero(6, 6);
  for (int i = 0; i < n; ++i) {
    Eigen::Matrix<double, 3, 6> a;
    a.leftCols<3>() = rig_from_tool[i].R;
    a.rightCols<3>() = -Eigen::Matrix3d::Identity();
    ata += atw.middleCols<3>(3 * i) * a;
  }
  const Eigen::MatrixXd solve = -ata.ldlt().solve(atw).topRows(3);
  Eigen::MatrixXd jacobian(3, 6 * n);
  for (int i = 0; i < n; ++i) {
    const Eigen::Matrix3d block = solve.middleCols<3>(3 * i);
    jacobian.middleCols<3>(6 * i) =
        -block * Skew(rig_from_tool[i].R * tip_in_tool);
    jacobian.middleCols<3>(6 * i + 3) = block;
  }
  return jacobian;
}

}  // namespace kincal
