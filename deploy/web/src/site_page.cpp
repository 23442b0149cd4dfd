#include "crane/web/site_page.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iterator>
#include <limits>
#include <string>
#include <string_view>
#include <vector>

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

// Foxglove's message pieces.
json vec3(double x, double y, double z) { return {{"x", x}, {"y", y}, {"z", z}}; }
json pose_at(double x, double y, double z) {
  return {{"position", vec3(x, y, z)}, {"orientation", {{"x", 0.0}, {"y", 0.0}, {"z", 0.0}, {"w", 1.0}}}};
}
json colour(const double (&rgb)[3], double alpha) {
  return {{"r", rgb[0]}, {"g", rgb[1]}, {"b", rgb[2]}, {"a", alpha}};
}
constexpr double kPalette[][3] = {{0.12, 0.47, 0.71}, {0.84, 0.15, 0.16}, {0.17, 0.63, 0.17}, {0.58, 0.40, 0.74},
                                  {1.00, 0.50, 0.05}, {0.55, 0.34, 0.29}, {0.89, 0.47, 0.76}, {0.09, 0.75, 0.81}};
constexpr std::uint8_t kLineStrip = 0, kLineLoop = 1, kLineList = 2;  // LinePrimitive.type
json line(std::uint8_t type, json points, double thickness, json rgba) {
  return {{"type", type},     {"pose", pose_at(0.0, 0.0, 0.0)}, {"thickness", thickness}, {"scale_invariant", false},
          {"points", points}, {"color", rgba},                  {"colors", json::array()}, {"indices", json::array()}};
}
json text(double x, double y, double z, const std::string& words, json rgba) {
  return {{"pose", pose_at(x, y, z)}, {"billboard", true}, {"font_size", 0.12}, {"scale_invariant", false},
          {"color", rgba},            {"text", words}};
}
json entity(const std::string& id, const json& stamp) {
  json e{{"timestamp", stamp}, {"frame_id", "site"}, {"id", id}, {"lifetime", {{"sec", 0}, {"nsec", 0}}},
         {"frame_locked", false}, {"metadata", json::array()}};
  for (const char* kind : {"arrows", "cubes", "spheres", "cylinders", "lines", "triangles", "texts", "models"}) {
    e[kind] = json::array();
  }
  return e;
}
json loops(const ac::SiteCrane& crane, const ac::Airspace& airspace, double z, double thickness, json rgba) {
  json out = json::array();
  for (std::size_t b = 0; b < airspace.count; ++b) {
    json points = json::array();
    for (const auto& p : ac::plan_outline(crane, airspace.boxes[b])) points.push_back(vec3(p[0], p[1], z));
    out.push_back(line(kLineLoop, points, thickness, rgba));
  }
  return out;
}

