#pragma once
// Safety supervisor core: modes, brakes, protective functions (limits), stage watchdogs.
//
// Pure logic (no DDS, no clock): the node feeds it what it observed of every stage of the chain and
// the latest sensor and actuator values; it answers whether drives may be energized, whether brakes
// may be opened and the voltage each drive may receive. Vocabulary after the OPC UA Companion
// Specification for Cranes and Hoists where it fits: operation modes (standby, ready, operating),
// protective functions (travel limiter, slew limiter, overspeed, sway limiter, ...), protective stop
// (a fault: brakes engaged, drives off) and emergency stop.
//
// Rules (docs/architecture.md, "Safety"):
//  - motion (drives) is enabled only in ready/operating, and only while every stage of the chain is
//    fresh: DDS liveliness asserted and a sample received within stage_timeout. The brakes are
//    released only in a cycle after the one that enabled the drives, with the chain still fresh
//    (the drives hold the load before the brakes let go);
//  - a stage that is not fresh is late: motion is inhibited while it lasts (drives off, brakes on,
//    warning kWarningStageLate), with no fault, so a few late cycles that recover latch nothing;
//  - the drives braked under way: in ready/operating, once a sensor sample has reported the brakes
//    released, a sample reporting them engaged (the actuation gate's command watchdog after a
//    stalled chain, or motion inhibited by a late stage) raises warning kWarningDrivesBraked for as
//    long as they stay on. The planner answers by pausing the goal where the brakes stopped the
//    crane (it goes on once they are open and the swing has settled): a reference that ran on
//    meanwhile would otherwise be chased at full voltage when the brakes open (both drives at
//    about twice their speed: docs/site.md);
//  - a stage silent for longer than stage_dead_timeout, or whose writer is gone (unmatched), is
//    dead: protective stop (fault stage_silent). So is a limit exceeded, a non-finite value or a
//    second writer: brakes engaged, drives at zero; the fault stays latched until an explicit
//    reset command arrives with a healthy chain and nothing active;
//  - an emergency stop (input or command) engages the brakes at once and needs a reset;
//  - approach margins: within approach_margin of a travel/slew limit, moving toward it, the axis
//    may not move faster than a speed that falls linearly from max to approach speed; when it does,
//    the voltage limit of that drive drops to approach_voltage_limit so the drive can only brake
//    (friction decelerates it); inside stop_margin of the limit, still moving toward it: protective
//    stop, so the brakes hold it before the hard limit;
//  - operating modes after OPC 40020 (MANUAL, SEMIAUTOMATIC, FULLAUTOMATIC, MAINTENANCE) change
//    only by an operator command here (FULLAUTOMATIC at start); the planner applies them (goals or
//    operator speeds) and stops softly first when the mode changes while the crane moves;
//  - no-go zones (common/site.hpp, switched on and off by operator commands; zone_guard() below),
//    enforced from the measured state in every operating mode, in three steps like the travel
//    limits: (1) the load's position after a soft stop from the measured speeds, within
//    zone_approach_margin of an enabled zone: warning zone_approach, to which the planner answers
//    with its soft stop (the first reaction, where a hard stop is not yet required); (2) that
//    position inside the zone itself (the soft stop no longer fits, e.g. the planner did not stop):
//    the voltage limit of each drive whose axis still speeds up drops to approach_voltage_limit (it
//    can no longer drive it faster; one that decelerates keeps its voltage to brake actively: the
//    slew's friction alone hardly slows it) and the warning speed_limited; (3) the brake envelope (where the load can swing if the brakes stop the
//    crane now) within zone_brake_margin of the zone while the crane moves, or the load measured
//    inside one: protective stop (fault zone, brakes), before the load enters.
// The axis velocities are differentiated here from the sensor samples, not taken from the state
// estimator: the supervisor does not trust the control processes. The interval between two samples
// is their measurement times' difference when the input gives them (SupervisorInput::sensor_time: a
// hardware bridge in realtime, whose cycles jitter: a read 2 ms late is a 20 % faster velocity over
// the nominal 10 ms; the simulated plant stamps each with its cycle's scheduled instant), within
// [kMinMeasuredInterval, kMaxMeasuredInterval] x the nominal one, and their seq difference x
// sample_period otherwise.

