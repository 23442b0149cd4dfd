// Tests of crane::config and crane::stack (the whole file, block by block): the real lab configuration against the dissertation (H. M. Omar,
// "Control of Gantry and Tower Cranes", Virginia Tech 2003), and the messages of bad files.
#include <algorithm>
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <numbers>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "crane/common/validation.hpp"
#include "crane/config/config_document.hpp"
#include "crane/stack/maneuver_run.hpp"
#include "crane/stack/stack_config.hpp"
#include "crane/state_estimator/state_estimator_stage.hpp"

namespace cfg = crane::stack;

namespace {

const std::string kLabConfig = std::string(CRANE_SOURCE_DIR) + "/deploy/config/lab_tower_crane.yaml";

std::string read_text(const std::string& path) {
  std::ifstream file(path);
  EXPECT_TRUE(file.good()) << "cannot open " << path;
  std::stringstream text;
  text << file.rdbuf();
  return text.str();
}

std::vector<std::string> split_lines(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream stream(text);
  for (std::string line; std::getline(stream, line);) lines.push_back(line);
  return lines;
}

std::string trim_left(const std::string& line) {
  const auto first = line.find_first_not_of(' ');
  return first == std::string::npos ? std::string() : line.substr(first);
}

struct Edit {
  std::string text;       // the edited file
  std::size_t line{0};    // 1-based number of the edited line
};

/// Finds the first line whose content (after indentation) starts with `key`, searching from the
/// first line that starts with `anchor` (empty: from the top). Replaces that line's content by
/// `replacement`, keeping its indentation, or deletes the line when `replacement` is nullopt.
/// Fails the test if no such line exists.
Edit edit_line(const std::string& text, const std::string& anchor, const std::string& key,
               const std::optional<std::string>& replacement) {
  auto lines = split_lines(text);
  std::size_t i = 0;
  if (!anchor.empty()) {
    while (i < lines.size() && trim_left(lines[i]).rfind(anchor, 0) != 0) ++i;
  }
  while (i < lines.size() && trim_left(lines[i]).rfind(key, 0) != 0) ++i;
  EXPECT_LT(i, lines.size()) << "no line '" << key << "' after '" << anchor << "'";
  Edit edit;
  edit.line = i + 1;
  if (i < lines.size()) {
    if (replacement) {
      const std::string indent = lines[i].substr(0, lines[i].size() - trim_left(lines[i]).size());
      lines[i] = indent + *replacement;
    } else {
      lines.erase(lines.begin() + static_cast<std::ptrdiff_t>(i));
    }
  }
  for (const auto& line : lines) edit.text += line + "\n";
  return edit;
}

/// The ConfigError message of parsing `text` as "test.yaml", or a marker if nothing was thrown.
std::string error_of(const std::string& text) {
  try {
    (void)cfg::parse_stack_config(text, "test.yaml");
  } catch (const crane::common::ConfigError& error) {
    return error.what();
  }
  return "<no ConfigError thrown>";
}

bool starts_with(const std::string& text, const std::string& prefix) { return text.rfind(prefix, 0) == 0; }
bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

class LabConfigText : public ::testing::Test {
 protected:
  void SetUp() override {
    text_ = read_text(kLabConfig);
    ASSERT_FALSE(text_.empty());
  }
  std::string text_;
};

}  // namespace

