#include "data/extension_kinds.h"

#include <gtest/gtest.h>

namespace kincal {
namespace {

Extension Transmission(std::map<std::string, double> values) {
  Extension e;
  e.cause = "transmission";
  e.joint = "a1";
  e.values = std::move(values);
  return e;
}

TEST(ExtensionKinds, AnyFourierCoefficientMakesATransmissionPeriodic) {
  EXPECT_TRUE(IsPeriodicTransmission(
      Transmission({{"lo", -170}, {"hi", 170}, {"a1", 0.01}})));
  EXPECT_TRUE(IsPeriodicTransmission(
      Transmission({{"lo", -170}, {"hi", 170}, {"b32", 0.0}})));
  EXPECT_TRUE(IsPeriodicTransmission(
      Transmission({{"lo", 0}, {"hi", 1}, {"s1", 0.1}, {"a7", 0.2}})));
}

TEST(ExtensionKinds, SineSeriesOverTheTravelIsNotPeriodic) {
  EXPECT_FALSE(IsPeriodicTransmission(
      Transmission({{"lo", -170}, {"hi", 170}, {"s1", 0.01}, {"s24", 0.02}})));
  EXPECT_FALSE(IsPeriodicTransmission(Transmission({{"lo", 0}, {"hi", 1}})));
  // Outside a1 .. a32 / b1 .. b32: not a Fourier coefficient.
  EXPECT_FALSE(
      IsPeriodicTransmission(Transmission({{"a33", 0.1}, {"b0", 0.1}})));
}

TEST(ExtensionKinds, OnlyTransmissionsArePeriodic) {
  Extension cyclic = Transmission({{"a1", 0.1}, {"cos", 0.01}});
  cyclic.cause = "cyclic";
  EXPECT_FALSE(IsPeriodicTransmission(cyclic));
}

}  // namespace
}  // namespace kincal
