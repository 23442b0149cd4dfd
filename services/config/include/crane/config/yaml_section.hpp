#pragma once
// Strict reading of one YAML mapping: every field required, typed, range-checked, and no unknown
// field tolerated (a typo is an error, not a silently ignored setting). Errors are
// crane::common::ConfigError whose message names the full dotted field, the value and the bound.

#include <yaml-cpp/yaml.h>

#include <array>
#include <set>
#include <string>

namespace crane::config {

class YamlSection {
 public:
  /// `path` is the dotted name of this mapping ("" for the document root). Throws
  /// common::ConfigError when `node` is not a mapping, or when a key appears twice in it (naming the
  /// field and both lines: YAML parsers keep one of the two silently).
  YamlSection(YAML::Node node, std::string path);

  /// Required number in [lower, upper]. Throws ConfigError if missing, not a number, or out of range.
  double number(const std::string& key, double lower, double upper);
  /// Required integer in [lower, upper].
  int integer(const std::string& key, int lower, int upper);
  /// Required boolean.
  bool flag(const std::string& key);
  /// Required string; when `allowed` is not empty the value must be one of them.
  std::string text(const std::string& key, const std::set<std::string>& allowed = {});
  /// Required nested mapping.
  YamlSection child(const std::string& key);
  /// Required sequence of [x, y] pairs of finite numbers (a polygon's vertices).
  std::vector<std::array<double, 2>> points(const std::string& key);
  /// Required sequence of mappings.
  std::vector<YamlSection> list(const std::string& key);
  /// Throws ConfigError naming the first field that was never read (unknown field).
  void finish() const;

  [[nodiscard]] std::string field(const std::string& key) const;

 private:
  YAML::Node required(const std::string& key);
  YAML::Node node_;
  std::string path_;
  std::set<std::string> read_;
};

}  // namespace crane::config