// The margin a distance between two cranes at rest is under: the site's rule (classify) with no
// motion to stop, so the emergency-stop envelope is not in question.
const char* band(double distance, const ac::Margins& m) noexcept {
  return ac::to_string(ac::classify(distance, std::numeric_limits<double>::infinity(), m));
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
    const json waits = listed ? json(ac::waits_for_names(layout, *status, i)) : json::array();
    crane["waits_for"] = waits;
    // Why (a WAIT_* name: held, starving, higher_cable, most_work_left) and how long its request has waited [s].
    crane["wait_reason"] = listed && !waits.empty()
                               ? json(std::string(protocol::code_name(protocol::SiteStatus::kCodes, "WAIT",
                                                                      status->wait_reason[i])))
                               : json(nullptr);
    crane["waited_s"] = listed && status->pending[i] ? json(status->waited[i]) : json(nullptr);
    crane["instruction"] = !seen.order                                        ? json(nullptr)
                           : seen.order->kind == ac::Instruction::Kind::go ? json("go")
                                                                            : json("yield");
    json parts = json::array();
    crane["work_left_s"] = seen.report ? json(seen.report->work_left) : json(nullptr);
    if (seen.report) {
      crane["pose"] = {{"slew", seen.report->slew}, {"trolley", seen.report->trolley},
                       {"cable_length", seen.report->cable_length}};
      const auto envelope = ac::envelope(c, ac::motion_of(*seen.report), ac::StopKind::none);
      for (std::size_t p = 0; p < ac::kPartCount; ++p) {
        const ac::Capsule& k = envelope.samples[0][p];
        parts.push_back({{"part", ac::to_string(static_cast<ac::Part>(p))},
                         {"a", {k.a.x(), k.a.y(), k.a.z()}},
                         {"b", {k.b.x(), k.b.y(), k.b.z()}},
                         {"radius", k.radius},
                         {"upright", k.upright}});
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

std::string_view scene_json_schema() noexcept {
  return R"j({"title": "foxglove.SceneUpdate", "type": "object",
 "properties": {"deletions": {"type": "array", "items": {"type": "object"}},
                "entities": {"type": "array", "items": {"type": "object", "properties": {
                  "timestamp": {"type": "object"}, "frame_id": {"type": "string"}, "id": {"type": "string"},
                  "lifetime": {"type": "object"}, "frame_locked": {"type": "boolean"}, "metadata": {"type": "array"},
                  "arrows": {"type": "array"}, "cubes": {"type": "array"}, "spheres": {"type": "array"},
                  "cylinders": {"type": "array"}, "lines": {"type": "array"}, "triangles": {"type": "array"},
                  "texts": {"type": "array"}, "models": {"type": "array"}}}}}})j";
}

json site_scene_json(const ac::SiteWatch& watch, std::int64_t stamp_ns) {
  const ac::SiteLayout& layout = watch.layout();
  const json stamp{{"sec", stamp_ns / 1000000000LL}, {"nsec", stamp_ns % 1000000000LL}};
  const auto& status = watch.last_status();
  json entities = json::array();
  for (std::size_t i = 0; i < layout.cranes.size(); ++i) {
    const ac::SiteCrane& c = layout.cranes[i];
    const auto& seen = watch.cranes()[i];
    const auto& rgb = kPalette[i % std::size(kPalette)];
    json e = entity("crane/" + c.name, stamp);
    e["cylinders"].push_back({{"pose", pose_at(c.base[0], c.base[1], c.jib_height / 2.0)},
                              {"size", vec3(c.mast_width, c.mast_width, c.jib_height)},
                              {"bottom_scale", 1.0},
                              {"top_scale", 1.0},
                              {"color", colour(rgb, seen.report ? 1.0 : 0.3)}});
    std::string label = c.name;
    if (seen.report) {
      const auto parts = ac::envelope(c, ac::motion_of(*seen.report), ac::StopKind::none).samples[0];
      const auto point = [](const ac::Vector3& v) { return vec3(v.x(), v.y(), v.z()); };
      for (const ac::Part p : {ac::Part::jib, ac::Part::counter_jib}) {
        const ac::Capsule& k = parts[static_cast<std::size_t>(p)];
        e["lines"].push_back(line(kLineList, json::array({point(k.a), point(k.b)}), 2.0 * k.radius, colour(rgb, 0.8)));
      }
      const ac::Capsule& cable = parts[static_cast<std::size_t>(ac::Part::cable)];
      e["lines"].push_back(line(kLineStrip, json::array({point(cable.a), point(cable.b)}), 0.01, colour(rgb, 1.0)));
      // The load's envelope, an upright cylinder with flat ends (crane_geometry.hpp).
      const ac::Capsule& load = parts[static_cast<std::size_t>(ac::Part::load)];
      const double d = 2.0 * load.radius;
      e["cylinders"].push_back({{"pose", pose_at(load.a.x(), load.a.y(), (load.a.z() + load.b.z()) / 2.0)},
                                {"size", vec3(d, d, std::abs(load.b.z() - load.a.z()))},
                                {"bottom_scale", 1.0},
                                {"top_scale", 1.0},
                                {"color", colour(rgb, 0.9)}});
      label += seen.report->state == protocol::SiteReport::STATE_MOVING ? " moving" : " at rest";
    } else {
      label += " silent";
    }
    if (status && i < status->holding.size() && i < status->crane_count) {
      label += ", holds " + std::string(protocol::code_name(protocol::SiteStatus::kCodes, "HOLDING", status->holding[i]));
      if (status->pending[i]) {
        // "waits for tc2 (held, 4 s)", as the site page's line says it.
        const auto names = ac::waits_for_names(layout, *status, i);
        std::string who;
        for (const auto& name : names) who += (who.empty() ? "" : ", ") + name;
        char waited[32];
        std::snprintf(waited, sizeof waited, "%.0f s", status->waited[i]);
        label += names.empty() ? ", waits (" + std::string(waited) + ")"
                               : ", waits for " + who + " (" +
                                     std::string(protocol::code_name(protocol::SiteStatus::kCodes, "WAIT",
                                                                     status->wait_reason[i])) +
                                     ", " + waited + ")";
      }
    }
    for (auto& l : loops(c, watch.held(i), c.jib_height, 0.02, colour(rgb, 0.9))) e["lines"].push_back(std::move(l));
    for (auto& l : loops(c, watch.requested(i), c.jib_height + 0.05, 0.01, colour(rgb, 0.4))) e["lines"].push_back(std::move(l));
    e["texts"].push_back(text(c.base[0], c.base[1], c.jib_height + c.jib_depth + 0.3, label, colour(rgb, 1.0)));
    entities.push_back(std::move(e));
  }
  json distances = entity("site/distances", stamp);
  for (const auto& pair : watch.distances()) {
    const ac::SiteCrane& a = layout.cranes[pair.first];
    const ac::SiteCrane& b = layout.cranes[pair.second];
    const char* how = band(pair.distance.distance, layout.margins);
    const double red[3] = {0.9, 0.1, 0.1}, amber[3] = {0.95, 0.55, 0.1}, green[3] = {0.1, 0.6, 0.2};
    const auto& rgb = std::string_view(how) == "clear" ? green : std::string_view(how) == "warning" ? amber : red;
    char words[160];
    std::snprintf(words, sizeof words, "%s-%s %.3f m (%s-%s)", a.name.c_str(), b.name.c_str(), pair.distance.distance,
                  ac::to_string(pair.distance.first), ac::to_string(pair.distance.second));
    distances["texts"].push_back(text((a.base[0] + b.base[0]) / 2.0, (a.base[1] + b.base[1]) / 2.0,
                                      std::max(a.jib_height, b.jib_height) + 0.6, words, colour(rgb, 1.0)));
  }
  entities.push_back(std::move(distances));
  json zones = entity("site/zones", stamp);
  const double grey[3] = {0.5, 0.5, 0.5};
  for (const auto& z : layout.zones) {
    json points = json::array();
    for (const auto& p : z.polygon) points.push_back(vec3(p[0], p[1], 0.0));
    zones["lines"].push_back(line(kLineLoop, points, 0.02, colour(grey, 1.0)));
  }
  entities.push_back(std::move(zones));
  return {{"deletions", json::array()}, {"entities", entities}};
}

}  // namespace crane::web