TEST(LabConfig, LoadsAndMatchesTheDissertation) {
  const auto c = cfg::load_stack_config(kLabConfig);

  // Section 4.5: m = 2 kg, L = 1 m.
  EXPECT_DOUBLE_EQ(c.facts.crane.load_mass, 2.0);
  EXPECT_DOUBLE_EQ(c.facts.crane.cable_length, 1.0);
  EXPECT_DOUBLE_EQ(c.facts.crane.gravity, 9.8);
  // (4.17): m_t = m/M = 2/22.222 = 0.0900009.
  EXPECT_NEAR(c.facts.crane.mass_ratio(), 0.09, 1e-3);
  // (4.17): m_r = m/J_o = 2/7.143 = 0.27999.
  EXPECT_NEAR(c.facts.crane.load_inertia_ratio(), 0.28, 1e-3);
  // (4.6): M_r = M/J_o = 1.93/7.143 = 0.27020.
  EXPECT_NEAR(c.facts.crane.trolley_inertia_ratio(), 0.27, 2e-3);
  // (4.4), (4.5): drive gains.
  EXPECT_DOUBLE_EQ(c.facts.crane.trolley_drive_gain, 2.0);
  EXPECT_DOUBLE_EQ(c.facts.crane.slew_drive_gain, 1.14);

  // Trolley friction (4.12), static (4.13), in volt-equivalents.
  const auto& tf = c.facts.crane.trolley_friction;
  EXPECT_DOUBLE_EQ(tf.viscous_positive, 1.5);
  EXPECT_DOUBLE_EQ(tf.viscous_negative, 6.0);
  EXPECT_DOUBLE_EQ(tf.coulomb_positive, 0.9);
  EXPECT_DOUBLE_EQ(tf.coulomb_negative, 1.2);
  EXPECT_DOUBLE_EQ(tf.static_positive, 1.0);
  EXPECT_DOUBLE_EQ(tf.static_negative, 1.2);
  // Slew friction (4.16), static (4.15).
  const auto& sf = c.facts.crane.slew_friction;
  EXPECT_DOUBLE_EQ(sf.viscous_positive, 1.5);
  EXPECT_DOUBLE_EQ(sf.viscous_negative, 0.05);
  EXPECT_DOUBLE_EQ(sf.coulomb_positive, 0.7);
  EXPECT_DOUBLE_EQ(sf.coulomb_negative, 0.6);
  EXPECT_DOUBLE_EQ(sf.static_positive, 0.7);
  EXPECT_DOUBLE_EQ(sf.static_negative, 0.6);

  // The compensator's model is the configured crane's friction (cross-check of the wiring).
  EXPECT_DOUBLE_EQ(c.friction_compensation.trolley.friction.viscous_negative, tf.viscous_negative);
  EXPECT_DOUBLE_EQ(c.friction_compensation.slew.friction.coulomb_positive, sf.coulomb_positive);
  // The tracking controller's model ratios are the crane's.
  EXPECT_DOUBLE_EQ(c.tracking.tracking.mass_ratio, c.facts.crane.mass_ratio());
  EXPECT_DOUBLE_EQ(c.tracking.tracking.load_inertia_ratio, c.facts.crane.load_inertia_ratio());
  EXPECT_DOUBLE_EQ(c.tracking.tracking.trolley_inertia_ratio, c.facts.crane.trolley_inertia_ratio());
  // 100 Hz: the estimator's sample rate is 1 / sample_period = 1 / 0.01.
  EXPECT_NEAR(c.state_estimator.estimator.sample_rate, 100.0, 1e-9);

  // One source for each shared fact (stack: and crane:), and every stage gets it from there.
  EXPECT_DOUBLE_EQ(c.facts.sample_period, 0.01);
  EXPECT_DOUBLE_EQ(c.plant.sample_period, c.facts.sample_period);
  EXPECT_DOUBLE_EQ(c.actuation.sample_period, c.facts.sample_period);
  EXPECT_DOUBLE_EQ(c.supervisor.sample_period, c.facts.sample_period);
  EXPECT_DOUBLE_EQ(c.anti_swing.anti_swing.sample_period, c.facts.sample_period);
  EXPECT_DOUBLE_EQ(c.facts.voltage_limit, 10.0);
  EXPECT_DOUBLE_EQ(c.tracking.tracking.voltage_limit, c.facts.voltage_limit);
  EXPECT_DOUBLE_EQ(c.tracking.gain_scheduling.voltage_limit, c.facts.voltage_limit);
  EXPECT_DOUBLE_EQ(c.friction_compensation.voltage_limit, c.facts.voltage_limit);
  EXPECT_DOUBLE_EQ(c.supervisor.voltage_limit, c.facts.voltage_limit);
  EXPECT_DOUBLE_EQ(c.actuation.max_drive_voltage, c.facts.voltage_limit);
  EXPECT_DOUBLE_EQ(c.hardware_bridge.bridge.gate.watchdog_timeout, c.actuation.watchdog_timeout);
  EXPECT_DOUBLE_EQ(c.facts.crane.min_cable_length, 0.2);
  EXPECT_DOUBLE_EQ(c.facts.crane.max_cable_length, 2.0);
  EXPECT_DOUBLE_EQ(c.plant.crane.max_cable_length, c.facts.crane.max_cable_length);
  EXPECT_DOUBLE_EQ(c.trajectory_planner.cable_min_length, c.facts.crane.min_cable_length);
  EXPECT_DOUBLE_EQ(c.trajectory_planner.cable_max_length, c.facts.crane.max_cable_length);
  EXPECT_DOUBLE_EQ(c.anti_swing.anti_swing.min_cable_length, c.facts.crane.min_cable_length);
  EXPECT_DOUBLE_EQ(c.anti_swing.anti_swing.max_cable_length, c.facts.crane.max_cable_length);
  EXPECT_DOUBLE_EQ(c.tracking.tracking.min_cable_length, c.facts.crane.min_cable_length);
  EXPECT_DOUBLE_EQ(c.tracking.gain_scheduling.min_cable_length, c.facts.crane.min_cable_length);
  EXPECT_EQ(c.anti_swing.law, crane::anti_swing::AntiSwingLaw::delay1);

  // Section 3.3.3: trolley (3.54), slew (3.55), combined; then (3.54) while hoisting.
  ASSERT_EQ(c.maneuvers.size(), 4U);
  EXPECT_EQ(c.maneuvers[0].name, "trolley");
  EXPECT_EQ(c.maneuvers[1].name, "slew");
  EXPECT_EQ(c.maneuvers[2].name, "combined");
  EXPECT_EQ(c.maneuvers[3].name, "trolley_hoist");
  for (std::size_t i = 0; i < 3; ++i) EXPECT_DOUBLE_EQ(c.maneuvers[i].cable_length_target, c.facts.crane.cable_length);
  EXPECT_DOUBLE_EQ(c.maneuvers[3].cable_length_target, 1.5);
  // trolley: 0.25 -> 1.0 m, no slew.
  EXPECT_DOUBLE_EQ(c.maneuvers[0].initial_trolley_position, 0.25);
  EXPECT_DOUBLE_EQ(c.maneuvers[0].trolley_target, 1.0);
  EXPECT_DOUBLE_EQ(c.maneuvers[0].slew_target, 0.0);
  // slew: 90 deg = 90 * pi/180 = pi/2 rad, at x = 0.9 m.
  EXPECT_NEAR(c.maneuvers[1].slew_target, std::numbers::pi / 2.0, 1e-12);
  EXPECT_DOUBLE_EQ(c.maneuvers[1].trolley_target, 0.9);
  // combined: both.
  EXPECT_NEAR(c.maneuvers[2].slew_target, std::numbers::pi / 2.0, 1e-12);
  EXPECT_DOUBLE_EQ(c.maneuvers[2].trolley_target, 1.0);
}

TEST_F(LabConfigText, UneditedTextParses) {
  // Control for the edits below: the same text through parse_stack_config is accepted.
  EXPECT_NO_THROW((void)cfg::parse_stack_config(text_, "test.yaml"));
}

TEST_F(LabConfigText, MissingField) {
  auto message = error_of(edit_line(text_, "crane:", "load_mass:", std::nullopt).text);
  EXPECT_TRUE(starts_with(message, "test.yaml: ")) << message;
  EXPECT_TRUE(contains(message, "missing field crane.load_mass")) << message;

  // Nested two levels: friction_compensation.trolley.stiction_slope (the first stiction_slope after
  // "friction_compensation:" is the trolley's).
  message = error_of(edit_line(text_, "friction_compensation:", "stiction_slope:", std::nullopt).text);
  EXPECT_TRUE(starts_with(message, "test.yaml: ")) << message;
  EXPECT_TRUE(contains(message, "missing field friction_compensation.trolley.stiction_slope")) << message;

  // A whole section.
  message = error_of(edit_line(text_, "", "arm_on_start:", std::nullopt).text);
  EXPECT_TRUE(contains(message, "missing field supervisor.arm_on_start")) << message;

  // A field of a maneuver names its list index.
  message = error_of(edit_line(text_, "- name: slew", "duration:", std::nullopt).text);
  EXPECT_TRUE(contains(message, "missing field maneuvers[1].duration")) << message;
}

TEST_F(LabConfigText, OutOfRange) {
  // cable_length must be in [0.05, 200].
  auto message = error_of(edit_line(text_, "crane:", "cable_length:", "cable_length: -1").text);
  EXPECT_TRUE(starts_with(message, "test.yaml: ")) << message;
  EXPECT_TRUE(contains(message, "crane.cable_length = -1")) << message;
  EXPECT_TRUE(contains(message, "must be in")) << message;
  EXPECT_TRUE(contains(message, "[0.05, 200]")) << message;

  // Nested: crane.trolley_friction.coulomb_positive must be in [0, 10].
  message = error_of(edit_line(text_, "trolley_friction:", "coulomb_positive:", "coulomb_positive: 11").text);
  EXPECT_TRUE(starts_with(message, "test.yaml: ")) << message;
  EXPECT_TRUE(contains(message, "crane.trolley_friction.coulomb_positive = 11")) << message;
  EXPECT_TRUE(contains(message, "[0, 10]")) << message;

  // supervisor.stage_timeout must be in [0.005, 5].
  message = error_of(edit_line(text_, "supervisor:", "stage_timeout:", "stage_timeout: 0.001").text);
  EXPECT_TRUE(contains(message, "supervisor.stage_timeout = 0.001")) << message;
  EXPECT_TRUE(contains(message, "[0.005, 5]")) << message;

  // An integer field given a fraction.
  message = error_of(edit_line(text_, "crane:", "dac_bits:", "dac_bits: 12.5").text);
  EXPECT_TRUE(starts_with(message, "test.yaml: ")) << message;
  EXPECT_TRUE(contains(message, "crane.dac_bits = 12.5 is not an integer")) << message;
}

