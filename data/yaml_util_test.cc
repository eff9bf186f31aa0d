// Tests of the strict YAML reading helpers (data/yaml_util.cc).

#include "data/yaml_util.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>

#include "data/error.h"

namespace kincal {
namespace {

// The InputError text of `f` ("" when it does not throw).
template <typename F>
std::string ErrorOf(F f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(YamlUtilTest, SyntaxErrorsCarryFileLineColumn) {
  const YamlReader r("f.yaml");
  try {
    r.Load("a: 1\nb: [1, 2\n");
    FAIL() << "an unclosed list parsed";
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), "f.yaml");
    EXPECT_GE(e.line(), 2) << e.what();  // 1-based, at or after the list
    EXPECT_GE(e.column(), 1) << e.what();
  }
}

TEST(YamlUtilTest, FailPointsAtTheNode) {
  const YamlReader r("f.yaml");
  const YAML::Node root = r.Load("a: 1\nb:\n  c: x\n");
  EXPECT_EQ(ErrorOf([&] { r.Fail(root["b"]["c"], "bad c"); }),
            "f.yaml:3:6: bad c");
  EXPECT_EQ(ErrorOf([&] { r.ExpectSequence(root["a"], "a"); }),
            "f.yaml:1:4: a: expected a list [...]");
  EXPECT_EQ(ErrorOf([&] { r.ExpectMap(root["a"], "a"); }),
            "f.yaml:1:4: a: expected a mapping {key: value}");
}

TEST(YamlUtilTest, UnknownAndMissingKeys) {
  const YamlReader r("f.yaml");
  const YAML::Node root = r.Load("name: x\nnmae: y\n");
  const std::string unknown = ErrorOf([&] {
    r.CheckKeys(root, {"name", "joints"}, "robot");
  });
  EXPECT_NE(unknown.find("f.yaml:2:1: robot: unknown key 'nmae'"),
            std::string::npos)
      << unknown;
  EXPECT_NE(unknown.find("name, joints"), std::string::npos) << unknown;
  EXPECT_EQ(ErrorOf([&] { r.Required(root, "joints", "robot"); }),
            "f.yaml:1:1: robot: missing required key 'joints'");
  EXPECT_EQ(r.Required(root, "name", "robot").Scalar(), "x");
}

TEST(YamlUtilTest, NumbersIntegersAndStrings) {
  const YamlReader r("f.yaml");
  const YAML::Node n =
      r.Load("a: 2.5\nb: x\nc: inf\nd: 3\ne: 3.5\nf: [1, 2]\ng: ''\nh: 1e12\n");
  EXPECT_DOUBLE_EQ(r.Number(n["a"], "a"), 2.5);
  EXPECT_NE(ErrorOf([&] {
              r.Number(n["b"], "b");
            }).find("b: expected a number, got 'x'"),
            std::string::npos);
  EXPECT_NE(ErrorOf([&] {
              r.Number(n["c"], "c");
            }).find("c: expected a finite number"),
            std::string::npos);
  EXPECT_DOUBLE_EQ(r.NumberOr(n, "zz", 7.0, "map"), 7.0);
  EXPECT_DOUBLE_EQ(r.NumberOr(n, "a", 7.0, "map"), 2.5);
  EXPECT_EQ(r.Integer(n["d"], "d"), 3);
  EXPECT_NE(
      ErrorOf([&] { r.Integer(n["e"], "e"); }).find("e: expected an integer"),
      std::string::npos);
  EXPECT_NE(
      ErrorOf([&] { r.Integer(n["h"], "h"); }).find("h: integer out of range"),
      std::string::npos);
  EXPECT_EQ(r.String(n["b"], "b"), "x");
  EXPECT_NE(ErrorOf([&] {
              r.String(n["g"], "g");
            }).find("g: expected a non-empty string"),
            std::string::npos);
  EXPECT_EQ(r.Numbers(n["f"], "f", 1, 3), (std::vector<double>{1, 2}));
  EXPECT_NE(ErrorOf([&] {
              r.Numbers(n["f"], "f", 3, 3);
            }).find("f: expected 3 numbers, got 2"),
            std::string::npos);
}

TEST(YamlUtilTest, FormatFixedHasTheGivenDecimals) {
  EXPECT_EQ(FormatFixed(100.0, 3), "100.000");
  EXPECT_EQ(FormatFixed(-0.3051, 2), "-0.31");
  EXPECT_EQ(FormatFixed(M_PI / 18, 9), "0.174532925");
}

TEST(YamlUtilTest, FormatDoubleIsShortestThatReadsBack) {
  EXPECT_EQ(FormatDouble(0.1), "0.1");
  EXPECT_EQ(FormatDouble(90), "90");
  EXPECT_EQ(FormatDouble(-1.5e-7), "-1.5e-07");
  for (double v : {1.0 / 3, 123.456789012345, 1e300, -0.0}) {
    EXPECT_EQ(std::strtod(FormatDouble(v).c_str(), nullptr), v) << v;
  }
}

}  // namespace
}  // namespace kincal
