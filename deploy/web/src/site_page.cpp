#include "crane/web/site_page.hpp"

#include <cmath>
#include <string>

#include "crane/anti_collision/site_messages.hpp"
#include "crane/protocol/messages.hpp"

namespace crane::web {
namespace {

using json = nlohmann::json;
namespace ac = anti_collision;

json outlines(const ac::SiteCrane& crane, const ac::Airspace& airspace) {
  json out = json::array();
  for (std::size_t b = 0; b < airspace.count; ++b) {
    json polygon = json::array();
    for (const auto& p : ac::plan_outline(crane, airspace.boxes[b])) polygon.push_back({p[0], p[1]});
    out.push_back(std::move(polygon));
  }
  return out;
}

const char* band(double distance, const ac::Margins& m) noexcept {
  if (!(distance >= m.stop)) return "stop";
  if (distance < m.slow_down) return "slow_down";
  if (distance < m.warning) return "warning";
  return "clear";
}

}  // namespace

json site_page_json(const ac::SiteWatch& watch, double time) {
  const ac::SiteLayout& layout = watch.layout();
  json out{{"site", layout.name},
           {"time", time},
           {"margins", {{"warning", layout.margins.warning}, {"slow_down", layout.margins.slow_down},
                        {"stop", layout.margins.stop}}}};
  json zones = json::array();
  for (const auto& z : layout.zones) {
    json polygon = json::array();
    for (const auto& p : z.polygon) polygon.push_back({p[0], p[1]});
    zones.push_back({{"name", z.name}, {"polygon", polygon}});
  }
  out["zones"] = zones;
  const auto& status = watch.last_status();
  if (status) {
    out["service"] = {{"epoch", status->epoch},
                      {"heard_s_ago", time - watch.status_heard()},
                      {"yields", status->yields},
                      {"unresolved", status->unresolved},
                      {"reports_refused", status->reports_rejected}};
  } else {
    out["service"] = nullptr;
  }
  json cranes = json::array();
  for (std::size_t i = 0; i < layout.cranes.size(); ++i) {
    const ac::SiteCrane& c = layout.cranes[i];
    const auto& seen = watch.cranes()[i];
    json crane{{"name", c.name},
               {"base", {c.base[0], c.base[1]}},
               {"jib_height", c.jib_height},
               {"reach", c.jib_length},
               {"counter_jib", c.counter_jib_length}};
    crane["state"] = !seen.report ? "silent"
                     : seen.report->state == protocol::SiteReport::STATE_MOVING ? "moving"
                                                                               : "at_rest";
    crane["heard_s_ago"] = seen.report ? json(time - seen.heard) : json(nullptr);
    const bool listed = status && i < status->holding.size() && i < status->crane_count;
    crane["holding"] = listed ? json(std::string(protocol::code_name(protocol::SiteStatus::kCodes, "HOLDING",
                                                                      status->holding[i])))
                              : json(nullptr);
    crane["waiting"] = listed && status->pending[i];
    json waits = json::array();
    for (std::size_t j = 0; listed && j < layout.cranes.size() && j < 32; ++j) {
      if ((status->waits_for[i] & (std::uint32_t{1} << j)) != 0) waits.push_back(layout.cranes[j].name);
    }
    crane["waits_for"] = waits;
    crane["instruction"] = !seen.order                                        ? json(nullptr)
                           : seen.order->kind == ac::Instruction::Kind::go ? json("go")
                                                                            : json("yield");
    json parts = json::array();
    if (seen.report) {
      crane["pose"] = {{"slew", seen.report->slew}, {"trolley", seen.report->trolley},
                       {"cable_length", seen.report->cable_length}};
      const auto envelope = ac::envelope(c, ac::motion_of(*seen.report), ac::StopKind::none);
      for (std::size_t p = 0; p < ac::kPartCount; ++p) {
        const ac::Capsule& k = envelope.samples[0][p];
        parts.push_back({{"part", ac::to_string(static_cast<ac::Part>(p))},
                         {"a", {k.a.x(), k.a.y(), k.a.z()}},
                         {"b", {k.b.x(), k.b.y(), k.b.z()}},
                         {"radius", k.radius}});
      }
    } else {
      crane["pose"] = nullptr;
    }
    crane["parts"] = parts;
    crane["held"] = outlines(c, watch.held(i));
    crane["requested"] = outlines(c, watch.requested(i));
    cranes.push_back(std::move(crane));
  }
  out["cranes"] = cranes;
  json pairs = json::array();
  for (const auto& pair : watch.distances()) {
    pairs.push_back({{"cranes", {layout.cranes[pair.first].name, layout.cranes[pair.second].name}},
                     {"distance", pair.distance.distance},
                     {"parts", {ac::to_string(pair.distance.first), ac::to_string(pair.distance.second)}},
                     {"band", band(pair.distance.distance, layout.margins)}});
  }
  out["pairs"] = pairs;
  out["closest"] = std::isfinite(watch.closest())
                       ? json{{"distance", watch.closest()}, {"parts", watch.closest_parts()}, {"at", watch.closest_time()}}
                       : json(nullptr);
  return out;
}

}  // namespace crane::web