#include <array>
#include <cstdint>
#include <limits>
#include <string>

#include "crane/common/site.hpp"
#include "crane/protocol/messages.hpp"

namespace crane::supervisor {

/// Stages of the chain the supervisor watches, in data-flow order (bit i of
/// SupervisorStatus.stages_alive is Stage(i): the IDL's STAGE_* codes).
enum class Stage : std::uint8_t {
  sensors = 0,          // plant or hardware bridge
  state_estimator = 1,
  trajectory_planner = 2,
  anti_swing = 3,
  tracking = 4,
  friction_compensation = 5,  // the actuator command
};
inline constexpr std::size_t kStageCount = 6;
static_assert((1U << kStageCount) - 1U == protocol::SupervisorStatus::STAGES_ALL);
/// "sensors", "state_estimator", ... (the IDL's code names).
[[nodiscard]] const char* stage_name(Stage stage) noexcept;

/// Operation modes (SupervisorStatus.mode, the IDL's MODE_* codes).
enum class Mode : std::uint8_t {
  starting = protocol::SupervisorStatus::MODE_STARTING,
  standby = protocol::SupervisorStatus::MODE_STANDBY,
  ready = protocol::SupervisorStatus::MODE_READY,
  operating = protocol::SupervisorStatus::MODE_OPERATING,
  fault = protocol::SupervisorStatus::MODE_FAULT,
  emergency_stop = protocol::SupervisorStatus::MODE_EMERGENCY_STOP,
};
[[nodiscard]] const char* mode_name(Mode mode) noexcept;

/// Fault codes (protective functions that tripped): one bit each in SupervisorStatus.active_faults /
/// latched_faults / last_fault. Defined in the IDL (FAULT_*, with their meaning); named here.
using StatusCodes = protocol::SupervisorStatus;  // the codes of SupervisorStatus
enum Fault : std::uint32_t {
  kFaultStageSilent = StatusCodes::FAULT_STAGE_SILENT,
  kFaultTrolleyTravel = StatusCodes::FAULT_TROLLEY_TRAVEL,
  kFaultVoltage = StatusCodes::FAULT_VOLTAGE,
  kFaultNonFinite = StatusCodes::FAULT_NON_FINITE,
  kFaultEmergencyStop = StatusCodes::FAULT_EMERGENCY_STOP,
  kFaultMultipleSensorWriters = StatusCodes::FAULT_MULTIPLE_SENSOR_WRITERS,
  kFaultSwing = StatusCodes::FAULT_SWING,
  kFaultSlewRange = StatusCodes::FAULT_SLEW_RANGE,
  kFaultTrolleyOverspeed = StatusCodes::FAULT_TROLLEY_OVERSPEED,
  kFaultSlewOverspeed = StatusCodes::FAULT_SLEW_OVERSPEED,
  kFaultVoltageRate = StatusCodes::FAULT_VOLTAGE_RATE,
  kFaultMultipleActuatorWriters = StatusCodes::FAULT_MULTIPLE_ACTUATOR_WRITERS,
  kFaultSensorSource = StatusCodes::FAULT_SENSOR_SOURCE,
  kFaultLimitSwitch = StatusCodes::FAULT_LIMIT_SWITCH,
  kFaultZone = StatusCodes::FAULT_ZONE,
  kFaultBridgeTravel = StatusCodes::FAULT_BRIDGE_TRAVEL,
  kFaultBridgeOverspeed = StatusCodes::FAULT_BRIDGE_OVERSPEED,
  kFaultSiteGrant = StatusCodes::FAULT_SITE_GRANT,
};
/// How many FAULT_* bits the IDL defines (one bit each, from bit 0): counted from its codes.
inline constexpr int kFaultBits = [] {
  int count = 0;
  for (const auto& code : StatusCodes::kCodes) count += code.group == "FAULT" ? 1 : 0;
  return count;
}();
/// Name of one fault bit ("stage_silent", "trolley_travel", ...); "unknown" for other values.
[[nodiscard]] const char* fault_name(std::uint32_t fault_bit) noexcept;

/// Warnings (SupervisorStatus.warnings, the IDL's WARNING_* codes): reported, motion continues.
enum Warning : std::uint32_t {
  kWarningTrolleyApproach = StatusCodes::WARNING_TROLLEY_APPROACH,  // trolley in its approach margin, moving toward the limit
  kWarningSlewApproach = StatusCodes::WARNING_SLEW_APPROACH,        // jib in its approach margin, moving toward the limit
  kWarningBridgeApproach = StatusCodes::WARNING_BRIDGE_APPROACH,    // bridge in its approach margin, moving toward the limit
  kWarningSpeedLimited = StatusCodes::WARNING_SPEED_LIMITED,        // an approach speed was exceeded: drive voltage limited
  kWarningStageLate = StatusCodes::WARNING_STAGE_LATE,              // a stage is late (not fresh, or a DDS deadline missed):
                                                              // motion inhibited while it lasts, not yet dead
  kWarningZoneApproach = StatusCodes::WARNING_ZONE_APPROACH,        // the predicted stopping position is in a zone
  kWarningSite = StatusCodes::WARNING_SITE,                         // the site guard asks for a soft stop
  kWarningDrivesBraked = StatusCodes::WARNING_DRIVES_BRAKED,        // brakes on in ready/operating after the drives ran
  kWarningSiteUnheard = StatusCodes::WARNING_SITE_UNHEARD,          // on a site: the guard does not hear the site service
};

/// What the crane's guard of its site grant (anti_collision::GrantGuard, docs/site.md) answered
/// this cycle: off when the crane is not on a site. emergency_stop raises kFaultSiteGrant (the
/// brakes); soft_stop is kWarningSite (the planner stops softly).
enum class SiteVerdict : std::uint8_t { off, proceed, soft_stop, emergency_stop };

/// Operating modes after OPC 40020 (SupervisorStatus.operating_mode, the IDL's OPERATION_* codes).
enum class OperatingMode : std::uint8_t {
  manual = StatusCodes::OPERATION_MANUAL,
  semiautomatic = StatusCodes::OPERATION_SEMIAUTOMATIC,
  fullautomatic = StatusCodes::OPERATION_FULLAUTOMATIC,
  maintenance = StatusCodes::OPERATION_MAINTENANCE,
};
/// "manual", "semiautomatic", "fullautomatic", "maintenance" (the IDL's names); "unknown" for other codes.
[[nodiscard]] const char* operating_mode_name(std::uint8_t code) noexcept;

/// One axis's range and approach behaviour. Units: [m] and [m/s] for the trolley, [rad] and [rad/s]
/// for the slew.
struct AxisLimits {
  double min{0.0};                // hard limit
  double max{1.0};                // hard limit
  double approach_margin{0.1};    // distance from a hard limit where slowing starts
  double stop_margin{0.02};       // distance from a hard limit where motion toward it is stopped
  double approach_speed{0.05};    // speed allowed at the stop margin (linear up to max_speed at the
                                  // approach margin)
  double max_speed{1.0};          // overspeed limit anywhere
};

/// Overspeed is a fault when the speed (the difference quotient of consecutive sensor samples) is
/// over max_speed in this many consecutive samples: a single sample's quotient doubles when one
/// encoder reading lands a cycle late and the next a cycle early (seen with the emulated board,
/// whose plant updates its counters once per step on its own timer: 1.28 m/s for one sample, then
/// 0.09, during a 0.64 m/s move). A real overspeed lasts longer; the trip comes one cycle later.
inline constexpr int kOverspeedSamples = 2;
/// Bounds of a measured interval between two sensor samples, as fractions of the nominal one (seq
/// difference x sample_period); outside them (a clock step, a sample reordered) the nominal is used.
inline constexpr double kMinMeasuredInterval = 0.25;
inline constexpr double kMaxMeasuredInterval = 4.0;

struct SupervisorParams {
  double trolley_min{0.05};          // [m] hard travel limit
  double trolley_max{1.30};          // [m] hard travel limit
  double trolley_approach_margin{0.15};  // [m]
  double trolley_stop_margin{0.03};      // [m]
  double trolley_approach_speed{0.1};    // [m/s]
  double trolley_max_speed{1.0};         // [m/s]
  // A tower crane's slew (crane.kind = tower; slew_enabled false elsewhere: no slew limits, no slew
  // limiter or overspeed, the slew drive's voltage limit 0).
  bool slew_enabled{true};
  double slew_min{-3.3};             // [rad] hard slew limit
  double slew_max{3.3};              // [rad]
  double slew_approach_margin{0.3};  // [rad]
  double slew_stop_margin{0.05};     // [rad]
  double slew_approach_rate{0.2};    // [rad/s]
  double slew_max_rate{2.0};         // [rad/s]
  double voltage_limit{10.0};        // [V] magnitude limit on both drive commands
  double approach_voltage_limit{0.5};  // [V] drive limit while an approach speed is exceeded
  double max_voltage_rate{1500.0};   // [V/s] largest change of a drive command between two samples
  double max_swing{0.35};            // [rad] swing angle beyond which the crane stops
  double stage_timeout{0.05};        // [s] a stage silent for longer is late: motion inhibited (5 cycles)
  double stage_dead_timeout{0.25};   // [s] a stage silent for longer is dead: fault stage_silent, latched
                                     // (in lockstep both count cycles of the sensor clock, not wall time)
  double sample_period{0.01};        // [s] of the sensor stream (velocities from seq differences)
  bool arm_on_start{true};           // arm by itself once the chain is healthy (simulation); a
                                     // real crane sets false and waits for an explicit arm command
  std::uint8_t expected_sensor_source{0};  // 0 any, 1 simulated plant, 2 hardware bridge
  // No-go zones (zone_guard()): the soft stop the planner uses (trajectory_planner.manual: its ramp's
  // accelerations and its shaper), and the margins of the three steps.
  double trolley_braking_deceleration{0.9929};  // [m/s^2] the soft stop's trolley deceleration (its ramp)
  double slew_braking_deceleration{2.0796};     // [rad/s^2] the soft stop's slew deceleration
  double zone_stop_delay_periods{0.5};  // [swing periods] how long the soft stop's shaper delays the
                                        // deceleration: its mean delay (ZV 0.25, ZVD 0.5), in [0, 3]
  double zone_approach_margin{0.05};    // [m] soft stop this close to a zone: warning zone_approach, in [0, 10]
  double zone_brake_margin{0.01};       // [m] brake envelope this close to a zone: protective stop, in [0, 1]
  double gravity{9.8};                  // [m/s^2] the load's swing frequency sqrt(g / L) (crane.gravity)
  common::Site site{};               // the no-go zones (a shared fact, `site:`)
  // An overhead crane's bridge (crane.kind = overhead; bridge_enabled false elsewhere): its runway travel,
  // guarded like the trolley's.
  bool bridge_enabled{false};
  double bridge_min{0.0};            // [m] hard travel limit
  double bridge_max{1.0};            // [m]
  double bridge_approach_margin{0.1};  // [m]
  double bridge_stop_margin{0.02};     // [m]
  double bridge_approach_speed{0.05};  // [m/s]
  double bridge_max_speed{1.0};        // [m/s]

