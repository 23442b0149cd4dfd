#pragma once
// Hybrid integrator of a crane (any CraneDynamics: tower, gantry, overhead) with stick-slip friction: a RAII wrapper around one
// SUNDIALS 6.4 solver, chosen by IntegratorSettings::method (plant.integrator in the config):
//   dormand_prince  ARKODE ERKStep, Dormand-Prince 5(4) (ARKODE_DORMAND_PRINCE_7_4_5), the default;
//   verner          ARKODE ERKStep, Verner 6(5) (ARKODE_VERNER_8_5_6);
//   adams           CVODE Adams-Moulton (orders 1-12) with fixed-point iteration;
//   bdf             CVODE BDF (orders 1-5), Newton with a dense SUNMatrix + dense SUNLinearSolver and
//                   CVODE's difference-quotient Jacobian.
// The choice and its figures: docs/integration.md (the convergence study and the comparison).
//
// State y (10, or 14 for a model with a hook): q = (x, phi, second axis, theta[, phi2, theta2]),
// q_dot, L, L_dot. Model: a CraneDynamics
// (crane_dynamics.hpp: TowerCraneModel (2.11)-(2.16), GantryCraneModel (2.5)-(2.6),
// OverheadCraneModel); friction: AxisFrictionModel ((3.1)-(3.3) as plant truth) on the trolley (x)
// and the second drive axis (slew gamma, or the overhead crane's bridge y; the gantry's is held);
// hoist: L_ddot held constant over each advance (zero-order hold).
//
// Friction switching is an explicit hybrid automaton per axis, never a smoothed sign() or a tiny
// fixed step:
//   slipping (+/-): friction is the smooth sliding law of the current direction; root function is
//                   the axis velocity. At its zero crossing the axis either sticks (driving force
//                   within the holding limits) or continues in the opposite direction.
//   stuck:          the axis velocity and acceleration are constrained to zero; the other
//                   coordinates move under the reduced equations and the friction force that holds
//                   the axis follows from the eliminated row. Root function is the stick margin
//                   (holding limit minus driving force); at its zero crossing the axis breaks away.
// Events are located by the solver's root finding (CVodeRootInit, ERKStepRootInit), then the mode
// switches and the solver restarts at the event time. A changed input (a ZOH step at a sample
// boundary) also restarts it: no step ever integrates across a discontinuity of the right-hand
// side. An explicit Runge-Kutta restart keeps the step size the solver had reached (one-step
// methods carry no other history); a multistep (CVODE) restart begins again at order 1.
//
// Every advance lands exactly on the requested end time (a stop time at the end of each advance).
// advance_to() is noexcept and, with every method but bdf, allocation-free (all N_Vectors and
// matrices are created in the constructor; tests/plant/test_plant_allocation.cpp counts). bdf
// allocates at each linear-solver setup (CVODE's difference-quotient Jacobian clones a vector
// header). The constructor throws std::runtime_error if SUNDIALS cannot allocate.

#include <array>
#include <memory>
#include <string_view>

#include <sundials/sundials_context.hpp>
#include <sundials/sundials_linearsolver.h>
#include <sundials/sundials_matrix.h>
#include <sundials/sundials_nonlinearsolver.h>
#include <sundials/sundials_nvector.h>

#include "crane/plant/axis_friction.hpp"
#include "crane/plant/crane_dynamics.hpp"

