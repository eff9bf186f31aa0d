#ifndef KINCAL_DATA_RIGID3_H_
#define KINCAL_DATA_RIGID3_H_

// Rigid transforms and their rotation-vector form.
//
// A rotation vector w (rad) is axis * angle: R = exp([w]x). Six-number pose
// blocks, as the optimisers and the JSON files hold them, are
// (w_x, w_y, w_z, t_x, t_y, t_z).
//
// Two ways from a rotation vector to a matrix, kept apart on purpose:
// - RotationMatrixFromVector (double, Eigen::AngleAxisd) for plain geometry;
// - RotationMatrixFromVectorT (any scalar, also ceres::Jet) for cost
//   functors: the Rodrigues formula with its first-order branch near zero,
//   operation for operation as ceres::AngleAxisToRotationMatrix, so that a
//   pose read back from a parameter block is the one the solver saw.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cmath>
#include <limits>

namespace kincal {

// A rigid transform target_from_source: p_in_target = R * p_in_source + t
// (t in mm at interfaces, or target units during calibration).
struct Rigid3 {
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  Eigen::Vector3d t = Eigen::Vector3d::Zero();

  Eigen::Vector3d operator*(const Eigen::Vector3d& p) const {
    return R * p + t;
  }
  Rigid3 operator*(const Rigid3& b) const { return {R * b.R, R * b.t + t}; }
  Rigid3 Inverse() const { return {R.transpose(), -(R.transpose() * t)}; }
  Eigen::Isometry3d ToIsometry() const {
    Eigen::Isometry3d iso = Eigen::Isometry3d::Identity();
    iso.linear() = R;
    iso.translation() = t;
    return iso;
  }
  // From a 4x4 homogeneous transform (its top 3x4 block).
  static Rigid3 FromMatrix(const Eigen::Matrix4d& m) {
    return {m.block<3, 3>(0, 0), m.block<3, 1>(0, 3)};
  }
};

// The rotation vector (rad) of a rotation matrix; angle in [0, pi].
inline Eigen::Vector3d RotationVectorFromMatrix(const Eigen::Matrix3d& R) {
  const Eigen::AngleAxisd aa(R);
  return aa.axis() * aa.angle();
}

// The rotation matrix of a rotation vector w (rad); identity for w = 0.
inline Eigen::Matrix3d RotationMatrixFromVector(const Eigen::Vector3d& w) {
  if (!(w.norm() > 0)) return Eigen::Matrix3d::Identity();
  return Eigen::AngleAxisd(w.norm(), w.normalized()).toRotationMatrix();
}

// The rotation matrix of the rotation vector w[0..2] (rad), for any scalar
// type (ceres::Jet included). With theta = |w| and n = w / theta:
//   R = cos(theta) I + (1 - cos(theta)) n n^T + sin(theta) [n]x,
// and R = I + [w]x when theta^2 <= machine epsilon (the derivative stays
// exact at w = 0). Same arithmetic as ceres::AngleAxisToRotationMatrix.
template <typename T>
Eigen::Matrix<T, 3, 3> RotationMatrixFromVectorT(const T* w) {
  using std::cos;
  using std::sin;
  using std::sqrt;
  const T one(1.0);
  Eigen::Matrix<T, 3, 3> R;
  const T theta2 = w[0] * w[0] + w[1] * w[1] + w[2] * w[2];
  if (theta2 > T(std::numeric_limits<double>::epsilon())) {
    const T theta = sqrt(theta2);
    const T wx = w[0] / theta;
    const T wy = w[1] / theta;
    const T wz = w[2] / theta;
    const T costheta = cos(theta);
    const T sintheta = sin(theta);
    // clang-format off
    R(0, 0) =     costheta   + wx*wx*(one -    costheta);
    R(1, 0) =  wz*sintheta   + wx*wy*(one -    costheta);
    R(2, 0) = -wy*sintheta   + wx*wz*(one -    costheta);
    R(0, 1) =  wx*wy*(one - costheta)     - wz*sintheta;
    R(1, 1) =     costheta   + wy*wy*(one -    costheta);
    R(2, 1) =  wx*sintheta   + wy*wz*(one -    costheta);
    R(0, 2) =  wy*sintheta   + wx*wz*(one -    costheta);
    R(1, 2) = -wx*sintheta   + wy*wz*(one -    costheta);
    R(2, 2) =     costheta   + wz*wz*(one -    costheta);
    // clang-format on
  } else {
    R(0, 0) = one;
    R(1, 0) = w[2];
    R(2, 0) = -w[1];
    R(0, 1) = -w[2];
    R(1, 1) = one;
    R(2, 1) = w[0];
    R(0, 2) = w[1];
    R(1, 2) = -w[0];
    R(2, 2) = one;
  }
  return R;
}

// The six-number block (rotation vector in rad, translation) of a pose.
inline std::array<double, 6> PoseBlockFromRigid3(const Rigid3& r) {
  const Eigen::Vector3d w = RotationVectorFromMatrix(r.R);
  return {w.x(), w.y(), w.z(), r.t.x(), r.t.y(), r.t.z()};
}

// The pose of a six-number block (rotation vector in rad, translation),
// rotation by RotationMatrixFromVectorT (as the cost functors read it).
inline Rigid3 Rigid3FromPoseBlock(const double* block) {
  return {RotationMatrixFromVectorT(block),
          Eigen::Vector3d(block[3], block[4], block[5])};
}

}  // namespace kincal

#endif  // KINCAL_DATA_RIGID3_H_
