#include "crane/plant/hybrid_integrator.hpp"

#include <Eigen/LU>
#include <cmath>
#include <stdexcept>
#include <type_traits>

#include <arkode/arkode_erkstep.h>
#include <cvode/cvode.h>
#include <nvector/nvector_serial.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunmatrix/sunmatrix_dense.h>
#include <sunnonlinsol/sunnonlinsol_fixedpoint.h>

#include "crane/common/validation.hpp"

namespace crane::plant {

namespace {

// Layout of the state vector: positions from 0, velocities from coordinates_ (velocity_offset()),
// then L and L_dot (cable_length_index(), cable_length_rate_index()).
constexpr int kPositionOffset = 0;

// solver_evolve()'s outcomes besides a failure (< 0).
constexpr int kReachedEnd = 0;
constexpr int kRootFound = 2;

// Generalized coordinate of each friction axis.
constexpr std::array<int, kNumFrictionAxes> kAxisCoordinate{kTrolleyIndex, kSlewIndex};

void silent_error_handler(int, const char*, const char*, char*, void*) {}

AxisMode slipping(int direction) {
  return direction >= 0 ? AxisMode::slipping_positive : AxisMode::slipping_negative;
}

void check(int flag, const char* what) {
  // CV_SUCCESS and ARK_SUCCESS are both 0.
  if (flag != 0) throw std::runtime_error(std::string("HybridIntegrator: ") + what + " failed");
}

constexpr std::array<std::pair<IntegrationMethod, std::string_view>, 4> kMethodNames{{
    {IntegrationMethod::dormand_prince, "dormand_prince"},
    {IntegrationMethod::verner, "verner"},
    {IntegrationMethod::adams, "adams"},
    {IntegrationMethod::bdf, "bdf"},
}};

ARKODE_ERKTableID butcher_table(IntegrationMethod method) {
  return method == IntegrationMethod::verner ? ARKODE_VERNER_8_5_6 : ARKODE_DORMAND_PRINCE_7_4_5;
}

}  // namespace

std::string_view integration_method_name(IntegrationMethod method) noexcept {
  for (const auto& [m, name] : kMethodNames) {
    if (m == method) return name;
  }
  return "unknown";
}

IntegrationMethod parse_integration_method(std::string_view name, std::string_view field) {
  std::string allowed;
  for (const auto& [m, n] : kMethodNames) {
    if (n == name) return m;
    allowed += (allowed.empty() ? "" : ", ") + std::string(n);
  }
  throw common::ConfigError(std::string(field) + " = '" + std::string(name) + "' is not one of " + allowed);
}

HybridIntegrator::HybridIntegrator(const CraneDynamics& model, const AxisFrictionModel& trolley_friction,
                                 const AxisFrictionModel& slew_friction, const IntegratorSettings& settings)
    : model_(model.clone()),
      coordinates_(model_->coordinate_count()),
      state_size_(2 * coordinates_ + 2),
      trolley_friction_(trolley_friction), slew_friction_(slew_friction), settings_(settings) {
  common::require_greater("integrator.relative_tolerance", settings.relative_tolerance, 0.0);
  common::require_greater("integrator.absolute_tolerance", settings.absolute_tolerance, 0.0);
  common::require_at_least("integrator.max_steps_per_advance", static_cast<double>(settings.max_steps_per_advance),
                           1.0);
  common::require_at_least("integrator.max_events_per_advance",
                           static_cast<double>(settings.max_events_per_advance), 1.0);

  y_ = N_VNew_Serial(state_size_, context_);
  y_saved_ = N_VNew_Serial(state_size_, context_);
  if (y_ == nullptr || y_saved_ == nullptr) {
    release();
    throw std::runtime_error("HybridIntegrator: SUNDIALS allocation failed");
  }
  N_VConst(0.0, y_);
  NV_Ith_S(y_, cable_length_index()) = model_->parameters().cable_length;
  try {
    if (explicit_runge_kutta()) {
      arkode_memory_ = ERKStepCreate(&HybridIntegrator::right_hand_side, 0.0, y_, context_);
      if (arkode_memory_ == nullptr) throw std::runtime_error("HybridIntegrator: ERKStepCreate failed");
      check(ERKStepSetErrHandlerFn(arkode_memory_, silent_error_handler, nullptr), "ERKStepSetErrHandlerFn");
      check(ERKStepSetTableNum(arkode_memory_, butcher_table(settings.method)), "ERKStepSetTableNum");
      check(ERKStepSStolerances(arkode_memory_, settings.relative_tolerance, settings.absolute_tolerance),
            "ERKStepSStolerances");
      check(ERKStepSetUserData(arkode_memory_, this), "ERKStepSetUserData");
      check(ERKStepRootInit(arkode_memory_, kNumFrictionAxes, &HybridIntegrator::root_functions), "ERKStepRootInit");
      check(ERKStepSetNoInactiveRootWarn(arkode_memory_), "ERKStepSetNoInactiveRootWarn");
      check(ERKStepSetMaxNumSteps(arkode_memory_, settings.max_steps_per_advance), "ERKStepSetMaxNumSteps");
    } else {
      const bool bdf = settings.method == IntegrationMethod::bdf;
      cvode_memory_ = CVodeCreate(bdf ? CV_BDF : CV_ADAMS, context_);
      if (cvode_memory_ == nullptr) throw std::runtime_error("HybridIntegrator: CVodeCreate failed");
      check(CVodeSetErrHandlerFn(cvode_memory_, silent_error_handler, nullptr), "CVodeSetErrHandlerFn");
      check(CVodeInit(cvode_memory_, &HybridIntegrator::right_hand_side, 0.0, y_), "CVodeInit");
      check(CVodeSStolerances(cvode_memory_, settings.relative_tolerance, settings.absolute_tolerance),
            "CVodeSStolerances");
      check(CVodeSetUserData(cvode_memory_, this), "CVodeSetUserData");
      if (bdf) {
        jacobian_ = SUNDenseMatrix(state_size_, state_size_, context_);
        if (jacobian_ == nullptr) throw std::runtime_error("HybridIntegrator: SUNDenseMatrix failed");
        linear_solver_ = SUNLinSol_Dense(y_, jacobian_, context_);
        if (linear_solver_ == nullptr) throw std::runtime_error("HybridIntegrator: SUNLinSol_Dense failed");
        check(CVodeSetLinearSolver(cvode_memory_, linear_solver_, jacobian_), "CVodeSetLinearSolver");
      } else {
        nonlinear_solver_ = SUNNonlinSol_FixedPoint(y_, 0, context_);
        if (nonlinear_solver_ == nullptr) throw std::runtime_error("HybridIntegrator: SUNNonlinSol_FixedPoint failed");
        check(CVodeSetNonlinearSolver(cvode_memory_, nonlinear_solver_), "CVodeSetNonlinearSolver");
      }
      check(CVodeRootInit(cvode_memory_, kNumFrictionAxes, &HybridIntegrator::root_functions), "CVodeRootInit");
      check(CVodeSetNoInactiveRootWarn(cvode_memory_), "CVodeSetNoInactiveRootWarn");
      check(CVodeSetMaxNumSteps(cvode_memory_, settings.max_steps_per_advance), "CVodeSetMaxNumSteps");
    }
  } catch (...) {
    release();
    throw;
  }
  ModelState rest;
  reset(0.0, rest, model_->parameters().cable_length, 0.0);
}

HybridIntegrator::~HybridIntegrator() { release(); }

void HybridIntegrator::release() noexcept {
  if (arkode_memory_ != nullptr) ERKStepFree(&arkode_memory_);
  if (cvode_memory_ != nullptr) CVodeFree(&cvode_memory_);
  if (nonlinear_solver_ != nullptr) SUNNonlinSolFree(nonlinear_solver_);
  if (linear_solver_ != nullptr) SUNLinSolFree(linear_solver_);
  if (jacobian_ != nullptr) SUNMatDestroy(jacobian_);
  if (y_saved_ != nullptr) N_VDestroy(y_saved_);
  if (y_ != nullptr) N_VDestroy(y_);
  arkode_memory_ = nullptr;
  cvode_memory_ = nullptr;
  nonlinear_solver_ = nullptr;
  linear_solver_ = nullptr;
  jacobian_ = nullptr;
  y_saved_ = nullptr;
  y_ = nullptr;
}

void HybridIntegrator::evaluate(const double* y, const std::array<AxisMode, kNumFrictionAxes>& modes, double* y_dot,
                               std::array<double, kNumFrictionAxes>& driving_force) const noexcept {
  if (coordinates_ == kMaxCoordinates) {
    evaluate_with<kMaxCoordinates>(y, modes, y_dot, driving_force);
  } else if (coordinates_ == kNumCoordinates + 1) {
    evaluate_with<kNumCoordinates + 1>(y, modes, y_dot, driving_force);
  } else {
    evaluate_with<kNumCoordinates>(y, modes, y_dot, driving_force);
  }
}

// N = 4: the model's compute_dynamics (the single pendulum); N = 6 (a hook) and N = 5 (an elastic
// rope, the first five of the extended rows): compute_extended_dynamics. The same arithmetic in all.
template <int N>
void HybridIntegrator::evaluate_with(const double* y, const std::array<AxisMode, kNumFrictionAxes>& modes,
                                    double* y_dot, std::array<double, kNumFrictionAxes>& driving_force) const noexcept {
  using Matrix = Eigen::Matrix<double, N, N>;
  using Vector = Eigen::Matrix<double, N, 1>;
  const int velocity_offset = N;
  std::conditional_t<N == kNumCoordinates, ModelState, ExtendedState> state;
  for (int j = 0; j < N; ++j) {
    state.position[j] = y[kPositionOffset + j];
    state.velocity[j] = y[velocity_offset + j];
  }
  const HoistMotion hoist{y[2 * N], y[2 * N + 1], input_.cable_length_acceleration};
  Matrix mass;
  Vector bias;
  if constexpr (N == kNumCoordinates) {
    model_->compute_dynamics(state, hoist, mass, bias);
  } else if constexpr (N == kMaxCoordinates) {
    model_->compute_extended_dynamics(state, hoist, mass, bias);
  } else {
    ExtendedMatrix full_mass;
    ExtendedVector full_bias;
    model_->compute_extended_dynamics(state, hoist, full_mass, full_bias);
    mass = full_mass.template topLeftCorner<N, N>();
    bias = full_bias.template head<N>();
  }

  // Generalized forces (2.15): drives plus the sliding friction of slipping axes, plus a force on
  // the load (wind) when there is one.
  Vector force = Vector::Zero();
  if (input_.load_force_x != 0.0 || input_.load_force_y != 0.0) {
    ExtendedState extended;
    extended.position.head<N>() = state.position.template head<N>();
    extended.velocity.head<N>() = state.velocity.template head<N>();
    force += model_->load_force(extended, hoist, input_.load_force_x, input_.load_force_y).template head<N>();
  }
  force[kTrolleyIndex] = input_.trolley_drive_force;
  force[kSlewIndex] = input_.slew_drive_torque;
  for (int a = 0; a < kNumFrictionAxes; ++a) {
    if (modes[a] == AxisMode::stuck) continue;
    const int j = kAxisCoordinate[a];
    const int direction = modes[a] == AxisMode::slipping_positive ? 1 : -1;
    force[j] += friction(a).sliding_force(state.velocity[j], direction, input_.brakes_engaged);
  }
  const Vector rhs = force - bias;

  // Stuck axes: q_dd_j = 0 is imposed by replacing row and column j with the identity (column j
  // multiplies q_dd_j = 0); the friction that holds the axis is the residual of the original row j.
  Matrix constrained = mass;
  Vector constrained_rhs = rhs;
  for (int a = 0; a < kNumFrictionAxes; ++a) {
    if (modes[a] != AxisMode::stuck) continue;
    const int j = kAxisCoordinate[a];
    constrained.row(j).setZero();
    constrained.col(j).setZero();
    constrained(j, j) = 1.0;
    constrained_rhs[j] = 0.0;
  }
  const Vector q_dd = constrained.partialPivLu().solve(constrained_rhs);
  for (int a = 0; a < kNumFrictionAxes; ++a) {
    const int j = kAxisCoordinate[a];
    // Driving force D = everything but the holding friction: friction must supply -D.
    driving_force[a] = modes[a] == AxisMode::stuck ? rhs[j] - mass.row(j).dot(q_dd) : 0.0;
  }
  if (y_dot == nullptr) return;
  for (int j = 0; j < N; ++j) {
    y_dot[kPositionOffset + j] = state.velocity[j];
    y_dot[velocity_offset + j] = q_dd[j];
  }
  for (int a = 0; a < kNumFrictionAxes; ++a) {
    if (modes[a] == AxisMode::stuck) y_dot[kPositionOffset + kAxisCoordinate[a]] = 0.0;
  }
  y_dot[2 * N] = hoist.cable_length_rate;
  y_dot[2 * N + 1] = hoist.cable_length_acceleration;
}

int HybridIntegrator::right_hand_side(double, N_Vector y, N_Vector y_dot, void* user_data) {
  auto* self = static_cast<HybridIntegrator*>(user_data);
  ++self->right_hand_side_count_;
  std::array<double, kNumFrictionAxes> driving{};
  self->evaluate(N_VGetArrayPointer(y), self->modes_, N_VGetArrayPointer(y_dot), driving);
  for (int i = 0; i < self->state_size_; ++i) {
    if (!std::isfinite(NV_Ith_S(y_dot, i))) return 1;  // recoverable: the solver retries with a smaller step
  }
  return 0;
}

int HybridIntegrator::root_functions(double, N_Vector y, double* g, void* user_data) {
  auto* self = static_cast<HybridIntegrator*>(user_data);
  ++self->root_evaluation_count_;
  const double* values = N_VGetArrayPointer(y);
  std::array<double, kNumFrictionAxes> driving{};
  self->evaluate(values, self->modes_, nullptr, driving);
  for (int a = 0; a < kNumFrictionAxes; ++a) {
    if (self->modes_[a] == AxisMode::stuck) {
      g[a] = self->friction(a).stick_margin(driving[a], self->input_.brakes_engaged);
    } else {
      g[a] = values[self->velocity_offset() + kAxisCoordinate[a]];
    }
  }
  return 0;
}

void HybridIntegrator::set_mode(int axis, AxisMode mode) noexcept {
  if (modes_[axis] == mode) return;
  const bool counts_as_event = mode == AxisMode::stuck || modes_[axis] == AxisMode::stuck;
  modes_[axis] = mode;
  if (!counts_as_event) return;
  ++friction_event_count_;
  last_event_ = FrictionEvent{time_, static_cast<FrictionAxis>(axis), mode};
}

void HybridIntegrator::settle_modes() noexcept {
  double* y = N_VGetArrayPointer(y_);
  // A few passes: a mode change of one axis changes the driving force on the other.
  for (int pass = 0; pass < 2 * kNumFrictionAxes + 1; ++pass) {
    bool changed = false;
    for (int a = 0; a < kNumFrictionAxes; ++a) {
      const int velocity_index = velocity_offset() + kAxisCoordinate[a];
      const AxisMode before = modes_[a];
      if (modes_[a] == AxisMode::stuck) {
        std::array<double, kNumFrictionAxes> driving{};
        evaluate(y, modes_, nullptr, driving);
        const int motion = friction(a).motion_at_rest(driving[a], input_.brakes_engaged);
        if (motion != 0) set_mode(a, slipping(motion));
      } else if (decision_pending_[a] && y[velocity_index] == 0.0) {
        // At rest: would the axis stay stuck if held? Evaluate with it constrained.
        std::array<AxisMode, kNumFrictionAxes> trial = modes_;
        trial[a] = AxisMode::stuck;
        std::array<double, kNumFrictionAxes> driving{};
        evaluate(y, trial, nullptr, driving);
        const int motion = friction(a).motion_at_rest(driving[a], input_.brakes_engaged);
        set_mode(a, motion == 0 ? AxisMode::stuck : slipping(motion));
        decision_pending_[a] = false;
      } else if (y[velocity_index] != 0.0) {
        // Direction follows the velocity (only differs from the mode after a reset or a missed root).
        set_mode(a, slipping(y[velocity_index] > 0.0 ? 1 : -1));
        decision_pending_[a] = false;
      }
      if (modes_[a] != before) changed = true;
      if (modes_[a] == AxisMode::stuck) {
        y[velocity_index] = 0.0;
        decision_pending_[a] = false;
      }
    }
    if (!changed) break;
  }
}

void HybridIntegrator::reset(double time, const ModelState& state, double cable_length,
                            double cable_length_rate) noexcept {
  ExtendedState extended;
  extended.position.head<kNumCoordinates>() = state.position;
  extended.velocity.head<kNumCoordinates>() = state.velocity;
  reset(time, extended, cable_length, cable_length_rate);
}

void HybridIntegrator::reset(double time, const ExtendedState& state, double cable_length,
                            double cable_length_rate) noexcept {
  time_ = time;
  double* y = N_VGetArrayPointer(y_);
  for (int j = 0; j < coordinates_; ++j) {
    y[kPositionOffset + j] = state.position[j];
    y[velocity_offset() + j] = state.velocity[j];
  }
  y[cable_length_index()] = cable_length;
  y[cable_length_rate_index()] = cable_length_rate;
  modes_ = {AxisMode::slipping_positive, AxisMode::slipping_positive};
  decision_pending_ = {true, true};
  // The initial mode decision is not a friction event.
  const long event_count = friction_event_count_;
  const FrictionEvent last_event = last_event_;
  settle_modes();
  friction_event_count_ = event_count;
  last_event_ = last_event;
  needs_reinit_ = true;
}

void HybridIntegrator::set_friction(const AxisFrictionModel& trolley_friction,
                                   const AxisFrictionModel& slew_friction) noexcept {
  trolley_friction_ = trolley_friction;
  slew_friction_ = slew_friction;
  const double* y = N_VGetArrayPointer(y_);
  for (int a = 0; a < kNumFrictionAxes; ++a) {
    if (y[velocity_offset() + kAxisCoordinate[a]] == 0.0) decision_pending_[a] = true;
  }
  settle_modes();
  needs_reinit_ = true;
}

IntegrationStatus HybridIntegrator::advance_to(double end_time, const SampleInput& input) noexcept {
  if (!std::isfinite(end_time) || !(end_time > time_) || !std::isfinite(input.trolley_drive_force) ||
      !std::isfinite(input.slew_drive_torque) || !std::isfinite(input.cable_length_acceleration) ||
      !std::isfinite(input.load_force_x) || !std::isfinite(input.load_force_y)) {
    return IntegrationStatus::invalid_request;
  }
  N_VScale(1.0, y_, y_saved_);
  const auto saved_modes = modes_;
  if (!(input == input_)) {
    if (input.brakes_engaged != input_.brakes_engaged) {
      // The brake changes what holds an axis at rest: one at exactly zero velocity is decided again
      // (a frictionless axis that slipped at rest with the brake off would otherwise keep its
      // direction, and the engaged brake's sliding force would push it from rest).
      const double* y = N_VGetArrayPointer(y_);
      for (int a = 0; a < kNumFrictionAxes; ++a) {
        if (y[velocity_offset() + kAxisCoordinate[a]] == 0.0) decision_pending_[a] = true;
      }
    }
    input_ = input;
    settle_modes();
    needs_reinit_ = true;
  }
  IntegrationStatus status = IntegrationStatus::ok;
  int events = 0;
  while (time_ < end_time) {
    if (needs_reinit_) {
      if (!solver_restart()) {
        status = IntegrationStatus::solver_failure;
        break;
      }
      needs_reinit_ = false;
    }
    double reached = time_;
    const int flag = solver_evolve(end_time, reached);
    if (flag == kRootFound) {
      time_ = reached;
      int found[kNumFrictionAxes] = {0, 0};
      solver_root_info(found);
      double* y = N_VGetArrayPointer(y_);
      std::array<double, kNumFrictionAxes> driving{};
      evaluate(y, modes_, nullptr, driving);
      for (int a = 0; a < kNumFrictionAxes; ++a) {
        if (found[a] == 0) continue;
        if (modes_[a] == AxisMode::stuck) {
          // Stick margin crossed zero: break away toward the driving force.
          set_mode(a, slipping(driving[a] >= 0.0 ? 1 : -1));
          decision_pending_[a] = false;
        } else {
          // Velocity crossed zero: snap it, then stick or reverse (decided in settle_modes).
          y[velocity_offset() + kAxisCoordinate[a]] = 0.0;
          decision_pending_[a] = true;
        }
      }
      settle_modes();
      needs_reinit_ = true;
      if (++events > settings_.max_events_per_advance) {
        status = IntegrationStatus::too_many_events;
        break;
      }
      continue;
    }
    if (flag == kReachedEnd) {
      time_ = end_time;
      break;
    }
    status = IntegrationStatus::solver_failure;
    break;
  }
  if (status != IntegrationStatus::ok) {
    ++solver_failure_count_;
    N_VScale(1.0, y_saved_, y_);
    modes_ = saved_modes;
    time_ = end_time;
    needs_reinit_ = true;
  }
  return status;
}

bool HybridIntegrator::solver_restart() noexcept {
  bank_counters();
  ++banked_work_.restarts;
  if (arkode_memory_ != nullptr) {
    // A one-step method keeps nothing across a restart but its step size: start where it was (the
    // first restart estimates one).
    double step = 0.0;
    if (banked_work_.restarts > 1 && ERKStepGetCurrentStep(arkode_memory_, &step) != ARK_SUCCESS) step = 0.0;
    if (ERKStepReInit(arkode_memory_, &HybridIntegrator::right_hand_side, time_, y_) != ARK_SUCCESS) return false;
    return ERKStepSetInitStep(arkode_memory_, std::isfinite(step) ? std::abs(step) : 0.0) == ARK_SUCCESS;
  }
  return CVodeReInit(cvode_memory_, time_, y_) == CV_SUCCESS;
}

int HybridIntegrator::solver_evolve(double end_time, double& reached) noexcept {
  if (arkode_memory_ != nullptr) {
    if (ERKStepSetStopTime(arkode_memory_, end_time) != ARK_SUCCESS) return -1;
    const int flag = ERKStepEvolve(arkode_memory_, end_time, y_, &reached, ARK_NORMAL);
    if (flag == ARK_ROOT_RETURN) return kRootFound;
    if (flag == ARK_TSTOP_RETURN || flag == ARK_SUCCESS) return kReachedEnd;
    return flag < 0 ? flag : -1;
  }
  if (CVodeSetStopTime(cvode_memory_, end_time) != CV_SUCCESS) return -1;
  const int flag = CVode(cvode_memory_, end_time, y_, &reached, CV_NORMAL);
  if (flag == CV_ROOT_RETURN) return kRootFound;
  if (flag == CV_TSTOP_RETURN || flag == CV_SUCCESS) return kReachedEnd;
  return flag < 0 ? flag : -1;
}

void HybridIntegrator::solver_root_info(int* found) noexcept {
  if (arkode_memory_ != nullptr) {
    ERKStepGetRootInfo(arkode_memory_, found);
  } else {
    CVodeGetRootInfo(cvode_memory_, found);
  }
}

IntegratorWork HybridIntegrator::solver_counters() const noexcept {
  IntegratorWork run;
  if (arkode_memory_ != nullptr) {
    if (ERKStepGetNumSteps(arkode_memory_, &run.steps) != ARK_SUCCESS) run.steps = 0;
  } else {
    if (CVodeGetNumSteps(cvode_memory_, &run.steps) != CV_SUCCESS) run.steps = 0;
    if (linear_solver_ != nullptr && CVodeGetNumLinSolvSetups(cvode_memory_, &run.jacobian_setups) != CV_SUCCESS) {
      run.jacobian_setups = 0;
    }
  }
  return run;
}

void HybridIntegrator::bank_counters() noexcept {
  // Both solvers zero their counters at a re-initialisation: add them up before it.
  const IntegratorWork run = solver_counters();
  banked_work_.steps += run.steps;
  banked_work_.jacobian_setups += run.jacobian_setups;
}

IntegratorWork HybridIntegrator::work() const noexcept {
  const IntegratorWork run = solver_counters();
  IntegratorWork w = banked_work_;
  w.steps += run.steps;
  w.jacobian_setups += run.jacobian_setups;
  w.right_hand_sides = right_hand_side_count_;
  w.root_evaluations = root_evaluation_count_;
  return w;
}

ExtendedState HybridIntegrator::extended_state() const noexcept {
  const double* y = N_VGetArrayPointer(y_);
  ExtendedState state;
  for (int j = 0; j < coordinates_; ++j) {
    state.position[j] = y[kPositionOffset + j];
    state.velocity[j] = y[velocity_offset() + j];
  }
  for (int a = 0; a < kNumFrictionAxes; ++a) {
    if (modes_[a] == AxisMode::stuck) state.velocity[kAxisCoordinate[a]] = 0.0;
  }
  return state;
}

ModelState HybridIntegrator::state() const noexcept {
  const double* y = N_VGetArrayPointer(y_);
  ModelState state;
  for (int j = 0; j < kNumCoordinates; ++j) {
    state.position[j] = y[kPositionOffset + j];
    state.velocity[j] = y[velocity_offset() + j];
  }
  for (int a = 0; a < kNumFrictionAxes; ++a) {
    if (modes_[a] == AxisMode::stuck) state.velocity[kAxisCoordinate[a]] = 0.0;
  }
  return state;
}

double HybridIntegrator::cable_length() const noexcept { return NV_Ith_S(y_, cable_length_index()); }

double HybridIntegrator::cable_length_rate() const noexcept { return NV_Ith_S(y_, cable_length_rate_index()); }

double HybridIntegrator::holding_force(FrictionAxis axis) const noexcept {
  const int a = index(axis);
  if (modes_[a] != AxisMode::stuck) return 0.0;
  std::array<double, kNumFrictionAxes> driving{};
  evaluate(N_VGetArrayPointer(y_), modes_, nullptr, driving);
  return driving[a];
}

}  // namespace crane::plant
