#include "data/rigid3.h"

#include <ceres/jet.h>
#include <ceres/rotation.h>
#include <gtest/gtest.h>

#include <cmath>

namespace kincal {
namespace {

Rigid3 Pose(const Eigen::Vector3d& w, const Eigen::Vector3d& t) {
  return {RotationMatrixFromVector(w), t};
}

TEST(Rigid3Test, QuarterTurnAboutZHasKnownMatrixAndVector) {
  const Eigen::Vector3d w(0, 0, M_PI / 2);
  Eigen::Matrix3d expected;
  expected << 0, -1, 0, 1, 0, 0, 0, 0, 1;
  EXPECT_TRUE(RotationMatrixFromVector(w).isApprox(expected, 1e-15));
  EXPECT_TRUE(RotationMatrixFromVectorT(w.data()).isApprox(expected, 1e-15));
  EXPECT_TRUE(RotationVectorFromMatrix(expected).isApprox(w, 1e-15));
  const Rigid3 r{expected, Eigen::Vector3d(1, 2, 3)};
  EXPECT_TRUE(
      (r * Eigen::Vector3d(1, 0, 0)).isApprox(Eigen::Vector3d(1, 3, 3), 1e-15));
}

TEST(Rigid3Test, ZeroVectorIsIdentity) {
  const Eigen::Vector3d zero = Eigen::Vector3d::Zero();
  EXPECT_EQ(RotationMatrixFromVector(zero), Eigen::Matrix3d::Identity());
  EXPECT_EQ(RotationMatrixFromVectorT(zero.data()),
            Eigen::Matrix3d::Identity());
  EXPECT_EQ(RotationVectorFromMatrix(Eigen::Matrix3d::Identity()), zero);
}

TEST(Rigid3Test, VectorMatrixRoundTrips) {
  for (const Eigen::Vector3d& w :
       {Eigen::Vector3d(0.1, -0.2, 0.3), Eigen::Vector3d(2.0, 1.0, -0.5),
        Eigen::Vector3d(1e-9, 0, 0), Eigen::Vector3d(0, 3.1, 0)}) {
    EXPECT_TRUE(
        RotationVectorFromMatrix(RotationMatrixFromVector(w)).isApprox(w, 1e-9))
        << w.transpose();
    EXPECT_TRUE(RotationMatrixFromVectorT(w.data()).isApprox(
        RotationMatrixFromVector(w), 1e-14))
        << w.transpose();
  }
}

TEST(Rigid3Test, PoseBlockRoundTrip) {
  const Rigid3 r =
      Pose(Eigen::Vector3d(0.4, -0.1, 0.7), Eigen::Vector3d(10, -20, 30));
  const std::array<double, 6> b = PoseBlockFromRigid3(r);
  EXPECT_DOUBLE_EQ(b[3], 10);
  EXPECT_DOUBLE_EQ(b[4], -20);
  EXPECT_DOUBLE_EQ(b[5], 30);
  const Rigid3 back = Rigid3FromPoseBlock(b.data());
  EXPECT_TRUE(back.R.isApprox(r.R, 1e-14));
  EXPECT_EQ(back.t, r.t);
}

TEST(Rigid3Test, CompositionAndInverse) {
  const Rigid3 a =
      Pose(Eigen::Vector3d(0.3, 0.2, -0.1), Eigen::Vector3d(1, 2, 3));
  const Rigid3 b =
      Pose(Eigen::Vector3d(-0.5, 0.1, 0.9), Eigen::Vector3d(-4, 0, 7));
  const Eigen::Vector3d p(0.5, -1.5, 2.5);
  EXPECT_TRUE(((a * b) * p).isApprox(a * (b * p), 1e-14));
  const Rigid3 id = a * a.Inverse();
  EXPECT_TRUE(id.R.isApprox(Eigen::Matrix3d::Identity(), 1e-14));
  EXPECT_LT(id.t.norm(), 1e-14);
  EXPECT_TRUE((a.Inverse() * (a * p)).isApprox(p, 1e-14));
  EXPECT_TRUE(a.ToIsometry().matrix().isApprox(
      (Eigen::Matrix4d() << a.R, a.t, 0, 0, 0, 1).finished()));
  EXPECT_EQ(Rigid3::FromMatrix(a.ToIsometry().matrix()).t, a.t);
}

// Bit for bit the rotation Ceres computes, values and derivatives.
TEST(Rigid3Test, TemplatedMatrixMatchesCeresForJets) {
  using Jet = ceres::Jet<double, 3>;
  for (const Eigen::Vector3d& w :
       {Eigen::Vector3d(0.3, -1.2, 0.4), Eigen::Vector3d(1e-9, 2e-9, 0)}) {
    Jet wj[3];
    for (int i = 0; i < 3; ++i) wj[i] = Jet(w[i], i);
    Jet expected[9];
    ceres::AngleAxisToRotationMatrix(wj, expected);  // column-major
    const Eigen::Matrix<Jet, 3, 3> got = RotationMatrixFromVectorT(wj);
    for (int k = 0; k < 9; ++k) {
      EXPECT_EQ(got.data()[k].a, expected[k].a);
      EXPECT_EQ(got.data()[k].v, expected[k].v);
    }
  }
}

}  // namespace
}  // namespace kincal
