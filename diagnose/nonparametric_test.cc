#include "diagnose/nonparametric.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace kincal {
namespace {

// Residuals that are a smooth function of the first of two inputs (the
// second is noise): the correction names it, predicts most of the power
// in cross-validation and lowers the held-out RMS.
TEST(NonparametricTest, FindsTheInputTheRestDependsOn) {
  std::mt19937_64 rng(4);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::normal_distribution<double> noise(0.0, 0.01);
  SmoothInputs in;
  in.names = {"j1", "j2"};
  std::vector<Eigen::Vector3d> train_res, held_res;
  auto pose = [&](std::vector<std::vector<double>>* x,
                  std::vector<Eigen::Vector3d>* res) {
    const double a = u(rng), b = u(rng);
    x->push_back({a, b});
    res->push_back(Eigen::Vector3d(0.5 * std::sin(3 * a) + noise(rng),
                                   noise(rng), noise(rng)));
  };
  for (int i = 0; i < 300; ++i) pose(&in.train, &train_res);
  for (int i = 0; i < 100; ++i) pose(&in.held, &held_res);
  const SmoothCorrection sc = FitSmoothCorrection(in, train_res, held_res);
  ASSERT_FALSE(sc.depends_on.empty());
  EXPECT_EQ(sc.depends_on.front(), "j1");
  EXPECT_GT(sc.cv_explained, 0.8);
  EXPECT_GT(sc.k, 0);
  EXPECT_LT(sc.heldout_rms_after_mm, 0.5 * sc.heldout_rms_before_mm);
  EXPECT_TRUE(std::isnan(sc.point_cv_explained));  // no measured points
}

// Pure noise: nothing a smooth function predicts.
TEST(NonparametricTest, NoiseExplainsNothing) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::normal_distribution<double> noise(0.0, 0.05);
  SmoothInputs in;
  in.names = {"j1"};
  std::vector<Eigen::Vector3d> train_res, held_res;
  for (int i = 0; i < 200; ++i) {
    in.train.push_back({u(rng)});
    train_res.push_back(Eigen::Vector3d(noise(rng), noise(rng), noise(rng)));
  }
  const SmoothCorrection sc = FitSmoothCorrection(in, train_res, held_res);
  EXPECT_LT(sc.cv_explained, 0.1);
}

}  // namespace
}  // namespace kincal