TEST_F(LabConfigText, NotANumber) {
  auto message = error_of(edit_line(text_, "crane:", "load_mass:", "load_mass: two").text);
  EXPECT_TRUE(starts_with(message, "test.yaml: ")) << message;
  EXPECT_TRUE(contains(message, "crane.load_mass")) << message;
  EXPECT_TRUE(contains(message, "'two'")) << message;
  EXPECT_TRUE(contains(message, "not a number")) << message;

  // A boolean field given a number.
  message = error_of(edit_line(text_, "supervisor:", "arm_on_start:", "arm_on_start: 3").text);
  EXPECT_TRUE(contains(message, "supervisor.arm_on_start")) << message;
  EXPECT_TRUE(contains(message, "not a boolean")) << message;
}

TEST_F(LabConfigText, UnknownField) {
  // A typo'd extra field inside a section.
  auto message = error_of(edit_line(text_, "crane:", "load_mass:", "load_mass: 2.0\n  load_mas: 2.0").text);
  EXPECT_TRUE(starts_with(message, "test.yaml: ")) << message;
  EXPECT_TRUE(contains(message, "unknown field")) << message;
  EXPECT_TRUE(contains(message, "crane.load_mas")) << message;

  // An extra top-level section.
  message = error_of(text_ + "hoist:\n  speed: 1.0\n");
  EXPECT_TRUE(starts_with(message, "test.yaml: ")) << message;
  EXPECT_TRUE(contains(message, "unknown field hoist")) << message;
}

TEST_F(LabConfigText, InvalidEnumListsAllowedValues) {
  auto message = error_of(edit_line(text_, "anti_swing:", "controller:", "controller: foo").text);
  EXPECT_TRUE(starts_with(message, "test.yaml: ")) << message;
  EXPECT_TRUE(contains(message, "anti_swing.controller")) << message;
  EXPECT_TRUE(contains(message, "'foo'")) << message;
  for (const char* allowed : {"none", "pd", "delay1", "delay2", "fuzzy"}) {
    EXPECT_TRUE(contains(message, allowed)) << message;
  }

  message = error_of(
      edit_line(text_, "friction_compensation:", "velocity_source:", "velocity_source: smoothed").text);
  EXPECT_TRUE(contains(message, "friction_compensation.trolley.velocity_source")) << message;
  EXPECT_TRUE(contains(message, "raw")) << message;
  EXPECT_TRUE(contains(message, "filtered")) << message;
}

TEST_F(LabConfigText, YamlSyntaxErrorNamesTheLine) {
  // "key: value: more" is an illegal map value; yaml-cpp reports the line of the edit.
  const auto edit = edit_line(text_, "crane:", "load_mass:", "load_mass: 2.0: 3");
  const auto message = error_of(edit.text);
  EXPECT_TRUE(starts_with(message, "test.yaml: ")) << message;
  EXPECT_TRUE(contains(message, "YAML syntax error at line " + std::to_string(edit.line))) << message;
}

// No-go zones: a self-intersecting or empty polygon is refused at start, naming the zone.
TEST_F(LabConfigText, BadZonePolygonsAreRefusedNamingTheZone) {
  auto message = error_of(edit_line(text_, "site:", "polygon:", "polygon: [[0, 0], [1, 1], [1, 0], [0, 1]]").text);
  EXPECT_TRUE(starts_with(message, "test.yaml: ")) << message;
  EXPECT_TRUE(contains(message, "site.zones[0] (control desk): polygon is self-intersecting: edges 0 and 2 cross"))
      << message;
  message = error_of(edit_line(text_, "site:", "polygon:", "polygon: []").text);
  EXPECT_TRUE(contains(message, "site.zones[0] (control desk): polygon has 0 vertices: at least 3")) << message;
  message = error_of(edit_line(text_, "site:", "polygon:", "polygon: [[0, 0], [1, x], [1, 1]]").text);
  EXPECT_TRUE(contains(message, "site.zones[0].polygon[1] must be an [x, y] pair of numbers")) << message;
  // The site is a shared fact: the planner and the supervisor get the same zones.
  const auto config = cfg::load_stack_config(kLabConfig);
  ASSERT_EQ(config.facts.site.zones.size(), 1U);
  EXPECT_EQ(config.trajectory_planner.site.zones.size(), 1U);
  EXPECT_EQ(config.supervisor.site.zones.size(), 1U);
  EXPECT_EQ(config.facts.site.zones[0].name, "control desk");
  EXPECT_FALSE(config.facts.site.zones[0].fixed);
  // A fixed zone (a building, a neighbour's site) is always enforced: fixed and off is refused;
  // fixed and on is read as such.
  message = error_of(edit_line(text_, "site:", "fixed:", "fixed: true").text);
  EXPECT_TRUE(contains(message, "site.zones[0] (control desk): fixed but not enabled")) << message;
  const auto fixed = cfg::parse_stack_config(
      edit_line(edit_line(text_, "site:", "fixed:", "fixed: true").text, "site:", "enabled:", "enabled: true").text,
      "test.yaml");
  EXPECT_TRUE(fixed.supervisor.site.zones[0].fixed);
  message = error_of(edit_line(text_, "site:", "fixed:", "fixed: maybe").text);
  EXPECT_TRUE(contains(message, "site.zones[0].fixed")) << message;
}

TEST(LabConfig, MissingFileNamesThePath) {
  const std::string path = std::string(CRANE_SOURCE_DIR) + "/deploy/config/no_such_crane.yaml";
  try {
    (void)cfg::load_stack_config(path);
    ADD_FAILURE() << "no ConfigError for " << path;
  } catch (const crane::common::ConfigError& error) {
    EXPECT_TRUE(contains(error.what(), path)) << error.what();
  }
}

TEST(LabConfig, EmptyDocumentIsRefused) {
  const auto message = error_of("");
  EXPECT_TRUE(starts_with(message, "test.yaml: ")) << message;
}

