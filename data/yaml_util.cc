#include "data/yaml_util.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "data/error.h"

namespace kincal {

YAML::Node YamlReader::Load(const std::string& text) const {
  try {
    return YAML::Load(text);
  } catch (const YAML::ParserException& e) {
    throw InputError(file_, e.mark.line + 1, e.mark.column + 1,
                     "invalid YAML: " + e.msg);
  }
}

void YamlReader::Fail(const YAML::Node& at, const std::string& msg) const {
  const YAML::Mark mark = at.Mark();
  if (mark.line >= 0)
    throw InputError(file_, mark.line + 1, mark.column + 1, msg);
  throw InputError(file_, 0, 0, msg);
}

void YamlReader::ExpectMap(const YAML::Node& node,
                           const std::string& what) const {
  if (!node.IsMap()) Fail(node, what + ": expected a mapping {key: value}");
}

void YamlReader::ExpectSequence(const YAML::Node& node,
                                const std::string& what) const {
  if (!node.IsSequence()) Fail(node, what + ": expected a list [...]");
}

void YamlReader::CheckKeys(const YAML::Node& map,
                           std::initializer_list<const char*> allowed,
                           const std::string& what) const {
  for (const auto& kv : map) {
    const std::string key = kv.first.Scalar();
    bool ok = false;
    for (const char* a : allowed) ok = ok || key == a;
    if (!ok) {
      std::string list;
      for (const char* a : allowed)
        list += std::string(list.empty() ? "" : ", ") + a;
      Fail(kv.first, what + ": unknown key '" + key +
                         "' (expected one of: " + list + ")");
    }
  }
}

const YAML::Node YamlReader::Required(const YAML::Node& map, const char* key,
                                      const std::string& what) const {
  const YAML::Node node = map[key];
  if (!node.IsDefined() || node.IsNull()) {
    Fail(map, what + ": missing required key '" + key + "'");
  }
  return node;
}

double YamlReader::Number(const YAML::Node& node,
                          const std::string& what) const {
  if (!node.IsScalar()) Fail(node, what + ": expected a number");
  const std::string& s = node.Scalar();
  char* end = nullptr;
  const double v = std::strtod(s.c_str(), &end);
  if (s.empty() || end != s.c_str() + s.size()) {
    Fail(node, what + ": expected a number, got '" + s + "'");
  }
  if (!std::isfinite(v)) {
    Fail(node, what + ": expected a finite number, got '" + s + "'");
  }
  return v;
}

double YamlReader::NumberOr(const YAML::Node& map, const char* key,
                            double fallback, const std::string& what) const {
  const YAML::Node node = map[key];
  if (!node.IsDefined() || node.IsNull()) return fallback;
  return Number(node, what + "." + key);
}

int YamlReader::Integer(const YAML::Node& node, const std::string& what) const {
  const double v = Number(node, what);
  if (v != std::floor(v)) Fail(node, what + ": expected an integer");
  // Outside int the cast is undefined (found by fuzz/robot_yaml_fuzz.cc).
  if (!(std::abs(v) <= 2147483647.0)) {
    Fail(node, what + ": integer out of range");
  }
  return static_cast<int>(v);
}

std::string YamlReader::String(const YAML::Node& node,
                               const std::string& what) const {
  if (!node.IsScalar() || node.Scalar().empty()) {
    Fail(node, what + ": expected a non-empty string");
  }
  return node.Scalar();
}

std::vector<double> YamlReader::Numbers(const YAML::Node& node,
                                        const std::string& what, int min_count,
                                        int max_count) const {
  ExpectSequence(node, what);
  const int n = static_cast<int>(node.size());
  if (n < min_count || n > max_count) {
    Fail(node,
         what + ": expected " +
             (min_count == max_count ? std::to_string(min_count)
                                     : std::to_string(min_count) + " to " +
                                           std::to_string(max_count)) +
             " numbers, got " + std::to_string(n));
  }
  std::vector<double> out;
  for (int i = 0; i < n; ++i) {
    out.push_back(Number(node[i], what + "[" + std::to_string(i) + "]"));
  }
  return out;
}

std::string FormatDouble(double value) {
  // %g at the least precision (at least 6) that reads back to the same
  // double: the digits std::to_chars's shortest round trip needs (one call
  // instead of a search over the precisions; a covariance of 150
  // parameters is 22,500 numbers).
  char buf[64];
  const std::to_chars_result r = std::to_chars(buf, buf + sizeof(buf), value,
                                               std::chars_format::scientific);
  int digits = 0;
  for (const char* c = buf; c != r.ptr && *c != 'e'; ++c)
    digits += (*c >= '0' && *c <= '9') ? 1 : 0;
  std::snprintf(buf, sizeof(buf), "%.*g", std::max(6, digits), value);
  return buf;
}

std::string FormatFixed(double value, int digits) {
  char buf[64];
  std::snprintf(buf, sizeof(buf), "%.*f", digits, value);
  return buf;
}

}  // namespace kincal
