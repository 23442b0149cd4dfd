#pragma once
// Simulated crane (tower, gantry or overhead, SimulatorParameters::kind): the facade the plant node
// steps at the sample rate.
//
//   DriveInput (ZOH over one sample_period)
//     -> DAC (clamp +-dac_range, dac_bits quantization; drives_and_sensors.hpp)
//     -> drive forces: F_x = M_drive K_mx V_x (2.26), (2.10); second axis: T_gamma = J_o K_mgamma V_gamma
//        (2.27) on a tower crane, F_y = M_y K_my V_y on an overhead crane's bridge, none on a gantry
//     -> the crane's model (crane_dynamics.hpp: TowerCraneModel (2.11)-(2.16), GantryCraneModel
//        (2.5)-(2.6), OverheadCraneModel) with stick-slip friction (3.1)-(3.3) and brakes
//        (axis_friction.hpp), integrated by SUNDIALS with event location (hybrid_integrator.hpp)
//     -> encoders (quadrature counts) -> SimulatorOutput.
// Options of the tower crane, each off by default (beyond the dissertation): the hook as a double
// pendulum (HookParameters, tower_crane_model.hpp), wind on the load (WindParameters, wind.hpp) and
// an elastic rope (RopeParameters, tower_crane_model.hpp).
// One composition for every kind: only the model and the second axis's friction differ.
#include <cstdint>
#include <memory>
#include <string>

#include "crane/common/crane_parameters.hpp"
#include "crane/common/crane_signals.hpp"
#include "crane/plant/axis_friction.hpp"
#include "crane/plant/hybrid_integrator.hpp"
#include "crane/plant/drives_and_sensors.hpp"
#include "crane/plant/crane_dynamics.hpp"
#include "crane/plant/tower_crane_model.hpp"
#include "crane/plant/wind.hpp"

namespace crane::plant {

/// True plant state, SI.
struct PlantState {
  double trolley_position{0.0};          // [m] x
  double trolley_velocity{0.0};          // [m/s]
  double slew_angle{0.0};                // [rad] gamma
  double slew_rate{0.0};                 // [rad/s]
  double swing_in_plane{0.0};            // [rad] phi
  double swing_in_plane_rate{0.0};       // [rad/s]
  double swing_out_of_plane{0.0};        // [rad] theta
  double swing_out_of_plane_rate{0.0};   // [rad/s]
  double cable_length{1.0};              // [m] L
  double cable_length_rate{0.0};         // [m/s]
  double bridge_position{0.0};           // [m] y, overhead crane only (0 otherwise)
  double bridge_velocity{0.0};           // [m/s]
  double rigging_in_plane{0.0};          // [rad] phi2, the hook-to-load rigging (tower crane with a hook only)
  double rigging_in_plane_rate{0.0};     // [rad/s]
  double rigging_out_of_plane{0.0};      // [rad] theta2
  double rigging_out_of_plane_rate{0.0}; // [rad/s]
  double rope_stretch{0.0};              // [m] s, the elastic rope's stretch (tower crane with plant.rope only)
  double rope_stretch_rate{0.0};         // [m/s]
};

/// Which crane the plant simulates: the config's crane.kind (common::CraneKind, a shared fact).
using PlantKind = common::CraneKind;
/// The model of `kind` (bridge used by the overhead crane only); throws common::ConfigError for
/// invalid parameters.
[[nodiscard]] std::unique_ptr<CraneDynamics> make_crane_dynamics(PlantKind kind, const common::CraneParameters& crane,
                                                                 const common::BridgeParameters& bridge,
                                                                 const HookParameters& hook = {},
                                                                 const RopeParameters& rope = {});

/// Commands held for one sample.
struct DriveInput {
  double trolley_voltage{0.0};  // [V] before the DAC
  double slew_voltage{0.0};     // [V] before the DAC: the slew drive (ignored on a gantry or overhead crane)
  double hoist_speed{0.0};      // [m/s] commanded dL/dt (positive lowers the load)
  bool brakes_engaged{true};    // both drive brakes
  double bridge_voltage{0.0};   // [V] before the DAC: the bridge drive (overhead crane only; ignored elsewhere)
};

struct SimulatorParameters {
  PlantKind kind{PlantKind::tower};
  common::CraneParameters crane{};
  common::BridgeParameters bridge{};   // overhead crane only
  double sample_period{0.01};          // [s] in (0, 1]
  IntegratorSettings integrator{};     // method; rtol and atol [-] in (0, 1e-2] (hybrid_integrator.hpp)
  double brake_holding_factor{20.0};   // [-] brake holding force / drive force at full DAC range, >= 0
  double hoist_max_acceleration{0.5};  // [m/s^2] > 0
  HookParameters hook{};               // tower crane only: the hook as a double pendulum (off by default)
  WindParameters wind{};               // tower crane only: wind on the load (off by default; needs load_mass > 0)
  RopeParameters rope{};               // tower crane only, no hook: the rope as a spring (off by default)
  PlantState initial_state{};          // finite; cable_length within the crane's [min_cable_length,
                                       // max_cable_length]; |swing| < pi/2
};

struct SimulatorOutput {
  common::CraneMeasurement measurement;  // quantized sensors of the current state (bridge_position: overhead
                                         // crane, through the trolley's encoder model; 0 elsewhere)
  double applied_trolley_voltage{0.0};   // [V] after the DAC, last sample
  double applied_slew_voltage{0.0};      // [V] after the DAC, last sample
  double applied_bridge_voltage{0.0};    // [V] after the DAC, last sample (overhead crane)
  double applied_hoist_speed{0.0};       // [m/s] rate-limited hoist speed at the end of the last sample
  bool brakes_engaged{true};             // last sample
};

class CraneSimulator {
 public:
  /// Validates everything (field names prefixed "simulator."); throws common::ConfigError.
  explicit CraneSimulator(const SimulatorParameters& parameters);

