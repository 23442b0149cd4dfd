#pragma once
// The site file (deploy/config/site_*.yaml, issue 34) read into anti_collision::SiteLayout: the
// `site:` block, every field required, typed and range-checked (the ranges of validate()), no
// unknown field; then validate(). Errors are common::ConfigError prefixed with the file name, e.g.
//   "site.yaml: site.cranes[0].jib_length = 0 is out of range: must be in [0.1, 200]"
//   "site.yaml: YAML syntax error at line 12: ..."

#include <filesystem>
#include <string>

#include "crane/anti_collision/site_layout.hpp"

namespace crane::anti_collision {

/// Reads `path` (the `site:` block; see deploy/config/site_three_towers.yaml) and validates it.
/// Each crane names its stack config (`config`, relative to the site file's directory), whose
/// planner block (read by trajectory_planner::read_params) gives, through its soft-stop shaper
/// (manual.shaping, swing_damping_ratio), the crane's StoppingData::soft_stop_delay_periods
/// (trajectory_planner::shaper_delay_periods).
/// Throws common::ConfigError prefixed with the file name (file missing, YAML syntax naming the
/// line, a field as in validate(), a crane's config that cannot be read or names no shaping:
/// "site.yaml: site.cranes[0].config = "x.yaml": the crane's config: x.yaml: ...").
[[nodiscard]] SiteLayout load_site_layout(const std::string& path);
/// Same, from YAML text (tests); `source_name` prefixes the messages and the cranes' configs are
/// found in `directory`.
[[nodiscard]] SiteLayout parse_site_layout(const std::string& yaml_text, const std::string& source_name,
                                           const std::filesystem::path& directory);

}  // namespace crane::anti_collision