namespace crane::plant {

/// The two axes with friction and brakes: the trolley and the second axis (slew on a tower crane,
/// bridge on an overhead crane).
enum class FrictionAxis : int { trolley = 0, slew = 1, bridge = 1 };
inline constexpr int kNumFrictionAxes = 2;

enum class AxisMode : int { slipping_positive, slipping_negative, stuck };

/// Inputs held constant (zero-order hold) over one advance.
struct SampleInput {
  double trolley_drive_force{0.0};        // [N] F_x from the drive (friction excluded)
  double slew_drive_torque{0.0};          // [N m] T_gamma from the drive (friction excluded); the
                                          // bridge drive force [N] on an overhead crane
  double cable_length_acceleration{0.0};  // [m/s^2] L_ddot
  double load_force_x{0.0};               // [N] horizontal force on the load (wind), inertial x
  double load_force_y{0.0};               // [N] inertial y (CraneDynamics::load_force)
  bool brakes_engaged{false};             // both drive brakes
  bool operator==(const SampleInput&) const = default;
};

/// The solver of IntegratorSettings::method (the header's comment lists what each is).
enum class IntegrationMethod : int { dormand_prince, verner, adams, bdf };

/// The config's name of `method` ("dormand_prince", "verner", "adams", "bdf").
[[nodiscard]] std::string_view integration_method_name(IntegrationMethod method) noexcept;
/// The method named `name`; throws common::ConfigError naming `field`, the value and the names allowed.
[[nodiscard]] IntegrationMethod parse_integration_method(std::string_view name, std::string_view field);

struct IntegratorSettings {
  // The default: measured (docs/integration.md): every printed figure of every demo maneuver of
  // the three crane kinds agrees with the reference, at 2300x real time for the in-process demo.
  IntegrationMethod method{IntegrationMethod::dormand_prince};
  double relative_tolerance{1e-9};   // [-] rtol, > 0
  double absolute_tolerance{1e-11};  // [SI of each state] atol, > 0
  long max_steps_per_advance{100000};  // the solver's mxstep
  int max_events_per_advance{1000};    // friction events per advance before giving up
};

/// Work done by the solver since construction (each restart included).
struct IntegratorWork {
  long steps{0};                 // accepted steps
  long right_hand_sides{0};      // evaluations of the dynamics by the solver (stages, Jacobians by difference
                                 // quotients); root-function evaluations not included
  long root_evaluations{0};      // evaluations of the root functions (each evaluates the dynamics once)
  long restarts{0};              // re-initialisations: input changes and friction events
  long jacobian_setups{0};       // linear-solver setups (bdf only)
};

enum class [[nodiscard]] IntegrationStatus {
  ok,
  invalid_request,   // end time not after the current time, or non-finite input
  solver_failure,    // the solver failed; the state was restored to the start of the advance
  too_many_events,   // event storm; the state was restored to the start of the advance
};

/// One mode change of a friction axis.
struct FrictionEvent {
  double time{0.0};  // [s]
  FrictionAxis axis{FrictionAxis::trolley};
  AxisMode new_mode{AxisMode::stuck};
};

class HybridIntegrator {
 public:
  /// Copies the model (CraneDynamics::clone) and frictions. Throws common::ConfigError for invalid settings (field names
  /// prefixed "integrator."), std::runtime_error if SUNDIALS fails to allocate.
  HybridIntegrator(const CraneDynamics& model, const AxisFrictionModel& trolley_friction,
                   const AxisFrictionModel& slew_friction, const IntegratorSettings& settings);
  ~HybridIntegrator();
  HybridIntegrator(const HybridIntegrator&) = delete;
  HybridIntegrator& operator=(const HybridIntegrator&) = delete;
  HybridIntegrator(HybridIntegrator&&) = delete;
  HybridIntegrator& operator=(HybridIntegrator&&) = delete;

  /// Sets time [s], state and hoist (L [m] > 0, L_dot [m/s]); friction modes are decided from the
  /// state (velocity sign, or stick/breakaway at zero velocity) under the current input.
  void reset(double time, const ModelState& state, double cable_length, double cable_length_rate) noexcept;
  /// The same for a model with more than four coordinates (slots beyond coordinate_count() ignored).
  void reset(double time, const ExtendedState& state, double cable_length, double cable_length_rate) noexcept;

  /// Integrates to exactly `end_time` [s] (> time()) with `input` held constant. noexcept,
  /// allocation-free. On failure the state is restored to its value before the call and time()
  /// still becomes end_time.
  IntegrationStatus advance_to(double end_time, const SampleInput& input) noexcept;

  /// Replaces the friction of both axes from the next advance on (a plant whose friction changes
  /// during a run, PlantMismatch::friction_change_factor); an axis at rest is decided again under the
  /// new breakaway. noexcept, allocation-free.
  void set_friction(const AxisFrictionModel& trolley_friction, const AxisFrictionModel& slew_friction) noexcept;