  /// Advances exactly one sample_period with `input` held (zero-order hold). noexcept.
  [[nodiscard]] common::StepStatus step(const DriveInput& input) noexcept;

  [[nodiscard]] SimulatorOutput output() const noexcept;
  /// True, unquantized state.
  [[nodiscard]] const PlantState& state() const noexcept { return state_; }
  /// Restarts at `state` and time 0 (counters are kept). Throws common::ConfigError like the
  /// constructor for an invalid state.
  void reset(const PlantState& state);
  /// [s] = number of samples since construction/reset times sample_period (no accumulation).
  [[nodiscard]] double time() const noexcept;

  /// The friction models of both drives for `crane`'s trolley_friction and slew_friction (the kind's
  /// second axis as at construction), to hand to set_friction later. Throws common::ConfigError for
  /// invalid coefficients.
  struct FrictionModels {
    AxisFrictionModel trolley;
    AxisFrictionModel second_axis;
  };
  [[nodiscard]] FrictionModels friction_models(const common::AxisFriction& trolley_friction,
                                               const common::AxisFriction& slew_friction) const;
  /// Friction from the next step on (a plant whose friction changes during a run). noexcept.
  void set_friction(const FrictionModels& models) noexcept {
    integrator_.set_friction(models.trolley, models.second_axis);
  }

  [[nodiscard]] long friction_event_count() const noexcept { return integrator_.friction_event_count(); }
  [[nodiscard]] long integrator_failure_count() const noexcept { return integrator_.solver_failure_count(); }
  /// The integrator's work since construction (steps, right-hand sides, restarts).
  [[nodiscard]] IntegratorWork integrator_work() const noexcept { return integrator_.work(); }
  [[nodiscard]] FrictionEvent last_friction_event() const noexcept { return integrator_.last_friction_event(); }
  [[nodiscard]] AxisMode axis_mode(FrictionAxis axis) const noexcept { return integrator_.mode(axis); }

  [[nodiscard]] const SimulatorParameters& parameters() const noexcept { return parameters_; }
  /// The crane's model (a TowerCraneModel, GantryCraneModel or OverheadCraneModel by kind).
  [[nodiscard]] const CraneDynamics& model() const noexcept { return *model_; }
  [[nodiscard]] const DrivesAndSensors& drives_and_sensors() const noexcept { return sensors_; }
  /// The wind force of the current sample [N], inertial frame ((0, 0) without wind).
  [[nodiscard]] const WindForce& wind() const noexcept { return wind_; }
  /// Total mechanical energy of the true state [J] (CraneDynamics::total_energy).
  [[nodiscard]] double total_energy() const noexcept;

 private:
  static const SimulatorParameters& validated(const SimulatorParameters& parameters);
  void validate_state(const PlantState& state) const;
  void refresh_state() noexcept;

  SimulatorParameters parameters_;
  std::unique_ptr<const CraneDynamics> model_;
  DrivesAndSensors sensors_;
  HybridIntegrator integrator_;
  WindForce wind_;
  PlantState state_{};
  std::int64_t sample_index_{0};
  double applied_trolley_voltage_{0.0};
  double applied_slew_voltage_{0.0};
  double applied_bridge_voltage_{0.0};
  double applied_hoist_speed_{0.0};
  bool brakes_engaged_{true};
};

}  // namespace crane::plant
