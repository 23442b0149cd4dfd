#include "crane/config/yaml_section.hpp"

#include <cmath>
#include <map>

#include "crane/common/validation.hpp"

namespace crane::config {

using common::ConfigError;

YamlSection::YamlSection(YAML::Node node, std::string path) : node_(std::move(node)), path_(std::move(path)) {
  if (!node_.IsMap()) {
    throw ConfigError((path_.empty() ? std::string("the document") : path_) + " must be a mapping of fields");
  }
  std::map<std::string, int> lines;  // key -> line of its first appearance
  for (const auto& entry : node_) {
    const std::string key = entry.first.as<std::string>();
    const int line = entry.first.Mark().line + 1;
    const auto [first, inserted] = lines.emplace(key, line);
    if (!inserted) {
      throw ConfigError("field " + field(key) + " appears twice (lines " + std::to_string(first->second) + " and " +
                        std::to_string(line) + ")");
    }
  }
}

std::string YamlSection::field(const std::string& key) const { return path_.empty() ? key : path_ + "." + key; }

YAML::Node YamlSection::required(const std::string& key) {
  read_.insert(key);
  YAML::Node value = node_[key];
  if (!value.IsDefined() || value.IsNull()) throw ConfigError("missing field " + field(key));
  return value;
}

double YamlSection::number(const std::string& key, double lower, double upper) {
  YAML::Node value = required(key);
  double parsed = 0.0;
  if (!value.IsScalar() || !YAML::convert<double>::decode(value, parsed)) {
    throw ConfigError(field(key) + " = '" + (value.IsScalar() ? value.Scalar() : std::string("<not a scalar>")) +
                      "' is not a number");
  }
  common::require_in_range(field(key), parsed, lower, upper);
  return parsed;
}

int YamlSection::integer(const std::string& key, int lower, int upper) {
  const double value = number(key, lower, upper);
  if (std::floor(value) != value) {
    throw ConfigError(field(key) + " = " + common::format_value(value) + " is not an integer");
  }
  return static_cast<int>(value);
}

bool YamlSection::flag(const std::string& key) {
  YAML::Node value = required(key);
  bool parsed = false;
  if (!value.IsScalar() || !YAML::convert<bool>::decode(value, parsed)) {
    throw ConfigError(field(key) + " = '" + (value.IsScalar() ? value.Scalar() : std::string("<not a scalar>")) +
                      "' is not a boolean (true or false)");
  }
  return parsed;
}

std::string YamlSection::text(const std::string& key, const std::set<std::string>& allowed) {
  YAML::Node value = required(key);
  if (!value.IsScalar()) throw ConfigError(field(key) + " must be a string");
  const std::string parsed = value.Scalar();
  if (!allowed.empty() && allowed.count(parsed) == 0) {
    std::string options;
    for (const auto& a : allowed) options += (options.empty() ? "" : ", ") + a;
    throw ConfigError(field(key) + " = '" + parsed + "' is not one of: " + options);
  }
  return parsed;
}

YamlSection YamlSection::child(const std::string& key) { return YamlSection(required(key), field(key)); }

std::vector<YamlSection> YamlSection::list(const std::string& key) {
  YAML::Node value = required(key);
  if (!value.IsSequence()) throw ConfigError(field(key) + " must be a list");
  std::vector<YamlSection> items;
  for (std::size_t i = 0; i < value.size(); ++i) {
    items.emplace_back(value[i], field(key) + "[" + std::to_string(i) + "]");
  }
  return items;
}

std::vector<std::array<double, 2>> YamlSection::points(const std::string& key) {
  YAML::Node value = required(key);
  if (!value.IsSequence()) throw ConfigError(field(key) + " must be a list of [x, y] pairs");
  std::vector<std::array<double, 2>> points;
  for (std::size_t i = 0; i < value.size(); ++i) {
    const std::string name = field(key) + "[" + std::to_string(i) + "]";
    if (!value[i].IsSequence() || value[i].size() != 2) throw ConfigError(name + " must be an [x, y] pair");
    std::array<double, 2> p{};
    for (std::size_t j = 0; j < 2; ++j) {
      if (!value[i][j].IsScalar() || !YAML::convert<double>::decode(value[i][j], p[j])) {
        throw ConfigError(name + " must be an [x, y] pair of numbers");
      }
      common::require_finite(name, p[j]);
    }
    points.push_back(p);
  }
  return points;
}

void YamlSection::finish() const {
  for (const auto& entry : node_) {
    const std::string key = entry.first.as<std::string>();
    if (read_.count(key) == 0) throw ConfigError("unknown field " + field(key));
  }
}

}  // namespace crane::config
