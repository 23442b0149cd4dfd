#include "crane/config/config_document.hpp"

#include <filesystem>
#include <fstream>
#include <sstream>

namespace crane::config {

using common::ConfigError;

namespace {

common::AxisFriction read_friction(YamlSection s) {
  common::AxisFriction f;
  f.viscous_positive = s.number("viscous_positive", 0.0, 100.0);
  f.viscous_negative = s.number("viscous_negative", 0.0, 100.0);
  f.coulomb_positive = s.number("coulomb_positive", 0.0, 10.0);
  f.coulomb_negative = s.number("coulomb_negative", 0.0, 10.0);
  f.static_positive = s.number("static_positive", 0.0, 10.0);
  f.static_negative = s.number("static_negative", 0.0, 10.0);
  s.finish();
  return f;
}

}  // namespace

common::CraneParameters read_crane(YamlSection& s) {
  common::CraneParameters c;
  c.gravity = s.number("gravity", 9.0, 10.5);
  c.load_mass = s.number("load_mass", 0.0, 1.0e5);
  c.cable_length = s.number("cable_length", 0.05, 200.0);
  c.min_cable_length = s.number("min_cable_length", 0.05, 200.0);
  c.max_cable_length = s.number("max_cable_length", c.min_cable_length, 200.0);
  c.trolley_drive_mass = s.number("trolley_drive_mass", 1e-3, 1.0e6);
  c.trolley_mass = s.number("trolley_mass", 1e-3, 1.0e6);
  c.jib_inertia = s.number("jib_inertia", 1e-4, 1.0e9);
  c.trolley_drive_gain = s.number("trolley_drive_gain", 1e-3, 1.0e3);
  c.slew_drive_gain = s.number("slew_drive_gain", 1e-3, 1.0e3);
  c.trolley_friction = read_friction(s.child("trolley_friction"));
  c.slew_friction = read_friction(s.child("slew_friction"));
  c.dac_bits = s.integer("dac_bits", 8, 24);
  c.dac_range = s.number("dac_range", 0.1, 100.0);
  c.motor_encoder_lines = s.integer("motor_encoder_lines", 1, 1 << 20);
  c.swing_encoder_lines = s.integer("swing_encoder_lines", 1, 1 << 20);
  c.leadscrew_pitch = s.number("leadscrew_pitch", 1e-6, 1.0);
  c.slew_gear_ratio = s.number("slew_gear_ratio", 1e-3, 1.0e4);
  s.finish();
  common::validate(c, "crane");
  return c;
}

common::Zone read_zone(YamlSection& z) {
  common::Zone zone;
  zone.name = z.text("name");
  zone.polygon = z.points("polygon");
  zone.bottom = z.number("bottom", -1.0e3, 1.0e3);
  zone.top = z.number("top", -1.0e3, 1.0e3);
  zone.enabled = z.flag("enabled");
  zone.fixed = z.flag("fixed");
  z.finish();
  return zone;
}

common::Site read_site(YamlSection& s) {
  common::Site site;
  site.jib_height = s.number("jib_height", 0.0, 1.0e3);
  site.zone_clearance = s.number("zone_clearance", 0.0, 100.0);
  for (auto& z : s.list("zones")) site.zones.push_back(read_zone(z));
  s.finish();
  common::validate(site, "site");
  return site;
}

common::BridgeParameters read_bridge(YamlSection& s) {
  common::BridgeParameters b;
  b.drive_mass = s.number("drive_mass", 1e-3, 1.0e7);
  b.drive_gain = s.number("drive_gain", 1e-3, 1.0e3);
  b.friction = read_friction(s.child("friction"));
  s.finish();  // the ranges above are BridgeParameters' (common::validate checks them again in the plant)
  return b;
}

ConfigDocument::ConfigDocument(YAML::Node root, std::string source_name)
    : root_(std::move(root)), source_name_(std::move(source_name)) {
  facts_ = guarded([&] {
    YamlSection document(root_, "");
    common::StackFacts facts;
    YamlSection crane = document.child("crane");
    facts.crane_kind = common::crane_kind_from_string(crane.text("kind", {"tower", "gantry", "overhead"}),
                                                      crane.field("kind"));
    if (facts.crane_kind == common::CraneKind::overhead) {  // elsewhere crane.bridge is an unknown field
      YamlSection bridge = crane.child("bridge");
      facts.bridge = read_bridge(bridge);
      common::validate(facts.bridge, "crane.bridge");
    }
    facts.crane = read_crane(crane);
    YamlSection stack = document.child("stack");
    facts.sample_period = stack.number("sample_period", 1e-4, 0.1);
    facts.voltage_limit = stack.number("voltage_limit", 0.1, 100.0);
    facts.lockstep_hang_timeout = stack.number("lockstep_hang_timeout", 0.1, 3600.0);
    stack.finish();
    if (root_["site"]) {
      YamlSection site = document.child("site");
      facts.site = read_site(site);
      // The zones' geometry (common::load_position, the planner's paths, the supervisor's guard) is
      // the tower crane's: trolley along the jib, slewing. On another crane a zone would be checked
      // at the wrong place, so it is refused rather than silently misplaced.
      if (facts.crane_kind != common::CraneKind::tower && !facts.site.zones.empty()) {
        throw ConfigError("site.zones: no-go zones are implemented for crane.kind = tower only (this crane is " +
                          std::string(common::to_string(facts.crane_kind)) +
                          "): remove the zones or the site block");
      }
    }
    return facts;
  });
}

YAML::Node parse_yaml_mapping(const std::string& yaml_text, const std::string& source_name) {
  YAML::Node root;
  try {
    root = YAML::Load(yaml_text);
  } catch (const YAML::Exception& error) {
    throw ConfigError(source_name + ": YAML syntax error at line " + std::to_string(error.mark.line + 1) + ": " +
                      error.msg);
  }
  if (!root.IsMap()) throw ConfigError(source_name + ": the document must be a mapping of fields");
  return root;
}

std::string read_text_file(const std::string& path) {
  std::ifstream file(path);
  if (!file) throw ConfigError(path + ": cannot be read");
  std::stringstream text;
  text << file.rdbuf();
  return text.str();
}

ConfigDocument ConfigDocument::parse(const std::string& yaml_text, const std::string& source_name) {
  return ConfigDocument(parse_yaml_mapping(yaml_text, source_name), source_name);
}

ConfigDocument ConfigDocument::load(const std::string& path) {
  return parse(read_text_file(path), std::filesystem::path(path).filename().string());
}

void ConfigDocument::check_blocks(std::initializer_list<std::string_view> known) const {
  for (const auto& entry : root_) {
    const std::string key = entry.first.as<std::string>();
    bool found = false;
    for (const auto& k : known) found = found || k == key;
    if (!found) throw ConfigError(source_name_ + ": unknown field " + key);
  }
}

}  // namespace crane::config