// A key given twice is refused with both lines (yaml-cpp itself keeps the first silently).
TEST_F(LabConfigText, DuplicateField) {
  const auto at = text_.find("\n  cable_length:");
  ASSERT_NE(at, std::string::npos);
  const auto line_end = text_.find('\n', at + 1);
  std::string text = text_;
  text.insert(line_end, "\n  cable_length: 1.5");
  const int first_line = static_cast<int>(std::count(text_.begin(), text_.begin() + static_cast<std::ptrdiff_t>(at), '\n')) + 2;
  const auto message = error_of(text);
  EXPECT_TRUE(starts_with(message, "test.yaml: ")) << message;
  EXPECT_TRUE(contains(message, "field crane.cable_length appears twice (lines " + std::to_string(first_line) + " and " +
                                    std::to_string(first_line + 1) + ")"))
      << message;
}

// A process reads only its own blocks: a whole block of another stage missing does not concern it
// (the whole-stack loader refuses the file).
TEST_F(LabConfigText, AProcessReadsItsOwnBlockOnly) {
  std::string text = text_;
  const auto start = text.find("\ntracking:");
  ASSERT_NE(start, std::string::npos);
  const auto end = text.find("\n\n", start + 1);
  text.erase(start + 1, end - start);
  const auto doc = crane::config::ConfigDocument::parse(text, "test.yaml");
  const auto estimator = doc.read("state_estimator", crane::state_estimator::read_params);
  EXPECT_NEAR(estimator.estimator.sample_rate, 100.0, 1e-9);
  EXPECT_TRUE(contains(error_of(text), "missing field tracking")) << error_of(text);
}

// The shared facts are read once: a bad sample period is refused by name, whoever reads.
TEST_F(LabConfigText, SharedFactsAreCheckedWhereTheyAreRead) {
  const auto message = error_of(edit_line(text_, "stack:", "sample_period:", "sample_period: 0").text);
  EXPECT_TRUE(starts_with(message, "test.yaml: ")) << message;
  EXPECT_TRUE(contains(message, "sample_period = 0")) << message;
  EXPECT_TRUE(contains(message, "[0.0001, 0.1]")) << message;
  const auto range = error_of(edit_line(text_, "crane:", "max_cable_length:", "max_cable_length: 0.1").text);
  EXPECT_TRUE(contains(range, "crane.max_cable_length = 0.1")) << range;
}

// The crane kind (crane.kind, a shared fact) and the gantry and overhead configurations (issue 18).
TEST(GantryConfig, LoadsWithTheValuesOfSection322) {
  const auto c = cfg::load_stack_config(std::string(CRANE_SOURCE_DIR) + "/deploy/config/gantry_crane.yaml");
  EXPECT_EQ(c.plant.kind, crane::plant::PlantKind::gantry);
  EXPECT_DOUBLE_EQ(c.facts.crane.trolley_drive_gain, 1.34);  // K_mx
  EXPECT_DOUBLE_EQ(c.facts.crane.cable_length, 1.0);         // L
  EXPECT_GE(c.facts.crane.mass_ratio(), 0.0);                // m_t within the studied 0..5
  EXPECT_LE(c.facts.crane.mass_ratio(), 5.0);
  EXPECT_FALSE(c.anti_swing.anti_swing.slew_enabled);
  for (const auto& m : c.maneuvers) EXPECT_EQ(m.slew_target, 0.0) << m.name;
  crane::plant::CraneSimulator plant(c.plant);  // the plant accepts it
  EXPECT_EQ(plant.model().drive_force_per_volt(crane::plant::DriveAxis::second), 0.0);
}

TEST(OverheadConfig, LoadsWithItsBridge) {
  const auto c = cfg::load_stack_config(std::string(CRANE_SOURCE_DIR) + "/deploy/config/overhead_crane.yaml");
  EXPECT_EQ(c.plant.kind, crane::plant::PlantKind::overhead);
  EXPECT_DOUBLE_EQ(c.plant.bridge.drive_mass, 7500.0);
  EXPECT_DOUBLE_EQ(c.plant.bridge.friction.static_positive, 0.6);
  EXPECT_EQ(c.facts.crane_kind, crane::common::CraneKind::overhead);
  EXPECT_TRUE(c.supervisor.bridge_enabled);
  EXPECT_TRUE(c.trajectory_planner.bridge_enabled);
  EXPECT_TRUE(c.tracking.bridge != nullptr);
  EXPECT_TRUE(c.friction_compensation.bridge.has_value());
  EXPECT_TRUE(c.anti_swing.bridge);
  crane::plant::CraneSimulator plant(c.plant);
  EXPECT_DOUBLE_EQ(plant.model().drive_force_per_volt(crane::plant::DriveAxis::second), 7500.0 * 0.15);
}

// The hardware bridge's channel map follows the crane (issue 18): the bridge's channels are required
// on an overhead crane, each missing one named by its field, and unknown fields on a tower crane;
// the overhead crane has no slew channels.
TEST(OverheadConfig, HardwareBridgeHasTheBridgeChannels) {
  const auto c = cfg::load_stack_config(std::string(CRANE_SOURCE_DIR) + "/deploy/config/overhead_crane.yaml");
  EXPECT_TRUE(c.hardware_bridge.board.axes == crane::hardware_bridge::kOverheadCraneAxes);
  EXPECT_TRUE(c.hardware_bridge.bridge.axes == crane::hardware_bridge::kOverheadCraneAxes);
  EXPECT_FALSE(c.supervisor.slew_enabled);
  using crane::hardware_bridge::AnalogOutput;
  using crane::hardware_bridge::CounterChannel;
  using crane::hardware_bridge::DigitalInput;
  using crane::hardware_bridge::DigitalOutput;
  using crane::hardware_bridge::index;
  const auto& board = c.hardware_bridge.board;
  // Wired where the lab tower crane has its slew's.
  EXPECT_EQ(board.counters[index(CounterChannel::bridge_motor)].subdevice, 0);
  EXPECT_EQ(board.counters[index(CounterChannel::bridge_motor)].channel, 1);
  EXPECT_EQ(board.analog_output_channels[index(AnalogOutput::bridge_drive)], 1);
  EXPECT_EQ(board.digital_output_bits[index(DigitalOutput::brake_release_bridge)], 1);
  EXPECT_EQ(board.digital_input_bits[index(DigitalInput::bridge_min_limit)], 2);
  EXPECT_EQ(board.digital_input_bits[index(DigitalInput::bridge_max_limit)], 3);
  // The tower crane's has the slew's and no bridge.
  const auto lab = cfg::load_stack_config(kLabConfig);
  EXPECT_TRUE(lab.hardware_bridge.board.axes == crane::hardware_bridge::kTowerCraneAxes);
  EXPECT_TRUE(lab.hardware_bridge.bridge.axes == crane::hardware_bridge::kTowerCraneAxes);
  EXPECT_TRUE(lab.supervisor.slew_enabled);
}