  [[nodiscard]] AxisLimits bridge() const noexcept {
    return {bridge_min, bridge_max, bridge_approach_margin, bridge_stop_margin, bridge_approach_speed, bridge_max_speed};
  }
  [[nodiscard]] AxisLimits trolley() const noexcept {
    return {trolley_min, trolley_max, trolley_approach_margin, trolley_stop_margin, trolley_approach_speed,
            trolley_max_speed};
  }
  [[nodiscard]] AxisLimits slew() const noexcept {
    return {slew_min, slew_max, slew_approach_margin, slew_stop_margin, slew_approach_rate, slew_max_rate};
  }
};
/// Throws crane::common::ConfigError naming the field ("supervisor.<name>"), value and bound.
void validate(const SupervisorParams& params);

/// What the node observed of one stage since the last step.
struct StageObservation {
  bool alive{false};                  // DDS liveliness asserted and matched
  bool present{true};                 // its writer is matched (false: the process is gone: dead at once)
  double seconds_since_sample{1e9};   // [s] since the last valid sample was received (in lockstep: cycles
                                      // of the sensor clock since its last sample, times the sample period)
  bool deadline_missed{false};        // a DDS requested-deadline-missed event since the last step
};

/// Operator commands (SupervisorCommand.command, the IDL's COMMAND_* codes).
enum class Command : std::uint8_t {
  none = protocol::SupervisorCommand::COMMAND_NONE,
  arm = protocol::SupervisorCommand::COMMAND_ARM,
  disarm = protocol::SupervisorCommand::COMMAND_DISARM,
  emergency_stop = protocol::SupervisorCommand::COMMAND_EMERGENCY_STOP,
  reset = protocol::SupervisorCommand::COMMAND_RESET,
  set_operating_mode = protocol::SupervisorCommand::COMMAND_SET_OPERATING_MODE,
  enable_zone = protocol::SupervisorCommand::COMMAND_ENABLE_ZONE,
  disable_zone = protocol::SupervisorCommand::COMMAND_DISABLE_ZONE,
};

/// Why an enable_zone / disable_zone command is refused (none: taken).
enum class ZoneRefusal : std::uint8_t {
  none = 0,
  no_such_zone = 1,  // the index is not one of site.zones
  fixed = 2,         // disable_zone of a fixed zone (common::Zone::fixed): always enforced
};
/// The rule for zone commands, the one place the supervisor and the operator's tool share.
[[nodiscard]] ZoneRefusal zone_command_refusal(const common::Site& site, Command command, std::uint8_t zone) noexcept;
/// The refusal as the operator reads it, naming the zone: "site.zones[0] (school yard) is fixed: it
/// stays enforced" or "no zone 5: site.zones has 2". "" for none.
[[nodiscard]] std::string describe(ZoneRefusal refusal, const common::Site& site, std::uint8_t zone);

struct SupervisorInput {
  std::array<StageObservation, kStageCount> stages{};
  bool sensors_valid{false};          // a sensor sample has been received (limits are checked only then)
  std::uint64_t sensor_seq{0};        // cycle number of the latest sensor sample
  double sensor_time{std::numeric_limits<double>::quiet_NaN()};  // [s] when its positions were measured, any
                                      // epoch; NaN: the samples are sample_period apart per seq
  std::uint8_t sensor_source{0};      // SensorSample_.source
  double trolley_position{0.0};       // [m] from the latest sensor sample
  double slew_angle{0.0};             // [rad]
  double swing_in_plane{0.0};         // [rad]
  double swing_out_of_plane{0.0};     // [rad]
  double cable_length{1.0};           // [m]
  std::uint8_t limit_switches{0};     // SensorSample_.limit_switches (bit 0 trolley min, 1 max, 2 slew min, 3 max)
  bool actuators_valid{false};        // an actuator command has been received
  std::uint64_t actuator_seq{0};      // cycle number of the latest actuator command
  double trolley_voltage{0.0};        // [V] latest actuator command
  double slew_voltage{0.0};           // [V]
  double bridge_position{0.0};        // [m] overhead crane, from the latest sensor sample
  double bridge_voltage{0.0};         // [V] overhead crane, latest actuator command
  bool emergency_stop_input{false};   // hardware input
  int sensor_writers{1};              // writers matched on the sensors topic
  int actuator_writers{1};            // writers matched on the actuators topic
  bool nonfinite_seen{false};         // a watched sample was rejected for NaN/Inf since last step
  bool brakes_engaged{true};          // SensorSample_.brakes_engaged of the latest sample (the brakes as applied)
  bool move_in_progress{false};       // the planner reports a move (ready -> operating)
  Command command{Command::none};
  std::uint8_t command_operating_mode{0};  // set_operating_mode: an OPERATION_* code (others refused)
  std::uint8_t command_zone{0};            // enable_zone / disable_zone: index in site.zones (others refused)
  SiteVerdict site{SiteVerdict::off};      // the site guard's answer for this cycle's motion
  bool site_unheard{false};                // on a site (site not off): the guard has not heard the site service
                                           // within its link deadline, or never (kWarningSiteUnheard)
};

struct SupervisorOutput {
  Mode mode{Mode::starting};
  bool motion_enabled{false};
  bool brakes_released{false};
  std::uint32_t active_faults{0};
  std::uint32_t latched_faults{0};
  std::uint32_t fault_count{0};
  std::uint32_t stages_alive{0};      // bit i set: Stage(i) fresh (alive, sample within stage_timeout)
  std::uint32_t stages_dead{0};       // bit i set: Stage(i) dead (gone, or silent beyond stage_dead_timeout)
  std::uint32_t warnings{0};          // Warning bits
  std::uint32_t last_fault{0};        // the most recently raised fault bit (0: none yet)
  std::uint64_t last_fault_seq{0};    // sensor cycle at which it was raised
  double trolley_voltage_limit{0.0};  // [V] magnitude the trolley drive may receive now
  double slew_voltage_limit{0.0};     // [V]
  double trolley_velocity{0.0};       // [m/s] differentiated from the sensor samples
  double slew_rate{0.0};              // [rad/s]
  double bridge_voltage_limit{0.0};   // [V] overhead crane (0 elsewhere)
  double bridge_velocity{0.0};        // [m/s]
  double cable_rate{0.0};             // [m/s] differentiated from the sensor samples (0 while the cable
                                      // length is not finite); the site guard's hoist (docs/site.md)
  std::uint8_t operating_mode{StatusCodes::OPERATION_FULLAUTOMATIC};  // an OPERATION_* code
  std::uint32_t zones_enabled{0};     // bit i: site.zones[i] enforced
  int zone{-1};                       // the zone of fault zone or warning zone_approach (-1: none)
  bool command_refused{false};        // the step's command was refused: arm with latched faults or an
                                      // unhealthy chain, reset with a fault still active or an unhealthy chain,
                                      // a zone command zone_command_refusal() refuses
  ZoneRefusal zone_refusal{ZoneRefusal::none};  // the step's zone command's refusal
};

/// The soft stop the zone rule predicts, by operating mode: shaped (MANUAL, SEMIAUTOMATIC: the
/// operator's speeds through the manual shaper, delayed by it), unshaped (MAINTENANCE: ramp only,
/// and the swing it excites), planned (FULLAUTOMATIC: the goal's profile decelerates where the
/// planner planned it around the zones; ramp only: with the shaper's delay the supervisor stopped
/// 24 of 86 seeded planned goals that keep out of every zone, docs/operation.md).
enum class SoftStop : std::uint8_t { shaped, unshaped, planned };

/// The measured state the zone rule looks at: the crane's coordinates and their rates from the
/// sensor samples, the load's horizontal velocity [m/s] (differentiated from its position).
struct ZoneState {
  double trolley{0.0};           // [m]
  double trolley_velocity{0.0};  // [m/s]
  double slew{0.0};              // [rad]
  double slew_rate{0.0};         // [rad/s]
  double swing_in_plane{0.0};    // [rad]
  double swing_out_of_plane{0.0};  // [rad]
  double cable_length{1.0};      // [m]
  std::array<double, 2> load_velocity{};  // [m/s] the load's horizontal velocity, world frame
  SoftStop stop{SoftStop::shaped};  // which soft stop the operating mode gives (zone_guard())
  double trolley_acceleration{0.0};  // [m/s^2] of the measured speed (last two velocities)
  double slew_acceleration{0.0};     // [rad/s^2]
};

/// The zone rule's verdict: the first enabled zone (index) each step reaches, or -1.
struct ZoneVerdict {
  int inside{-1};    // the load measured inside a zone (protective stop)
  int brake{-1};     // the brake envelope within zone_brake_margin, the crane moving (protective stop)
  int limit{-1};     // the soft stop's rest position inside a zone: the axes still speeding up get
                     // their drive voltage limited
  bool limit_trolley{false};
  bool limit_slew{false};
  int approach{-1};  // the soft stop's rest position within zone_approach_margin (warning zone_approach)
};

/// The no-go zone rule (the header's three steps), from the measured state:
///  - soft stop: each axis ramps down at its *_braking_deceleration after the shaper's delay
///    t_d = zone_stop_delay_periods 2 pi sqrt(L / g) (0 unless SoftStop::shaped), so it rests at
///    x + v|v| / (2 a) + v t_d
///    (exact for a steady speed when t_d is the shaper's mean delay sum A_i t_i: ZV T/4, ZVD T/2); the load anywhere within the swing's
///    amplitude sqrt(|u|^2 + |du/dt|^2 / w^2) of that point (u the load's horizontal offset from
///    the trolley's point, w = sqrt(g / L): a shaped stop adds no swing of its own), plus, for
///    SoftStop::unshaped, the point's speed / w (the most a stop excites);
///  - brake envelope: the trolley's point stops at x + v|v| / (2 a) (the brakes stop it sooner);
///    the load then swings about it as a pendulum: its horizontal offset
///    u(t) = u0 cos(w t) + (v_load / w) sin(w t), w = sqrt(g / L), from the measured offset u0 and
///    the load's velocity v_load (the whole velocity is lost by the trolley: the most a stop can
///    excite); checked at 24 phases of that ellipse around the trolley's point now and at its stop,
///    and only while the crane moves toward that zone (the trolley's point nearer to it at the soft
///    stop's rest than now); in FULLAUTOMATIC only with the ramp-only prediction in the zone too (a
///    planned path passes zones closer than the brake envelope: one of the seeded goals of
///    tests/closed_loop tripped it). So in FULLAUTOMATIC the supervisor relies on the planner's
///    paths: a goal planned through a zone (the planner's guard bypassed) enters it by 2.6 cm
///    (closed_loop.Zones.TheSupervisorAlone*, printed), where under operator speeds it never does.
/// The soft stop's prediction is exact for a steady speed; a stop begun while the shaped speed is
/// still rising (a stick pushed a moment before) runs past it (the shaper's later impulses of the
/// rise), and the voltage limit and the brakes take over.
/// Pure, noexcept.
[[nodiscard]] ZoneVerdict zone_guard(const SupervisorParams& params, std::uint32_t zones_enabled,
                                     const ZoneState& state) noexcept;

class Supervisor {
 public:
  /// Throws crane::common::ConfigError for invalid params (validate()).
  explicit Supervisor(const SupervisorParams& params);
  /// One supervision cycle. Never throws, never allocates.
  void step(const SupervisorInput& input, SupervisorOutput& output) noexcept;
  [[nodiscard]] Mode mode() const noexcept { return mode_; }
  /// Faults raised in the last step that were not active before (for the fault log).
  [[nodiscard]] std::uint32_t newly_raised() const noexcept { return newly_raised_; }
  /// Faults that were active before the last step and are not any more.
  [[nodiscard]] std::uint32_t newly_cleared() const noexcept { return newly_cleared_; }
  [[nodiscard]] const SupervisorParams& params() const noexcept { return params_; }

