#pragma once
// What the operator page draws of the crane and its surroundings (GET /site.json): the crane's
// kind and dimensions and the no-go zones, from the configuration crane_web is given (--config,
// the file the stack runs with), so the page's top and side views are this crane's and not a
// drawing of the lab's. Which zones are enforced at run time comes from the supervisor's status
// (SupervisorStatus.zones_enabled, bit i: zones[i]); `enabled_at_start` is the configured state.
//
// {"source": "lab_tower_crane.yaml", "kind": "tower" | "gantry" | "overhead",
//  "jib_height": m, "zone_clearance": m,           // site: (the load's height = jib_height - L)
//  "cable_length": {"min": m, "max": m},           // crane: the hoist's range
//  "trolley": {"min": m, "max": m},                // supervisor: the trolley's travel (tower: along the jib)
//  "slew": {"min": rad, "max": rad},               // tower only: the slew's range
//  "bridge": {"min": m, "max": m},                 // overhead only: the bridge's runway travel
//  "zones": [{"index": i, "name": "...", "polygon": [[x, y], ...] (m), "bottom": m, "top": m,
//             "enabled_at_start": bool}, ...]}
// Frame (common/site.hpp): origin on the slew axis (tower) at the ground, x along the jib at slew 0
// (the trolley's axis), y across (an overhead crane's runway), z up.

#include <nlohmann/json.hpp>
#include <string>

#include "crane/common/stack_facts.hpp"
#include "crane/supervisor/supervisor.hpp"

namespace crane::web {

/// The page's geometry from the shared facts (`crane:`, `site:`) and the supervisor's limits
/// (`supervisor:`); `source` names the file. Allocates; does not throw beyond std::bad_alloc.
[[nodiscard]] nlohmann::json site_json(const common::StackFacts& facts, const supervisor::SupervisorParams& limits,
                                       const std::string& source);

/// site_json of the configuration file at `path` (its `stack:`, `crane:`, `site:` and `supervisor:`
/// blocks, read by the stack's own readers). Throws common::ConfigError naming the file and the field.
[[nodiscard]] nlohmann::json site_json_of_config(const std::string& path);

}  // namespace crane::web