// A gantry crane has no slew (issue 18): its configuration names no slew channel and no slew limit,
// loads, and a slew channel or slew limit in it is refused as an unknown field, as a bridge channel
// on a tower crane is; the tower crane's slew channels and limits stay required.
TEST(GantryConfig, HasNoSlewChannelsAndNoSlewLimits) {
  const std::string path = std::string(CRANE_SOURCE_DIR) + "/deploy/config/gantry_crane.yaml";
  const auto c = cfg::load_stack_config(path);
  EXPECT_TRUE(c.hardware_bridge.board.axes == crane::hardware_bridge::kGantryCraneAxes);
  EXPECT_TRUE(c.hardware_bridge.bridge.axes == crane::hardware_bridge::kGantryCraneAxes);
  EXPECT_FALSE(c.supervisor.slew_enabled);
  EXPECT_FALSE(c.supervisor.bridge_enabled);
  const std::string text = read_text(path);
  ASSERT_FALSE(text.empty());
  auto message = error_of(
      edit_line(text, "hardware_bridge:", "swing_out_of_plane:",
                "swing_out_of_plane: {subdevice: 0, channel: 3}\n      slew_motor: {subdevice: 0, channel: 1}")
          .text);
  EXPECT_TRUE(starts_with(message, "test.yaml: ")) << message;
  EXPECT_TRUE(contains(message, "unknown field hardware_bridge.comedi.counters.slew_motor")) << message;
  message = error_of(edit_line(text, "hardware_bridge:", "analog_outputs:",
                               "analog_outputs: {subdevice: 1, range: 0, trolley_drive: 0, slew_drive: 1, hoist_speed: 2}")
                         .text);
  EXPECT_TRUE(contains(message, "unknown field hardware_bridge.comedi.analog_outputs.slew_drive")) << message;
  message = error_of(edit_line(text, "hardware_bridge:", "digital_inputs:",
                               "digital_inputs: {subdevice: 3, active_low: true, trolley_min_limit: 0, "
                               "trolley_max_limit: 1, slew_min_limit: 2, emergency_stop: 4}")
                         .text);
  EXPECT_TRUE(contains(message, "unknown field hardware_bridge.comedi.digital_inputs.slew_min_limit")) << message;
  message = error_of(edit_line(text, "supervisor:", "max_swing:", "max_swing: 0.6\n  slew_max_rate: 2.0").text);
  EXPECT_TRUE(contains(message, "unknown field supervisor.slew_max_rate")) << message;
}

TEST_F(LabConfigText, ASlewChannelOrLimitMissingOnATowerCraneIsNamed) {
  auto message = error_of(edit_line(text_, "hardware_bridge:", "slew_motor:", std::nullopt).text);
  EXPECT_TRUE(starts_with(message, "test.yaml: ")) << message;
  EXPECT_TRUE(contains(message, "missing field hardware_bridge.comedi.counters.slew_motor")) << message;
  message = error_of(edit_line(text_, "supervisor:", "slew_max_rate:", std::nullopt).text);
  EXPECT_TRUE(contains(message, "missing field supervisor.slew_max_rate")) << message;
  message = error_of(edit_line(text_, "supervisor:", "slew_braking_deceleration:", std::nullopt).text);
  EXPECT_TRUE(contains(message, "missing field supervisor.slew_braking_deceleration")) << message;
}

// No-go zones are the tower crane's geometry (trolley along a slewing jib): the lab's site block with
// its zones on the gantry or the overhead crane is refused naming the field and the crane, not
// checked at the wrong place.
TEST(GantryConfig, ZonesOnACraneOtherThanATowerAreRefused) {
  const std::string lab = read_text(kLabConfig);
  const auto begin = lab.find("\nsite:");
  ASSERT_NE(begin, std::string::npos);
  auto end = begin + 1;
  do {  // the block runs to the next top-level field
    end = lab.find('\n', end) + 1;
  } while (end < lab.size() && (lab[end] == ' ' || lab[end] == '#' || lab[end] == '\n'));
  const std::string site = lab.substr(begin, end - begin);
  ASSERT_NE(site.find("zones:"), std::string::npos) << site;
  for (const char* name : {"gantry_crane.yaml", "overhead_crane.yaml"}) {
    const std::string text = read_text(std::string(CRANE_SOURCE_DIR) + "/deploy/config/" + name);
    ASSERT_EQ(text.find("\nsite:"), std::string::npos) << name;
    const std::string message = error_of(text + site);
    EXPECT_TRUE(starts_with(message, "test.yaml: ")) << message;
    EXPECT_TRUE(contains(message, "site.zones: no-go zones are implemented for crane.kind = tower only")) << message;
    EXPECT_TRUE(contains(message, std::string("this crane is ") + (name[0] == 'g' ? "gantry" : "overhead"))) << message;
  }
  EXPECT_NO_THROW(cfg::load_stack_config(kLabConfig));
}

TEST(OverheadConfig, AMissingBridgeChannelIsNamed) {
  const std::string text = read_text(std::string(CRANE_SOURCE_DIR) + "/deploy/config/overhead_crane.yaml");
  ASSERT_FALSE(text.empty());
  ASSERT_EQ(error_of(text), "<no ConfigError thrown>");
  auto message = error_of(edit_line(text, "hardware_bridge:", "bridge_motor:", std::nullopt).text);
  EXPECT_TRUE(starts_with(message, "test.yaml: ")) << message;
  EXPECT_TRUE(contains(message, "missing field hardware_bridge.comedi.counters.bridge_motor")) << message;
  message = error_of(edit_line(text, "hardware_bridge:", "analog_outputs:",
                               "analog_outputs: {subdevice: 1, range: 0, trolley_drive: 0, hoist_speed: 2}")
                         .text);
  EXPECT_TRUE(contains(message, "missing field hardware_bridge.comedi.analog_outputs.bridge_drive")) << message;
  message = error_of(edit_line(text, "hardware_bridge:", "digital_outputs:",
                               "digital_outputs: {subdevice: 2, brake_release_trolley: 0, brake_release_hoist: 2,")
                         .text);
  EXPECT_TRUE(contains(message, "missing field hardware_bridge.comedi.digital_outputs.brake_release_bridge")) << message;
  message = error_of(edit_line(text, "hardware_bridge:", "bridge_min_limit:", "bridge_max_limit: 3,").text);
  EXPECT_TRUE(contains(message, "missing field hardware_bridge.comedi.digital_inputs.bridge_min_limit")) << message;
  message = error_of(edit_line(text, "hardware_bridge:", "bridge_min_limit:", "bridge_min_limit: 2,").text);
  EXPECT_TRUE(contains(message, "missing field hardware_bridge.comedi.digital_inputs.bridge_max_limit")) << message;
  // A slew channel on an overhead crane: an unknown field, as the bridge's on a tower crane.
  message = error_of(edit_line(text, "hardware_bridge:", "swing_in_plane:",
                               "swing_in_plane: {subdevice: 0, channel: 2}\n      slew_motor: {subdevice: 0, channel: 4}")
                         .text);
  EXPECT_TRUE(contains(message, "unknown field hardware_bridge.comedi.counters.slew_motor")) << message;
  // Present but on a line another function uses: named with the value and the other field.
  message = error_of(edit_line(text, "hardware_bridge:", "bridge_motor:", "bridge_motor: {subdevice: 0, channel: 0}").text);
  EXPECT_TRUE(contains(message, "hardware_bridge.comedi.counters[4].channel = 0")) << message;
  EXPECT_TRUE(contains(message, "must differ from hardware_bridge.comedi.counters[0].channel")) << message;
  message = error_of(edit_line(text, "hardware_bridge:", "bridge_min_limit:", "bridge_min_limit: 4, bridge_max_limit: 3,").text);
  EXPECT_TRUE(contains(message, "hardware_bridge.comedi.digital_input_bits[5] = 4")) << message;
}

