#pragma once
// The site service's memory as a file (site_service --memory FILE; docs/site.md, "The service's
// memory"): what SiteService::memory() returns, written whenever it changes and before the
// instructions of the same step leave, and read by the service started after a crash or a kill
// (SiteService::recall). JSON, one object:
//   {"format": "crane site service memory 1", "site": NAME,
//    "cranes": [{"name": "tc1", "out_of_service": false,
//                "motion": {"slew": rad, "slew_rate": rad/s, "trolley": m, "trolley_velocity": m/s,
//                           "cable_length": m, "cable_rate": m/s, "swing_in_plane": rad,
//                           "swing_out_of_plane": rad, "swing_in_plane_rate": rad/s,
//                           "swing_out_of_plane_rate": rad/s},
//                "place": null | {"moving": bool, "boxes": [[slew_low, slew_high, trolley_low,
//                                   trolley_high, cable_low, cable_high, swing_radius], ...]}}, ...]}
// with every crane of the site file, in its order, by name; angles [rad], lengths [m]. Numbers are
// written with 17 significant digits, so they read back to the bit (a non-finite one is written as
// null, which reads back as an error).

#include <optional>
#include <string>

#include "crane/anti_collision/site_layout.hpp"
#include "crane/anti_collision/site_service.hpp"

namespace crane::anti_collision {

inline constexpr const char* kSiteMemoryFormat = "crane site service memory 1";

/// `memory` of the site `layout` as the file's JSON text. std::invalid_argument when it has another
/// number of cranes than the site.
[[nodiscard]] std::string memory_to_json(const SiteMemory& memory, const SiteLayout& layout);
/// The memory from the file's JSON text. Throws common::ConfigError prefixed with `source_name`,
/// naming the field and the value: not JSON, another format or site, a crane missing, unknown or out
/// of order, a field missing or of the wrong type, a box of other than 7 numbers
/// ("memory.json: cranes[1].place.boxes[0] has 6 numbers: must be 7"). What the values mean is
/// SiteService::recall's to judge (a non-finite or inverted box).
[[nodiscard]] SiteMemory memory_from_json(const std::string& text, const SiteLayout& layout,
                                          const std::string& source_name);
/// Reads `path`: none when it does not exist; else as memory_from_json (ConfigError prefixed with
/// the path, also when it cannot be read).
[[nodiscard]] std::optional<SiteMemory> read_memory_file(const std::string& path, const SiteLayout& layout);
/// Writes `text` to `path` whole or not at all: to PATH.tmp, flushed to the disk, then renamed over
/// PATH. std::runtime_error naming the file and the system's reason when it cannot.
void write_memory_file(const std::string& path, const std::string& text);

}  // namespace crane::anti_collision
