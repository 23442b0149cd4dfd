#pragma once
// The site file (deploy/config/site_*.yaml, issue 34) read into anti_collision::SiteLayout: the
// `site:` block, every field required, typed and range-checked (the ranges of validate()), no
// unknown field; then validate(). Errors are common::ConfigError prefixed with the file name, e.g.
//   "site.yaml: site.cranes[0].jib_length = 0 is out of range: must be in [0.1, 200]"
//   "site.yaml: YAML syntax error at line 12: ..."

#include <filesystem>
#include <string>

#include "crane/anti_collision/crane_site_link.hpp"
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

/// The header line of a crane's job file: one job a line after it, pick and place, angles [rad]
/// and lengths [m].
inline constexpr const char* kSiteJobsHeader =
    "pick_slew_rad,pick_trolley_m,pick_cable_length_m,place_slew_rad,place_trolley_m,place_cable_length_m";

/// A crane's jobs from `path` (kSiteJobsHeader, then a job a line). Throws common::ConfigError
/// prefixed with the file name: missing, another header, a line without 6 fields, a field that is
/// not a finite number ("tc1.csv: line 3: place_trolley_m = 'x' is not a finite number"). Ranges
/// are the site link's to check (CraneSiteLink).
[[nodiscard]] std::vector<SiteJob> load_site_jobs(const std::string& path);
/// Writes `jobs` to `path` in that format (17 significant digits: read back exactly). Throws
/// std::runtime_error when the file cannot be written.
void write_site_jobs(const std::string& path, const std::vector<SiteJob>& jobs);

}  // namespace crane::anti_collision
