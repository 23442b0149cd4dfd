#pragma once
// What crane_web's site page draws (GET /site/view.json, www/site.html; issue 34, item 5): every
// crane of the site, what the site service holds for it and what it asks for, and the distance
// between every two cranes, from what the site's domain carries (anti_collision::SiteWatch). The
// geometry is computed here, in the site frame of the site file [m]; the page only draws it.
//
// {"site": "lab_three_towers", "time": s (the watch's clock),
//  "margins": {"warning": m, "slow_down": m, "stop": m},
//  "zones": [{"name": "...", "polygon": [[x, y], ...]}, ...],
//  "service": null | {"epoch": n, "heard_s_ago": s, "yields": n, "unresolved": n, "reports_refused": n},
//  "cranes": [{"name": "tc1", "base": [x, y], "jib_height": m, "reach": m (jib length),
//              "counter_jib": m, "state": "at_rest" | "moving" | "silent" (no report yet),
//              "heard_s_ago": s | null, "holding": "rest" | "path" | "yield" | "whole_reach" | null,
//              "waiting": bool, "waits_for": ["tc2", ...], "instruction": "go" | "yield" | null,
//              "pose": null | {"slew": rad, "trolley": m, "cable_length": m},
//              "parts": [{"part": "jib", "a": [x, y, z], "b": [x, y, z], "radius": m}, ...],
//              "held": [[[x, y], ...], ...], "requested": [[[x, y], ...], ...]}, ...],
//  "pairs": [{"cranes": ["tc1", "tc2"], "distance": m, "parts": ["jib", "cable"],
//             "band": "clear" | "warning" | "slow_down" | "stop"}, ...],
//  "closest": null | {"distance": m, "parts": "tc1.jib-tc2.cable", "at": s}}
//
// parts: crane_geometry.hpp's capsules at the reported pose (the load as its measured swing
// envelope); held, requested: one plan outline per box of the airspace (plan_outline), the held
// one as SiteWatch::held says; band: the margin the distance is under (margins.stop first).

#include <nlohmann/json.hpp>

#include "crane/anti_collision/site_watch.hpp"

namespace crane::web {

/// The site page's view of `watch` at `time` [s] (the clock the watch was fed with). Allocates;
/// does not throw beyond std::bad_alloc.
[[nodiscard]] nlohmann::json site_page_json(const anti_collision::SiteWatch& watch, double time);

}  // namespace crane::web
