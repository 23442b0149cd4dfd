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
//              "waiting": bool, "waits_for": ["tc2", ...], "wait_reason": null (it waits for none) |
//              "held" | "starving" | "higher_cable" | "most_work_left" (SiteStatus_'s WAIT_*), "waited_s": s (how long its
//              request has waited) | null (none pending), "instruction": "go" | "yield" | null,
//              "work_left_s": s (its reported estimate of its jobs left alone) | null (no report),
//              "pose": null | {"slew": rad, "trolley": m, "cable_length": m},
//              "parts": [{"part": "jib", "a": [x, y, z], "b": [x, y, z], "radius": m,
//                         "upright": bool}, ...],
//              "held": [[[x, y], ...], ...], "requested": [[[x, y], ...], ...]}, ...],
//  "pairs": [{"cranes": ["tc1", "tc2"], "distance": m, "parts": ["jib", "cable"],
//             "band": "clear" | "warning" | "slow_down" | "stop"}, ...],
//  "closest": null | {"distance": m, "parts": "tc1.jib-tc2.cable", "at": s}}
//
// parts: crane_geometry.hpp's shapes at the reported pose (capsules; upright: the upright
// cylinder about [a, b] with flat ends, the cable and the load as their measured swing envelope); held, requested: one plan outline per box of the airspace (plan_outline), the held
// one as SiteWatch::held says; band: the margin the distance is under, the site's rule
// (anti_collision::classify) for cranes at rest ("emergency_stop" only for a NaN distance).

//
// The same for Foxglove's 3D panel: site_scene_json, a foxglove.SceneUpdate (JSON encoding) on
// crane_web's channel kSceneTopic, frame "site" (the site frame): one entity per crane
// ("crane/tc1": the mast a cylinder, jib and counter-jib a line list as thick as their capsules,
// the cable a line, the load an upright cylinder of its swing envelope, what the service holds a
// line loop at the jib's height per box, what it asks for a thinner one 5 cm above, a text with the name,
// state and holding, and while its request waits, for whom, why and how long: "tc1 at rest,
// holds rest, waits for tc2 (held, 3 s)") and one with the pairs' distances ("site/distances": a text per pair over
// the middle of the two masts, coloured by its band) and the fixed zones ("site/zones": a line
// loop each on the ground). Entities are replaced by id at each update (lifetime 0).

#include <cstdint>
#include <nlohmann/json.hpp>
#include <string_view>

#include "crane/anti_collision/site_watch.hpp"

namespace crane::web {

/// The site page's view of `watch` at `time` [s] (the clock the watch was fed with). Allocates;
/// does not throw beyond std::bad_alloc.
[[nodiscard]] nlohmann::json site_page_json(const anti_collision::SiteWatch& watch, double time);

/// crane_web's channel of the site's scene (with --site), its schema's name and its JSON schema
/// (the fields site_scene_json writes, Foxglove's SceneUpdate message definition).
inline constexpr std::string_view kSceneTopic = "/site/scene";
inline constexpr std::string_view kSceneSchemaName = "foxglove.SceneUpdate";
[[nodiscard]] std::string_view scene_json_schema() noexcept;

/// The scene of `watch` (see the header), stamped `stamp_ns` [ns since the epoch]. Allocates;
/// does not throw beyond std::bad_alloc.
[[nodiscard]] nlohmann::json site_scene_json(const anti_collision::SiteWatch& watch, std::int64_t stamp_ns);

}  // namespace crane::web
