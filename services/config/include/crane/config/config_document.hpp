#pragma once
// One configuration file (deploy/config/*.yaml), parsed once, read block by block.
//
// Each stage reads its own block with its own reader (e.g. state_estimator::read_params) and
// receives the facts every stage shares (common::StackFacts: the `stack:` block and the crane),
// which are read here, once. Every block is read strictly (all fields required, typed and
// range-checked, no unknown field); any problem throws common::ConfigError whose message starts
// with the file name and names the field, the value and the bound, e.g.
//   "lab.yaml: crane.load_mass = -2 is out of range: must be in [0, 100000]"
//   "lab.yaml: missing field tracking.proportional_gain"
//   "lab.yaml: YAML syntax error at line 12: ..."

#include <yaml-cpp/yaml.h>

#include <initializer_list>
#include <string>
#include <string_view>
#include <utility>

#include "crane/common/stack_facts.hpp"
#include "crane/common/validation.hpp"
#include "crane/config/yaml_section.hpp"

namespace crane::config {

/// Reads the `crane:` block (every field of common::CraneParameters) and validates it.
[[nodiscard]] common::CraneParameters read_crane(YamlSection& block);
/// Reads the `site:` block (jib_height, zone_clearance, zones: name, polygon [[x, y], ...], bottom, top,
/// enabled). Throws common::ConfigError naming the field or the zone (common::validate(Site)).
[[nodiscard]] common::Site read_site(YamlSection& block);
/// Reads one zone of a `zones:` list (name, polygon [[x, y], ...], bottom, top, enabled, fixed); the
/// caller validates the zones (common::validate(Site)).
[[nodiscard]] common::Zone read_zone(YamlSection& zone);
/// Parses YAML text whose root must be a mapping. Throws common::ConfigError prefixed with
/// `source_name`: "YAML syntax error at line N: ..." or "the document must be a mapping of fields".
[[nodiscard]] YAML::Node parse_yaml_mapping(const std::string& yaml_text, const std::string& source_name);
/// The whole text of `path`. Throws common::ConfigError "<path>: cannot be read".
[[nodiscard]] std::string read_text_file(const std::string& path);
/// Reads a bridge block (common::BridgeParameters: drive_mass, drive_gain, friction {the six
/// volt-equivalents of the crane's frictions}) and validates it.
[[nodiscard]] common::BridgeParameters read_bridge(YamlSection& block);

class ConfigDocument {
 public:
  /// Reads `path`. Throws common::ConfigError when the file cannot be read, is not YAML (naming the
  /// line), or its `stack:` or `crane:` block is bad.
  [[nodiscard]] static ConfigDocument load(const std::string& path);
  /// The same from YAML text (tests); `source_name` prefixes the messages.
  [[nodiscard]] static ConfigDocument parse(const std::string& yaml_text, const std::string& source_name);

  [[nodiscard]] const std::string& source_name() const noexcept { return source_name_; }
  /// The shared facts: `stack:` (sample period, voltage limit, lockstep hang timeout) and `crane:`.
  [[nodiscard]] const common::StackFacts& facts() const noexcept { return facts_; }

  /// `reader(block, facts())` on the top-level block `name`; the block is then checked for unknown
  /// fields. Any ConfigError (missing block included) is rethrown prefixed with the file name.
  template <class Reader>
  auto read(const std::string& name, Reader&& reader) const {
    return guarded([&] {
      YamlSection root(root_, "");
      YamlSection block = root.child(name);
      auto result = std::forward<Reader>(reader)(block, facts_);
      block.finish();
      return result;
    });
  }

  /// Throws common::ConfigError naming the first top-level block not in `known` (a typo in a block
  /// name is an error, not an ignored block). The whole-stack loader calls it; a single process
  /// reading its own blocks does not.
  void check_blocks(std::initializer_list<std::string_view> known) const;

  /// `read` on the document's root mapping itself (the whole-stack loader).
  template <class Reader>
  auto read_root(Reader&& reader) const {
    return guarded([&] {
      YamlSection root(root_, "");
      return std::forward<Reader>(reader)(root, facts_);
    });
  }

 private:
  ConfigDocument(YAML::Node root, std::string source_name);
  template <class F>
  auto guarded(F&& f) const {
    try {
      return f();
    } catch (const common::ConfigError& error) {
      throw common::ConfigError(source_name_ + ": " + error.what());
    } catch (const YAML::Exception& error) {
      throw common::ConfigError(source_name_ + ": " + error.what());
    }
  }

  YAML::Node root_;
  std::string source_name_;
  common::StackFacts facts_;
};

}  // namespace crane::config
