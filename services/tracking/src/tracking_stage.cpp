#include "crane/tracking/tracking_stage.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>

#include "crane/common/protocol_signals.hpp"
#include "crane/common/validation.hpp"
#include "crane/config/yaml_section.hpp"
#include "crane/friction_compensation/friction_compensation.hpp"
#include "crane/tracking/trajectory_feedback.hpp"

namespace crane::tracking {

namespace {
constexpr std::array<std::string_view, 4> kLawNames{"tracking", "gain_scheduling_partial", "gain_scheduling_full",
                                                   "follower"};
}

std::string_view law_name(TrackingLaw law) noexcept { return kLawNames[static_cast<std::size_t>(law)]; }

TrackingLaw law_from_name(std::string_view name, std::string_view field) {
  std::string choices;
  for (std::size_t i = 0; i < kLawNames.size(); ++i) {
    if (kLawNames[i] == name) return static_cast<TrackingLaw>(i);
    choices += (choices.empty() ? "" : ", ") + std::string(kLawNames[i]);
  }
  throw common::ConfigError(std::string(field) + " = '" + std::string(name) + "' is not one of: " + choices);
}

namespace {

// The stage's params for `crane` (the crane's own, or the bridge seen as a trolley).
TrackingStageParams params_for(const common::CraneParameters& crane, const TrackingParams& gains,
                               const common::StackFacts& facts) {
  TrackingStageParams p;
  // The controller's model is the configured crane (section 3.3: (3.37)-(3.38) need K_m, m_t, m_r,
  // M_r and g).
  p.tracking = tracking_params_from(crane);
  p.tracking.proportional_gain = gains.proportional_gain;
  p.tracking.derivative_gain = gains.derivative_gain;
  p.tracking.min_radius = gains.min_radius;
  p.tracking.slew_enabled = gains.slew_enabled;
  p.tracking.min_cable_length = crane.min_cable_length;
  p.tracking.voltage_limit = facts.voltage_limit;
  p.gain_scheduling = gain_scheduling::gain_scheduling_params_from(crane);
  p.gain_scheduling.voltage_limit = facts.voltage_limit;
  p.gain_scheduling.slew_enabled = p.tracking.slew_enabled;
  p.gain_scheduling.min_cable_length = crane.min_cable_length;
  p.trolley_drive_mass = crane.trolley_drive_mass;
  p.jib_inertia = crane.jib_inertia;
  p.trolley_friction = crane.trolley_friction;
  p.sample_period = facts.sample_period;
  p.second_friction = facts.crane_kind == common::CraneKind::overhead ? facts.bridge.friction : crane.slew_friction;
  return p;
}

// The PD law's momentum balance of one drive, lagging as the estimator's rates do.
FrictionMomentumBalance balance_for(const TrackingStageParams& params) {
  common::require_in_range("tracking.friction_balance_block", params.friction_balance_block, params.sample_period,
                           1000.0);
  // The estimator's own validation (StateEstimator's constructor) names a bad field first.
  const state_estimator::StateEstimator estimator(params.estimator);
  const auto& e = params.estimator;
  return FrictionMomentumBalance(
      state_estimator::butterworth_low_pass(e.cutoff_frequency, e.sample_rate),
      state_estimator::differentiator_lag(state_estimator::differentiator_coefficients(e.differentiator, e.sample_rate),
                                          e.sample_rate),
      params.sample_period, static_cast<int>(std::lround(params.friction_balance_block / params.sample_period)));
}

}  // namespace

TrackingStageParams read_params(config::YamlSection& s, const common::StackFacts& facts) {
  TrackingParams gains;
  gains.proportional_gain = s.number("proportional_gain", 0.0, 1.0e4);
  gains.derivative_gain = s.number("derivative_gain", 0.0, 1.0e3);
  gains.min_radius = s.number("min_radius", 1e-3, 100.0);
  gains.slew_enabled = s.flag("slew_enabled");
  const bool estimate_friction_factor = s.flag("estimate_friction_factor");
  s.finish();
  TrackingStageParams p = params_for(facts.crane, gains, facts);
  p.estimate_friction_factor = estimate_friction_factor;
  if (facts.crane_kind == common::CraneKind::overhead) {
    TrackingParams bridge_gains = gains;
    bridge_gains.slew_enabled = false;
    p.bridge = std::make_shared<const TrackingStageParams>(
        params_for(common::bridge_as_trolley(facts.crane, facts.bridge), bridge_gains, facts));
  }
  TrackingStage{p};
  return p;
}

TrackingStage::TrackingStage(const TrackingStageParams& params)
    : law_(params.law),
      tracking_(params.tracking),
      voltage_limit_(params.tracking.voltage_limit),
      trolley_drive_mass_(params.trolley_drive_mass),
      jib_inertia_(params.jib_inertia),
      friction_factor_(params.trolley_friction, params.second_friction,
                       params.law == TrackingLaw::tracking ? params.tracking_friction_factor : FrictionFactorParams{}),
      friction_factor_step_(params.friction_factor_rate * params.sample_period),
      breakaway_(params.breakaway, params.sample_period),
      estimate_friction_factor_(params.estimate_friction_factor && params.law == TrackingLaw::tracking),
      tracking_friction_factor_speed_(params.tracking_friction_factor.min_reference_speed),
      balance_{balance_for(params), balance_for(params)},
      friction_model_{params.trolley_friction, params.second_friction} {
  common::require_greater("tracking.trolley_drive_mass", trolley_drive_mass_, 0.0);
  common::require_greater("tracking.friction_factor_rate", params.friction_factor_rate, 0.0);
  common::require_finite("tracking.friction_factor_rate", params.friction_factor_rate);
  common::require_greater("tracking.jib_inertia", jib_inertia_, 0.0);
  if (law_ == TrackingLaw::gain_scheduling_partial || law_ == TrackingLaw::gain_scheduling_full) {
    auto p = params.gain_scheduling;
    p.kind = law_ == TrackingLaw::gain_scheduling_full ? gain_scheduling::FeedbackKind::full
                                                        : gain_scheduling::FeedbackKind::partial;
    scheduled_.emplace(p);
  }
  if (params.bridge) {
    TrackingStageParams bridge = *params.bridge;
    bridge.law = law_ == TrackingLaw::follower ? TrackingLaw::tracking : law_;  // follow() drives the bridge
    bridge.bridge.reset();
    bridge.estimate_friction_factor = false;  // this stage estimates it on both drives
    bridge_ = std::make_unique<TrackingStage>(bridge);
  }
}

common::StepStatus TrackingStage::step(const protocol::CraneState& estimate, const protocol::Reference& reference,
                                       const protocol::AntiSwingCommand& anti_swing,
                                       protocol::LinearCommand& command) noexcept {
  if (law_ == TrackingLaw::follower && reference.feedback_law) return follow(estimate, reference, command);
  TrackingInput in;
  in.estimate = common::to_estimate(estimate);
  in.reference = common::to_reference(reference);
  if (estimate.payload_confident) {  // the online estimate (crane::adaptation), (2.25)
    in.load = common::LoadRatios{estimate.payload_mass / trolley_drive_mass_, estimate.payload_mass / jib_inertia_};
  }
  if (!scheduled_) {
    in.reference.trolley.position += anti_swing.trolley_reference_correction;
    in.reference.trolley.velocity += anti_swing.trolley_reference_rate_correction;
    in.reference.slew.position += anti_swing.slew_reference_correction;
    in.reference.slew.velocity += anti_swing.slew_reference_rate_correction;
    in.trolley_anti_swing_action = anti_swing.trolley_action;
    in.slew_anti_swing_action = anti_swing.slew_action;
  }
  TrackingOutput result;
  const auto run = [&]() noexcept {
    result = TrackingOutput{};
    return scheduled_ ? scheduled_->step(in.estimate, in.reference, result.command, in.load ? &*in.load : nullptr)
                      : tracking_.step(in, result);
  };
  common::StepStatus status = run();
  const auto finite = [&] {
    return std::isfinite(result.command.trolley_voltage) && std::isfinite(result.command.slew_voltage) &&
           std::isfinite(result.command.hoist_speed);
  };
  if (in.load && (status != common::StepStatus::ok || !finite())) {
    // Fail safe: a load estimate the law cannot use (absurdly large, overflowing the gains) is
    // dropped for this cycle, and the configured load is used.
    in.load.reset();
    status = run();
  }
  command.trolley_voltage = result.command.trolley_voltage;
  command.slew_voltage = result.command.slew_voltage;
  command.hoist_speed = result.command.hoist_speed;
  command.trolley_tracking_action = result.trolley_tracking_action;
  command.slew_tracking_action = result.slew_tracking_action;
  momentum_ = {result.trolley_momentum, result.trolley_centripetal_voltage, result.slew_momentum};
  if (bridge_) {
    protocol::LinearCommand bridge;
    const auto bridge_status = bridge_->step(common::bridge_view(estimate), common::bridge_view(reference),
                                             common::bridge_view(anti_swing), bridge);
    command.bridge_voltage = bridge.trolley_voltage;
    command.bridge_tracking_action = bridge.trolley_tracking_action;
    if (status == common::StepStatus::ok) status = bridge_status;
  }
  if (estimate_friction_factor_ && status == common::StepStatus::ok) {
    command.friction_factor = hand_balanced_friction_factor(estimate, reference, bridge_ != nullptr, command);
  }
  common::same_cycle(estimate.header, command.header);
  return status;
}

double TrackingStage::hand_balanced_friction_factor(const protocol::CraneState& estimate,
                                                    const protocol::Reference& reference, bool bridge,
                                                    const protocol::LinearCommand& command) noexcept {
  // Rows along a planned move (not the operator's stick, request 0, whose stops and stalls the rows
  // do not model), where the measured speed slides the reference's way (the compensation then adds
  // the sliding part the row assumes) and the law's voltage is not clamped.
  if (start_friction_estimate(reference, true)) {
    for (auto& b : balance_) b.drop_block();
  }
  const std::array<double, 2> voltage{command.trolley_voltage, bridge ? command.bridge_voltage : command.slew_voltage};
  // The bridge's stage holds the bridge's momentum as its trolley's.
  const std::array<double, 2> momentum{momentum_[0], bridge ? bridge_->momentum_[0] : momentum_[2]};
  const std::array<double, 2> centripetal{momentum_[1], bridge ? bridge_->momentum_[1] : 0.0};
  const std::array<double, 2> speed{estimate.trolley_velocity, bridge ? estimate.bridge_velocity : estimate.slew_rate};
  const std::array<double, 2> reference_speed{reference.trolley_velocity,
                                              bridge ? reference.bridge_velocity : reference.slew_rate};
  const double share = compensated_share(0.0);
  for (std::size_t a = 0; a < 2; ++a) {
    const double friction =
        reference_speed[a] == 0.0
            ? 0.0
            : friction_compensation::sliding_friction_voltage(friction_model_[a], reference_speed[a],
                                                              reference_speed[a] > 0.0 ? 1 : -1);
    const bool sliding = reference.request_id != 0 && speed[a] * reference_speed[a] > 0.0 &&
                         std::abs(speed[a]) >= tracking_friction_factor_speed_ && std::abs(voltage[a]) < voltage_limit_;
    const auto row = balance_[a].step(voltage[a] + centripetal[a] + share * friction, friction, momentum[a], sliding);
    if (row) friction_factor_.add_row(static_cast<int>(a), row->balance, row->friction, 0.0);
  }
  return next_handed_friction_factor(reference, bridge);
}

bool TrackingStage::start_friction_estimate(const protocol::Reference& reference, bool carry) noexcept {
  if (reference.request_id == 0 || reference.request_id == friction_request_) return false;  // 0: holding
  // With `carry`, the last move's factor is the new one's until it has rows enough (the plant's
  // friction does not change with the move; a hoist alone gives no rows); else the model's.
  const double carried = carry ? friction_factor_.factor() : 1.0;
  friction_factor_.reset(carried);
  friction_request_ = reference.request_id;
  handed_friction_factor_ = carried;
  return true;
}

bool TrackingStage::at_target(const protocol::Reference& reference, bool bridge) noexcept {
  return reference.trolley_velocity == 0.0 && reference.trolley_acceleration == 0.0 &&
         (bridge ? reference.bridge_velocity : reference.slew_rate) == 0.0 &&
         (bridge ? reference.bridge_acceleration : reference.slew_acceleration) == 0.0;
}

double TrackingStage::compensated_share(double reduction) const noexcept {
  return friction_compensation::kept_sliding_share(reduction, handed_friction_factor_) -
         friction_compensation::kept_sliding_share(reduction, 1.0);
}

double TrackingStage::next_handed_friction_factor(const protocol::Reference& reference, bool bridge) noexcept {
  // Along the move the handed factor follows the estimate at friction_factor_rate at most (the prior
  // until this one has rows enough); at the target it is the estimate.
  const double estimate_factor = friction_factor_.factor();
  handed_friction_factor_ =
      at_target(reference, bridge)
          ? estimate_factor
          : handed_friction_factor_ + std::clamp(estimate_factor - handed_friction_factor_, -friction_factor_step_,
                                                 friction_factor_step_);
  return handed_friction_factor_;
}

double TrackingStage::hand_friction_factor(const protocol::Reference& reference, bool bridge,
                                           const std::array<double, 2>& voltage, const std::array<double, 2>& known,
                                           double reduction) noexcept {
  // Rows along the move, from the feedback's part of each drive's voltage where it is not clamped. A
  // row adds back the share the compensation took over from the feedback with the factor handed with
  // the last command.
  const std::array<double, 2> reference_speed{reference.trolley_velocity,
                                              bridge ? reference.bridge_velocity : reference.slew_rate};
  const std::array<double, 2> reference_acceleration{
      reference.trolley_acceleration, bridge ? reference.bridge_acceleration : reference.slew_acceleration};
  const double share = compensated_share(reduction);
  for (int axis = 0; axis < 2; ++axis) {
    const auto a = static_cast<std::size_t>(axis);
    if (std::abs(voltage[a]) < voltage_limit_) {
      friction_factor_.add(axis, voltage[a] - known[a], reference_speed[a], reference_acceleration[a], share);
    }
  }
  return next_handed_friction_factor(reference, bridge);
}

common::StepStatus TrackingStage::follow(const protocol::CraneState& estimate, const protocol::Reference& reference,
                                         protocol::LinearCommand& command) noexcept {
  const bool bridge = bridge_ != nullptr;
  const std::array<double, 4> position{estimate.trolley_position, estimate.swing_in_plane,
                                       bridge ? estimate.bridge_position : estimate.slew_angle,
                                       estimate.swing_out_of_plane};
  const std::array<double, 4> velocity{estimate.trolley_velocity, estimate.swing_in_plane_rate,
                                       bridge ? estimate.bridge_velocity : estimate.slew_rate,
                                       estimate.swing_out_of_plane_rate};
  const common::TrajectoryFeedback law = common::to_trajectory_feedback(reference, bridge);
  const std::array<double, 2> u = trajectory_feedback_voltages(law, position, velocity, voltage_limit_);
  command = protocol::LinearCommand{};
  common::same_cycle(estimate.header, command.header);
  const double reduction = reference.sliding_friction_reduction;
  if (!std::isfinite(u[0]) || !std::isfinite(u[1]) || !std::isfinite(reference.cable_length_rate) ||
      !(reduction >= 0.0 && reduction <= 1.0)) {
    return common::StepStatus::rejected_nonfinite;  // 0 V, the safe output
  }
  // The friction factor (friction_factor_estimate.hpp), from the LQR's part of the voltage.
  if (start_friction_estimate(reference, false)) breakaway_.reset();
  command.friction_factor = hand_friction_factor(reference, bridge, u, law.feedforward, reduction);
  // At the target, a drive the friction holds at rest off it is ramped toward it.
  std::array<double, 2> voltage = u;
  if (at_target(reference, bridge)) {
    for (std::size_t axis = 0; axis < 2; ++axis) {
      const std::size_t slot = axis == 0 ? 0 : 2;  // the trolley, the slew or the bridge
      const double ramp = breakaway_.step(static_cast<int>(axis), position[slot] - law.position[slot], velocity[slot]);
      voltage[axis] = std::clamp(u[axis] + ramp, -voltage_limit_, voltage_limit_);
    }
  } else {
    breakaway_.reset();
  }
  command.trolley_voltage = voltage[0];
  (bridge ? command.bridge_voltage : command.slew_voltage) = voltage[1];
  command.hoist_speed = reference.cable_length_rate;
  command.sliding_friction_reduction = reduction;
  return common::StepStatus::ok;
}

}  // namespace crane::tracking