 private:
  SupervisorParams params_;
  Mode mode_{Mode::starting};
  std::uint32_t latched_{0};
  std::uint32_t previous_active_{0};
  std::uint32_t fault_count_{0};
  std::uint32_t newly_raised_{0};
  std::uint32_t newly_cleared_{0};
  std::uint32_t last_fault_{0};
  bool chain_was_up_{false};  // every stage has been fresh once: a death from now on is a fault
  std::uint64_t last_fault_seq_{0};
  bool armed_{false};
  std::uint8_t operating_mode_{StatusCodes::OPERATION_FULLAUTOMATIC};
  std::uint32_t zones_enabled_{0};
  bool drives_enabled_previous_{false};
  bool drives_ran_{false};  // in ready/operating, a sample reported the brakes released (kWarningDrivesBraked)
  // Velocity from successive sensor samples.
  bool have_previous_sample_{false};
  std::uint64_t previous_sensor_seq_{0};
  double previous_sensor_time_{std::numeric_limits<double>::quiet_NaN()};  // [s] SupervisorInput::sensor_time
  double previous_trolley_{0.0};
  double previous_slew_{0.0};
  double trolley_velocity_{0.0};
  double slew_rate_{0.0};
  int trolley_overspeed_samples_{0};  // consecutive sensor samples over max_speed
  int slew_overspeed_samples_{0};
  double previous_bridge_{0.0};
  double bridge_velocity_{0.0};
  int bridge_overspeed_samples_{0};
  double previous_cable_{std::numeric_limits<double>::quiet_NaN()};  // [m] NaN: no finite cable length yet
  double cable_rate_{0.0};
  double previous_bridge_voltage_{0.0};
  // Voltage rate from successive actuator commands.
  bool have_previous_command_{false};
  std::uint64_t previous_actuator_seq_{0};
  double previous_trolley_voltage_{0.0};
  double previous_slew_voltage_{0.0};
  double trolley_acceleration_{0.0};  // [m/s^2] from the last two velocities (zones)
  double slew_acceleration_{0.0};     // [rad/s^2]
  // The load's horizontal position from successive sensor samples (zones).
  std::array<double, 2> previous_load_{};
  std::array<double, 2> load_velocity_{};
};

}  // namespace crane::supervisor