TEST_F(LabConfigText, ABridgeChannelOnATowerCraneIsAnUnknownField) {
  auto message = error_of(
      edit_line(text_, "hardware_bridge:", "swing_out_of_plane:",
                "swing_out_of_plane: {subdevice: 0, channel: 3}\n      bridge_motor: {subdevice: 0, channel: 4}")
          .text);
  EXPECT_TRUE(starts_with(message, "test.yaml: ")) << message;
  EXPECT_TRUE(contains(message, "unknown field hardware_bridge.comedi.counters.bridge_motor")) << message;
  message = error_of(edit_line(text_, "hardware_bridge:", "drive_enable:", "drive_enable: 3, brake_release_bridge: 4}").text);
  EXPECT_TRUE(contains(message, "unknown field hardware_bridge.comedi.digital_outputs.brake_release_bridge")) << message;
}

TEST_F(LabConfigText, CraneKindIsValidatedLikeTheRest) {
  auto message = error_of(edit_line(text_, "crane:", "kind:", "kind: gantri").text);
  EXPECT_TRUE(starts_with(message, "test.yaml: ")) << message;
  EXPECT_TRUE(contains(message, "crane.kind")) << message;
  EXPECT_TRUE(contains(message, "gantri")) << message;
  for (const char* allowed : {"tower", "gantry", "overhead"}) EXPECT_TRUE(contains(message, allowed)) << message;

  message = error_of(edit_line(text_, "crane:", "kind:", std::nullopt).text);
  EXPECT_TRUE(contains(message, "missing field crane.kind")) << message;

  // An overhead crane needs its bridge; a tower crane has none.
  message = error_of(edit_line(text_, "crane:", "kind:", "kind: overhead").text);
  EXPECT_TRUE(contains(message, "missing field crane.bridge")) << message;
  message = error_of(edit_line(text_, "crane:", "kind:", "kind: tower\n  bridge: {drive_mass: 1.0}").text);
  EXPECT_TRUE(contains(message, "unknown field crane.bridge")) << message;
}

// The online estimation's block (state_estimator.adaptation): every field required and range-checked,
// the error naming the field, the value and the bound; its cross-field rule (max_mass > min_mass) too.
TEST_F(LabConfigText, AdaptationFieldsAreValidatedByName) {
  auto message = error_of(edit_line(text_, "adaptation:", "forgetting_factor:", "forgetting_factor: 1.5").text);
  EXPECT_TRUE(starts_with(message, "test.yaml: ")) << message;
  EXPECT_TRUE(contains(message, "state_estimator.adaptation.forgetting_factor = 1.5")) << message;
  EXPECT_TRUE(contains(message, "[0.9, 1]")) << message;
  message = error_of(edit_line(text_, "adaptation:", "max_reversals:", "max_reversals: 1").text);
  EXPECT_TRUE(contains(message, "state_estimator.adaptation.limit_cycle.max_reversals = 1")) << message;
  message = error_of(edit_line(text_, "adaptation:", "max_mass:", "max_mass: 0").text);
  EXPECT_TRUE(contains(message, "state_estimator.adaptation.max_mass = 0")) << message;
  message = error_of(edit_line(text_, "adaptation:", "filter_cutoff:", std::nullopt).text);
  EXPECT_TRUE(contains(message, "missing field state_estimator.adaptation.filter_cutoff")) << message;
  // The configured load (2 kg) must lie within [min_mass, max_mass].
  message = error_of(edit_line(text_, "adaptation:", "max_mass:", "max_mass: 1.5").text);
  EXPECT_TRUE(contains(message, "state_estimator.adaptation.min_mass, max_mass = [0, 1.5] kg is out of range: "
                                "must contain crane.load_mass = 2 kg"))
      << message;
  message = error_of(edit_line(text_, "adaptation:", "min_mass:", "min_mass: 3").text);
  EXPECT_TRUE(contains(message, "must contain crane.load_mass = 2 kg")) << message;
  message = error_of(edit_line(text_, "adaptation:", "enabled:", "enabled: maybe").text);
  EXPECT_TRUE(contains(message, "state_estimator.adaptation.enabled")) << message;
}

// The equivalent pendulum's block (state_estimator.swing_length): every field required and
// range-checked by name; off in the shipped configs; the stage's facts (kind, crane) filled in.
TEST_F(LabConfigText, SwingLengthFieldsAreValidatedByName) {
  const auto shipped = crane::stack::parse_stack_config(text_, "test.yaml");
  EXPECT_FALSE(shipped.state_estimator.swing_length.enabled);
  EXPECT_EQ(shipped.state_estimator.swing_length.crane_kind, shipped.facts.crane_kind);
  EXPECT_EQ(shipped.state_estimator.swing_length.crane.gravity, shipped.facts.crane.gravity);
  EXPECT_EQ(shipped.state_estimator.swing_length.length_bound, 0.02);
  auto message = error_of(edit_line(text_, "swing_length:", "length_bound:", "length_bound: 0").text);
  EXPECT_TRUE(contains(message, "state_estimator.swing_length.length_bound = 0")) << message;
  message = error_of(edit_line(text_, "swing_length:", "forgetting_factor:", "forgetting_factor: 1.5").text);
  EXPECT_TRUE(contains(message, "state_estimator.swing_length.forgetting_factor = 1.5")) << message;
  message = error_of(edit_line(text_, "swing_length:", "min_swing:", std::nullopt).text);
  EXPECT_TRUE(contains(message, "missing field state_estimator.swing_length.min_swing")) << message;
  message = error_of(edit_line(text_, "swing_length:", "enabled:", "enabled: sometimes").text);
  EXPECT_TRUE(contains(message, "state_estimator.swing_length.enabled")) << message;
}