  [[nodiscard]] double time() const noexcept { return time_; }
  [[nodiscard]] ModelState state() const noexcept;
  /// All coordinates (slots beyond coordinate_count() are 0).
  [[nodiscard]] ExtendedState extended_state() const noexcept;
  /// The model's coordinate_count(): 4, or 6 with a hook.
  [[nodiscard]] int coordinate_count() const noexcept { return coordinates_; }
  [[nodiscard]] double cable_length() const noexcept;       // [m]
  [[nodiscard]] double cable_length_rate() const noexcept;  // [m/s]
  [[nodiscard]] AxisMode mode(FrictionAxis axis) const noexcept { return modes_[index(axis)]; }
  /// Driving force [N] (trolley) or torque [N m] (slew) that friction holds while the axis is stuck;
  /// 0 when slipping.
  [[nodiscard]] double holding_force(FrictionAxis axis) const noexcept;

  [[nodiscard]] long friction_event_count() const noexcept { return friction_event_count_; }
  [[nodiscard]] long solver_failure_count() const noexcept { return solver_failure_count_; }
  [[nodiscard]] FrictionEvent last_friction_event() const noexcept { return last_event_; }
  [[nodiscard]] const IntegratorSettings& settings() const noexcept { return settings_; }
  /// The solver's counters summed over its restarts. noexcept.
  [[nodiscard]] IntegratorWork work() const noexcept;

 private:
  static int index(FrictionAxis axis) noexcept { return static_cast<int>(axis); }
  static int right_hand_side(double t, N_Vector y, N_Vector y_dot, void* user_data);
  static int root_functions(double t, N_Vector y, double* g, void* user_data);

  // Evaluates the hybrid dynamics at y with `modes`; writes y_dot if non-null and the driving force
  // of each stuck axis.
  void evaluate(const double* y, const std::array<AxisMode, kNumFrictionAxes>& modes, double* y_dot,
                std::array<double, kNumFrictionAxes>& driving_force) const noexcept;
  template <int N>
  void evaluate_with(const double* y, const std::array<AxisMode, kNumFrictionAxes>& modes, double* y_dot,
                     std::array<double, kNumFrictionAxes>& driving_force) const noexcept;
  int velocity_offset() const noexcept { return coordinates_; }
  int cable_length_index() const noexcept { return 2 * coordinates_; }
  int cable_length_rate_index() const noexcept { return 2 * coordinates_ + 1; }
  void settle_modes() noexcept;
  void release() noexcept;
  bool explicit_runge_kutta() const noexcept { return settings_.method <= IntegrationMethod::verner; }
  // The solver's part: restart at (time_, y_), integrate toward end_time (returns the SUNDIALS flag,
  // normalized: 0 reached end_time, 2 a root, < 0 failure), and which roots were found.
  bool solver_restart() noexcept;
  int solver_evolve(double end_time, double& reached) noexcept;
  void solver_root_info(int* found) noexcept;
  IntegratorWork solver_counters() const noexcept;  // steps and setups of the solver's run since its last restart
  void bank_counters() noexcept;
  void set_mode(int axis, AxisMode mode) noexcept;
  const AxisFrictionModel& friction(int axis) const noexcept { return axis == 0 ? trolley_friction_ : slew_friction_; }

  std::unique_ptr<const CraneDynamics> model_;
  int coordinates_{kNumCoordinates};  // the model's coordinate_count()
  int state_size_{2 * kNumCoordinates + 2};
  AxisFrictionModel trolley_friction_;
  AxisFrictionModel slew_friction_;
  IntegratorSettings settings_;

  sundials::Context context_;
  N_Vector y_{nullptr};
  N_Vector y_saved_{nullptr};
  SUNMatrix jacobian_{nullptr};
  SUNLinearSolver linear_solver_{nullptr};
  SUNNonlinearSolver nonlinear_solver_{nullptr};  // adams: fixed-point iteration
  void* cvode_memory_{nullptr};                   // adams, bdf
  void* arkode_memory_{nullptr};                  // the explicit Runge-Kutta methods
  IntegratorWork banked_work_{};                  // counters of the solver's runs before its last restart
  long right_hand_side_count_{0};
  long root_evaluation_count_{0};

  double time_{0.0};
  SampleInput input_{};
  std::array<AxisMode, kNumFrictionAxes> modes_{AxisMode::slipping_positive, AxisMode::slipping_positive};
  std::array<bool, kNumFrictionAxes> decision_pending_{true, true};
  bool needs_reinit_{true};
  long friction_event_count_{0};
  long solver_failure_count_{0};
  FrictionEvent last_event_{};
};

}  // namespace crane::plant
