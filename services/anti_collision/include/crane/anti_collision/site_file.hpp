#pragma once
// The site file (deploy/config/site_*.yaml, issue 34) read into anti_collision::SiteLayout: the
// `site:` block, every field required, typed and range-checked (the ranges of validate()), no
// unknown field; then validate(). Errors are common::ConfigError prefixed with the file name, e.g.
//   "site.yaml: site.cranes[0].jib_length = 0 is out of range: must be in [0.1, 200]"
//   "site.yaml: YAML syntax error at line 12: ..."

#include <string>

#include "crane/anti_collision/site_layout.hpp"

namespace crane::anti_collision {

/// Reads `path` (the `site:` block; see deploy/config/site_three_towers.yaml) and validates it.
/// Throws common::ConfigError prefixed with the file name (file missing, YAML syntax naming the
/// line, a field as in validate()).
[[nodiscard]] SiteLayout load_site_layout(const std::string& path);
/// Same, from YAML text (tests); `source_name` prefixes the messages.
[[nodiscard]] SiteLayout parse_site_layout(const std::string& yaml_text, const std::string& source_name);

}  // namespace crane::anti_collision
