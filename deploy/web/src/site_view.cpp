#include "crane/web/site_view.hpp"

#include "crane/config/config_document.hpp"
#include "crane/supervisor/supervisor_stage.hpp"

namespace crane::web {

nlohmann::json site_json(const common::StackFacts& facts, const supervisor::SupervisorParams& limits,
                         const std::string& source) {
  using nlohmann::json;
  const auto range = [](double min, double max) { return json{{"min", min}, {"max", max}}; };
  json site{{"source", source},
            {"kind", common::to_string(facts.crane_kind)},
            {"jib_height", facts.site.jib_height},
            {"zone_clearance", facts.site.zone_clearance},
            {"cable_length", range(facts.crane.min_cable_length, facts.crane.max_cable_length)},
            {"trolley", range(limits.trolley_min, limits.trolley_max)}};
  if (facts.crane_kind == common::CraneKind::tower) site["slew"] = range(limits.slew_min, limits.slew_max);
  if (facts.crane_kind == common::CraneKind::overhead) site["bridge"] = range(limits.bridge_min, limits.bridge_max);
  json zones = json::array();
  for (std::size_t i = 0; i < facts.site.zones.size(); ++i) {
    const auto& z = facts.site.zones[i];
    json polygon = json::array();
    for (const auto& p : z.polygon) polygon.push_back({p[0], p[1]});
    zones.push_back({{"index", i}, {"name", z.name}, {"polygon", polygon}, {"bottom", z.bottom}, {"top", z.top},
                     {"enabled_at_start", z.enabled}});
  }
  site["zones"] = zones;
  return site;
}

nlohmann::json site_json_of_config(const std::string& path) {
  const auto document = config::ConfigDocument::load(path);
  const auto limits = document.read("supervisor", supervisor::read_params);
  return site_json(document.facts(), limits, document.source_name());
}

}  // namespace crane::web