// The follower's estimator (state_estimator.follower_cutoff_frequency, for_follower): read and
// range-checked like the rest, and it changes the Butterworth's cutoff and nothing else. The lag of
// a ramp, the filter's group delay at DC sqrt2 / (2 pi fc) for a second-order Butterworth, halves
// from 45 ms at the dissertation's 5 Hz to 22.5 ms at 10 Hz.
TEST_F(LabConfigText, TheFollowersFilterCutoffIsReadAndChangesOnlyTheCutoff) {
  const auto c = cfg::parse_stack_config(text_, "test.yaml");
  EXPECT_DOUBLE_EQ(c.state_estimator.estimator.cutoff_frequency, 5.0);  // section 4.3: 0.05 fs
  EXPECT_DOUBLE_EQ(c.state_estimator.follower_cutoff_frequency, 10.0);
  const auto follower = crane::state_estimator::for_follower(c.state_estimator);
  EXPECT_DOUBLE_EQ(follower.estimator.cutoff_frequency, 10.0);
  EXPECT_EQ(follower.estimator.differentiator, c.state_estimator.estimator.differentiator);
  EXPECT_DOUBLE_EQ(follower.estimator.sample_rate, c.state_estimator.estimator.sample_rate);
  EXPECT_EQ(follower.adaptation.enabled, c.state_estimator.adaptation.enabled);
  // Which stacks filter so (the in-process stack and crane_demo ask ControllerChoice): the follower's.
  EXPECT_TRUE(cfg::choose_controller("follower", c.maneuvers[0], false).follower_filter());
  for (const char* other : {"delay1", "delay2", "pd", "none", "gain_scheduling_full"}) {
    EXPECT_FALSE(cfg::choose_controller(other, c.maneuvers[0], false).follower_filter()) << other;
  }

  const auto ramp_lag = [](const crane::state_estimator::StateEstimatorParams& params) {
    crane::state_estimator::StateEstimator estimator(params);
    crane::common::CraneStateEstimate e;
    const double v = 0.4, fs = params.sample_rate;
    double t = 0.0;
    for (int k = 0; k < 300; ++k) {
      t = k / fs;
      EXPECT_EQ(estimator.step(crane::common::CraneMeasurement{v * t, 0.0, 0.0, 0.0, 1.0}, e),
                crane::common::StepStatus::ok);
    }
    return (v * t - e.trolley_position) / v;  // [s]
  };
  const double sqrt2_over_2pi = std::numbers::sqrt2 / (2.0 * std::numbers::pi);
  EXPECT_NEAR(ramp_lag(c.state_estimator.estimator), sqrt2_over_2pi / 5.0, 1e-3);
  EXPECT_NEAR(ramp_lag(follower.estimator), sqrt2_over_2pi / 10.0, 1e-3);

  auto message = error_of(edit_line(text_, "state_estimator:", "follower_cutoff_frequency:",
                                    "follower_cutoff_frequency: 60").text);
  EXPECT_TRUE(contains(message, "state_estimator.follower_cutoff_frequency = 60")) << message;
  EXPECT_TRUE(contains(message, "49.9")) << message;  // the bound, 0.499 fs
  message = error_of(edit_line(text_, "state_estimator:", "follower_cutoff_frequency:", std::nullopt).text);
  EXPECT_TRUE(contains(message, "missing field state_estimator.follower_cutoff_frequency")) << message;
}

TEST_F(LabConfigText, PlantHookAndWindAreOffAndValidatedLikeTheRest) {
  const auto c = cfg::parse_stack_config(text_, "test.yaml");
  EXPECT_FALSE(c.plant.hook.enabled);  // off by default: the dissertation's single pendulum
  EXPECT_FALSE(c.plant.wind.enabled);
  auto message = error_of(edit_line(text_, "hook:", "rigging_length:", "rigging_length: 0").text);
  EXPECT_TRUE(starts_with(message, "test.yaml: ")) << message;
  EXPECT_TRUE(contains(message, "plant.hook.rigging_length = 0")) << message;
  EXPECT_TRUE(contains(message, "[0.001, 10]")) << message;
  message = error_of(edit_line(text_, "wind:", "gust_time_constant:", "gust_time_constant: -2").text);
  EXPECT_TRUE(contains(message, "plant.wind.gust_time_constant = -2")) << message;
  message = error_of(edit_line(text_, "wind:", "seed:", std::nullopt).text);
  EXPECT_TRUE(contains(message, "missing field plant.wind.seed")) << message;
  message = error_of(edit_line(text_, "hook:", "enabled:", "enabled: maybe").text);
  EXPECT_TRUE(contains(message, "plant.hook.enabled")) << message;
  // Enabled, they reach the plant's parameters.
  const auto on = cfg::parse_stack_config(
      edit_line(edit_line(text_, "hook:", "enabled:", "enabled: true").text, "wind:", "enabled:", "enabled: true").text,
      "test.yaml");
  EXPECT_TRUE(on.plant.hook.enabled);
  EXPECT_DOUBLE_EQ(on.plant.hook.rigging_length, 0.3);
  EXPECT_TRUE(on.plant.wind.enabled);
  EXPECT_EQ(on.plant.wind.seed, 1U);
}

// The lab crane plans robustly near its mast only (docs/optimal_control.md, "Robust near the mast");
// the ranges are validated, and the radius is a tower crane's.
TEST_F(LabConfigText, TheRobustPlanIsNearTheMastAndItsRangesAreValidated) {
  const auto c = cfg::parse_stack_config(text_, "test.yaml");
  EXPECT_EQ(c.trajectory_planner.robust_length_range, 0.2);
  EXPECT_EQ(c.trajectory_planner.robust_margin, 0.2);
  EXPECT_EQ(c.trajectory_planner.robust_within_radius, 0.5);
  auto message = error_of(edit_line(text_, "trajectory_planner:", "robust_length_range:", "robust_length_range: 0.6").text);
  EXPECT_TRUE(contains(message, "trajectory_planner.robust_length_range = 0.6")) << message;
  EXPECT_TRUE(contains(message, "[0, 0.5]")) << message;
  message = error_of(edit_line(text_, "trajectory_planner:", "robust_margin:", "robust_margin: -0.1").text);
  EXPECT_TRUE(contains(message, "trajectory_planner.robust_margin = -0.1")) << message;
  message = error_of(edit_line(text_, "trajectory_planner:", "robust_within_radius:", "robust_within_radius: -1").text);
  EXPECT_TRUE(contains(message, "trajectory_planner.robust_within_radius = -1")) << message;
  const auto off = cfg::parse_stack_config(
      edit_line(text_, "trajectory_planner:", "robust_length_range:", "robust_length_range: 0").text, "test.yaml");
  EXPECT_EQ(off.trajectory_planner.robust_length_range, 0.0);
  for (const char* name : {"gantry_crane.yaml", "overhead_crane.yaml"}) {
    const std::string text = read_text(std::string(CRANE_SOURCE_DIR) + "/deploy/config/" + name);
    EXPECT_EQ(cfg::parse_stack_config(text, name).trajectory_planner.robust_within_radius, 0.0) << name;
    message = error_of(edit_line(text, "trajectory_planner:", "robust_within_radius:", "robust_within_radius: 0.5").text);
    EXPECT_TRUE(contains(message, "trajectory_planner.robust_within_radius = 0.5")) << name << ": " << message;
    EXPECT_TRUE(contains(message, "tower crane only")) << name << ": " << message;
  }
}

