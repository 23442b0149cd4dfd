#pragma once
// The plant stage: what the plant process computes each cycle, without DDS, clock or thread. The
// simulated crane (CraneSimulator) behind the actuation gate the hardware bridge applies too
// (supervisor/actuation_gate.hpp):
//   sample(k):  the SensorSample of cycle k (seq k; quantized encoders, the voltages applied during
//               the previous cycle, the brakes) - the measurement possibly delayed (mismatch);
//   step(in):   the gate turns the command and the supervisor's permit into drive voltages (or 0 V
//               and brakes), held over [k, k+1) while the nonlinear model is integrated; k -> k+1.
// A plant may differ from the configured crane (robustness studies: PlantMismatch): the
// controllers keep assuming the configuration, the plant simulates the truth.

#include <array>
#include <cstdint>
#include <optional>
#include <span>

#include "crane/common/stack_facts.hpp"
#include "crane/plant/crane_simulator.hpp"
#include "crane/protocol/messages.hpp"
#include "crane/supervisor/actuation_gate.hpp"

namespace crane::config {
class YamlSection;
}

namespace crane::plant {

/// How the simulated crane differs from the configured one (all 1 / 0: not at all).
struct PlantMismatch {
  double cable_length_factor{1.0};  // [-] simulated L = factor x configured L, in [0.1, 10]; the sensors
                                    // still report the configured L (the lab crane has no hoist encoder)
  double load_mass_factor{1.0};     // [-] simulated load mass = factor x configured, in [0, 10]
  double friction_factor{1.0};      // [-] every friction coefficient of both drives x factor, in [0, 10]
  int sensor_delay_cycles{0};       // [cycles] the sample of cycle k reports the encoders of k - d, in [0, 16]
  // A plant whose friction changes during a run (wear, temperature; the online re-estimation's test):
  // from cycle friction_change_cycle on, every friction coefficient of both drives is
  // friction_change_factor times what it was (friction_factor included). 1: off (the default; the
  // simulation is then bit-identical to a plant without the option).
  double friction_change_factor{1.0};     // [-] in [0.1, 10]
  std::uint64_t friction_change_cycle{0};  // [cycles] the first cycle integrated with the changed friction
};
/// Throws common::ConfigError naming the field ("plant.mismatch.<name>"), the value and the bound.
void validate(const PlantMismatch& mismatch);
/// The command lines' `--mismatch L M F` (crane_sim, crane_site demo's --plant-mismatch): the cable
/// length, load mass and friction factors [-], every other field nominal. std::invalid_argument for
/// a count other than 3; the ranges are validate()'s, checked where the plant is made.
[[nodiscard]] PlantMismatch mismatch_from_factors(std::span<const double> factors);

struct PlantStageParams {
  SimulatorParameters simulator{};   // the configured crane, integrator settings, initial state
  supervisor::ActuationGateParams gate{};
  PlantMismatch mismatch{};
};

/// Reads the `plant:` block (integrator: a method name of hybrid_integrator.hpp; relative_tolerance
/// [-] in [1e-14, 1e-3], absolute_tolerance [-] in [1e-16, 1e-3],
/// brake_holding_factor [-] in [1, 1000], hoist_max_acceleration [m/s^2] in [1e-3, 100]); the
/// crane, its kind (crane.kind) and bridge (crane.bridge), sample period from facts; the initial state at rest with the crane's cable length. The
/// gate's params are read from `actuation:` by supervisor::read_actuation_params. Throws
/// common::ConfigError naming the field.
[[nodiscard]] SimulatorParameters read_params(config::YamlSection& block, const common::StackFacts& facts);

class PlantStage {
 public:
  static constexpr int kMaxSensorDelay = 16;  // [cycles]

  /// Throws common::ConfigError for invalid params (simulator, gate or mismatch).
  explicit PlantStage(const PlantStageParams& params);

  /// The sensor sample of the current cycle: header.seq = cycle(), source SOURCE_PLANT; the
  /// header's stamp and origin and writer_pid are the caller's. Never throws.
  void sample(protocol::SensorSample& sensors) const noexcept;

  /// Gates `input` and integrates the current cycle over one sample period; cycle() + 1. ok, or the
  /// simulator's failure (the cycle still counts; the state is the integrator's last). Never throws.
  [[nodiscard]] common::StepStatus step(const supervisor::GateInput& input) noexcept;

  [[nodiscard]] std::uint64_t cycle() const noexcept { return cycle_; }
  [[nodiscard]] const supervisor::GateOutput& gate_output() const noexcept { return gate_output_; }
  /// What the simulator held over the last cycle (the gate's output as drive input).
  [[nodiscard]] const DriveInput& drive_input() const noexcept { return drive_; }
  [[nodiscard]] const supervisor::ActuationGate& gate() const noexcept { return gate_; }
  [[nodiscard]] const CraneSimulator& simulator() const noexcept { return simulator_; }
  [[nodiscard]] const PlantMismatch& mismatch() const noexcept { return mismatch_; }

 private:
  void remember_measurement() noexcept;

  PlantMismatch mismatch_;
  CraneSimulator simulator_;
  supervisor::ActuationGate gate_;
  supervisor::GateOutput gate_output_{};
  DriveInput drive_{};
  double cable_length_reading_factor_{1.0};
  std::uint64_t cycle_{0};
  std::array<common::CraneMeasurement, kMaxSensorDelay + 1> measurements_{};  // ring, by cycle
  std::optional<CraneSimulator::FrictionModels> changed_friction_;  // applied at friction_change_cycle
};

/// The simulated crane: `configured` with `mismatch` applied (cable length, load mass, friction).
[[nodiscard]] SimulatorParameters simulated_truth(const SimulatorParameters& configured, const PlantMismatch& mismatch);

}  // namespace crane::plant
