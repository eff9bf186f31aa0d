#ifndef KINCAL_DATA_YAML_UTIL_H_
#define KINCAL_DATA_YAML_UTIL_H_

#include <yaml-cpp/yaml.h>

#include <initializer_list>
#include <string>
#include <vector>

namespace kincal {

// Strict helpers for reading YAML documents with file:line:column messages.
// Every failure throws InputError.
class YamlReader {
 public:
  explicit YamlReader(std::string file) : file_(std::move(file)) {}

  // Parses text; syntax errors become InputError with the parser's position.
  YAML::Node Load(const std::string& text) const;

  [[noreturn]] void Fail(const YAML::Node& at, const std::string& msg) const;

  void ExpectMap(const YAML::Node& node, const std::string& what) const;
  void ExpectSequence(const YAML::Node& node, const std::string& what) const;
  // Rejects keys not in `allowed` (typos must not be silently ignored).
  void CheckKeys(const YAML::Node& map,
                 std::initializer_list<const char*> allowed,
                 const std::string& what) const;
  const YAML::Node Required(const YAML::Node& map, const char* key,
                            const std::string& what) const;

  double Number(const YAML::Node& node, const std::string& what) const;
  double NumberOr(const YAML::Node& map, const char* key, double fallback,
                  const std::string& what) const;
  int Integer(const YAML::Node& node, const std::string& what) const;
  std::string String(const YAML::Node& node, const std::string& what) const;
  std::vector<double> Numbers(const YAML::Node& node, const std::string& what,
                              int min_count, int max_count) const;

  const std::string& file() const { return file_; }

 private:
  std::string file_;
};

// Shortest text that reads back to the same double (for writers).
std::string FormatDouble(double value);
// `value` with `digits` decimals ("%.*f"), for messages and fixed-width text.
std::string FormatFixed(double value, int digits);

}  // namespace kincal

#endif  // KINCAL_DATA_YAML_UTIL_H_