TEST_F(LabConfigText, ManualShapingAndItsSwingModelAreValidated) {
  const auto c = cfg::parse_stack_config(text_, "test.yaml");
  EXPECT_EQ(c.trajectory_planner.manual.shaping, crane::trajectory_planner::SpeedShaping::zvd);
  EXPECT_EQ(c.trajectory_planner.manual.swing_length_scale, 1.0);  // the single pendulum sqrt(g/L)
  EXPECT_EQ(c.trajectory_planner.manual.swing_length_offset, 0.0);
  EXPECT_EQ(c.trajectory_planner.manual.swing_damping_ratio, 0.0);
  auto message = error_of(edit_line(text_, "manual:", "shaping:", "shaping: zvdd").text);
  EXPECT_TRUE(contains(message, "trajectory_planner.manual.shaping = \"zvdd\"")) << message;
  EXPECT_TRUE(contains(message, "two_hump_ei")) << message;
  message = error_of(edit_line(text_, "manual:", "swing_damping_ratio:", "swing_damping_ratio: 0.5").text);
  EXPECT_TRUE(contains(message, "trajectory_planner.manual.swing_damping_ratio = 0.5")) << message;
  EXPECT_TRUE(contains(message, "[0, 0.3]")) << message;
  // The supervisor's model of the soft stop follows the shaper: two_hump_ei's mean delay is 3/4 of
  // a period (impulses symmetric about 3/4 T), zvd's 1/2.
  const std::string two_hump = edit_line(text_, "manual:", "shaping:", "shaping: two_hump_ei").text;
  message = error_of(two_hump);
  EXPECT_TRUE(contains(message, "test.yaml: supervisor.zone_stop_delay_periods = 0.5 does not describe the planner's "
                                "soft stop: trajectory_planner.manual.shaping = two_hump_ei delays it by 0.75 swing "
                                "periods")) << message;
  const auto calibrated = cfg::parse_stack_config(
      edit_line(edit_line(two_hump, "supervisor:", "zone_stop_delay_periods:", "zone_stop_delay_periods: 0.75").text,
                "manual:", "swing_length_offset:", "swing_length_offset: 0.25")
          .text,
      "test.yaml");
  EXPECT_EQ(calibrated.trajectory_planner.manual.shaping, crane::trajectory_planner::SpeedShaping::two_hump_ei);
  EXPECT_EQ(calibrated.trajectory_planner.manual.swing_length_offset, 0.25);
  // An equivalent pendulum that is no pendulum at the shortest cable (the minimum-time plans swing
  // it, optimal_control::minimum_time_problem): refused with the length it would have.
  message = error_of(edit_line(text_, "manual:", "swing_length_offset:", "swing_length_offset: -0.99").text);
  EXPECT_TRUE(contains(message, "trajectory_planner.manual.swing_length_offset = -0.99")) << message;
  EXPECT_TRUE(contains(message, "leaves no pendulum at the shortest cable")) << message;
}

TEST_F(LabConfigText, PlantRopeIsOffAndValidatedLikeTheRest) {
  const auto c = cfg::parse_stack_config(text_, "test.yaml");
  EXPECT_FALSE(c.plant.rope.enabled);  // off by default: an inextensible cable
  auto message = error_of(edit_line(text_, "rope:", "axial_stiffness:", "axial_stiffness: 0").text);
  EXPECT_TRUE(contains(message, "plant.rope.axial_stiffness = 0")) << message;
  EXPECT_TRUE(contains(message, "[1, 1e+10]")) << message;
  message = error_of(
      edit_line(edit_line(text_, "rope:", "enabled:", "enabled: true").text, "hook:", "enabled:", "enabled: true").text);
  EXPECT_TRUE(contains(message, "plant.rope.enabled = true needs plant.hook.enabled = false")) << message;
  // Enabled, the plant starts at the static stretch m g L / EA.
  const auto on = cfg::parse_stack_config(edit_line(text_, "rope:", "enabled:", "enabled: true").text, "test.yaml");
  EXPECT_TRUE(on.plant.rope.enabled);
  EXPECT_NEAR(on.plant.initial_state.rope_stretch, 2.0 * 9.8 * 1.0 / 2.0e5, 1e-15);
}

// plant.integrator names one of the integrators (hybrid_integrator.hpp); the configs carry the
// code's default, and another name or a missing field is refused naming the field.
TEST_F(LabConfigText, PlantIntegratorIsTheDefaultAndValidated) {
  const auto c = cfg::parse_stack_config(text_, "test.yaml");
  EXPECT_EQ(c.plant.integrator.method, crane::plant::IntegratorSettings{}.method);
  EXPECT_DOUBLE_EQ(c.plant.integrator.relative_tolerance, crane::plant::IntegratorSettings{}.relative_tolerance);
  EXPECT_DOUBLE_EQ(c.plant.integrator.absolute_tolerance, crane::plant::IntegratorSettings{}.absolute_tolerance);
  auto message = error_of(edit_line(text_, "plant:", "integrator:", "integrator: rk4").text);
  EXPECT_TRUE(starts_with(message, "test.yaml: ")) << message;
  EXPECT_TRUE(contains(message, "plant.integrator = 'rk4' is not one of dormand_prince, verner, adams, bdf")) << message;
  message = error_of(edit_line(text_, "plant:", "integrator:", std::nullopt).text);
  EXPECT_TRUE(contains(message, "missing field plant.integrator")) << message;
  const auto bdf = cfg::parse_stack_config(edit_line(text_, "plant:", "integrator:", "integrator: bdf").text, "test.yaml");
  EXPECT_EQ(bdf.plant.integrator.method, crane::plant::IntegrationMethod::bdf);
}
