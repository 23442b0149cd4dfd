#include "crane/optimal_control/minimum_time.hpp"

#include <IpIpoptApplication.hpp>
#include <IpSolveStatistics.hpp>
#include <IpTNLP.hpp>

#include <Eigen/LU>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <mutex>
#include <string>

#include "crane/common/validation.hpp"
#include "crane/trajectory_planner/time_optimal_profile.hpp"
#include "crane/trajectory_planner/trapezoid_profile.hpp"

namespace crane::optimal_control {

namespace {

using plant::ExtendedMatrix;
using plant::ExtendedState;
using plant::ExtendedVector;
using plant::HoistMotion;
using plant::kSlewIndex;
using plant::kTrolleyIndex;

constexpr double kInfinity = 1e19;  // IPOPT's default nlp_upper_bound_inf
constexpr int kInputs = 3;          // a_trolley, a_second, a_hoist
constexpr int kMaxPassive = plant::kMaxCoordinates - 2;  // the coordinates without a drive
constexpr int kMaxNodeVariables = 2 * plant::kMaxCoordinates + 2 + kMaxDetunedPendulums * 2 * kMaxPassive + kInputs;

// The variables of one node: q (n), q' (n), L, L', the detuned pendulums' passive coordinates and
// rates (copies x 2 p), then the inputs.
struct Layout {
  int n{4};            // the model's coordinates
  int passive{2};      // p = n - 2, the coordinates without a drive
  int copies{0};       // detuned pendulums (MinimumTimeProblem::detuned_pendulums), the least-effort solve only
  int states{10};      // 2 n + 2 + copies 2 p
  int stride{13};      // states + inputs
  int nodes{101};      // N + 1
  int voltages{2};     // drives with a voltage row (1 on a gantry)
  [[nodiscard]] int position(int i) const { return i; }
  [[nodiscard]] int velocity(int i) const { return n + i; }
  [[nodiscard]] int cable_length() const { return 2 * n; }
  [[nodiscard]] int cable_rate() const { return 2 * n + 1; }
  /// Copy c's r-th passive coordinate (in the order of the model's coordinates) and its rate.
  [[nodiscard]] int copy_position(int c, int r) const { return 2 * n + 2 + c * 2 * passive + r; }
  [[nodiscard]] int copy_velocity(int c, int r) const { return 2 * n + 2 + c * 2 * passive + passive + r; }
  [[nodiscard]] int input(int j) const { return states + j; }
  [[nodiscard]] int duration_index() const { return nodes * stride; }
  [[nodiscard]] int variable_count() const { return nodes * stride + 1; }
  [[nodiscard]] int defect_rows() const { return (nodes - 1) * states; }
  [[nodiscard]] int constraint_count() const { return defect_rows() + nodes * voltages; }
};

using NodeVector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxNodeVariables, 1>;
using NodeJacobian = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxNodeVariables, kMaxNodeVariables>;

// [rad/s] The swing frequency of detuned pendulum c at the target, sqrt(g / (factor L_target)): it
// weighs the rate in the pendulum's residual amplitude (header: detuned_pendulums).
double detuned_frequency(const MinimumTimeProblem& problem, int c) {
  return std::sqrt(problem.model->parameters().gravity /
                   (problem.detuned_pendulums[static_cast<std::size_t>(c)] * problem.hoist.target));
}

bool second_axis_driven(const plant::CraneDynamics& model) {
  return model.drive_force_per_volt(plant::DriveAxis::second) > 0.0;
}

// The dynamics at one node: the state derivative (q', q'', L', L'') and the drive voltages.
class NodeDynamics {
 public:
  NodeDynamics(const MinimumTimeProblem& problem, const Layout& layout)
      : model_(problem.model->clone()),
        layout_(layout),
        detuned_(problem.detuned_pendulums),
        trolley_friction_(problem.trolley_friction),
        second_friction_(problem.second_friction),
        smoothing_(problem.friction_smoothing_speed),
        trolley_force_per_volt_(model_->drive_force_per_volt(plant::DriveAxis::trolley)),
        second_force_per_volt_(model_->drive_force_per_volt(plant::DriveAxis::second)) {}

  // z: the node's variables (states then inputs); derivative: states rows; voltage: layout.voltages.
  void evaluate(const double* z, NodeVector& derivative, NodeVector& voltage) const {
    const int n = layout_.n;
    ExtendedState s;
    for (int i = 0; i < n; ++i) {
      s.position[i] = z[layout_.position(i)];
      s.velocity[i] = z[layout_.velocity(i)];
    }
    const HoistMotion hoist{z[layout_.cable_length()], z[layout_.cable_rate()], z[layout_.input(2)]};
    ExtendedMatrix mass;
    ExtendedVector bias;
    model_->compute_extended_dynamics(s, hoist, mass, bias);

    ExtendedVector acceleration = ExtendedVector::Zero();
    acceleration[kTrolleyIndex] = z[layout_.input(0)];
    acceleration[kSlewIndex] = z[layout_.input(1)];
    int passive[plant::kMaxCoordinates];
    int p = 0;
    for (int i = 0; i < n; ++i) {
      if (i != kTrolleyIndex && i != kSlewIndex) passive[p++] = i;
    }
    // Passive rows: M_PP q''_P = -(b_P + M_PA a_A), Q_P = 0.
    const auto passive_accelerations = [&](const ExtendedMatrix& m, const ExtendedVector& b, ExtendedVector& a) {
      using PassiveMatrix =
          Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, plant::kMaxCoordinates, plant::kMaxCoordinates>;
      PassiveMatrix mpp(p, p);
      Eigen::Matrix<double, Eigen::Dynamic, 1, 0, plant::kMaxCoordinates, 1> rhs(p);
      for (int r = 0; r < p; ++r) {
        rhs[r] = -b[passive[r]] - m(passive[r], kTrolleyIndex) * a[kTrolleyIndex] -
                 m(passive[r], kSlewIndex) * a[kSlewIndex];
        for (int c = 0; c < p; ++c) mpp(r, c) = m(passive[r], passive[c]);
      }
      const auto solution = mpp.partialPivLu().solve(rhs).eval();
      for (int r = 0; r < p; ++r) a[passive[r]] = solution[r];
    };
    passive_accelerations(mass, bias, acceleration);

    derivative.resize(layout_.states);
    // The detuned pendulums (header: detuned_pendulums): the same drive motion, the hoist's length,
    // rate and acceleration scaled, their own passive coordinates.
    for (int c = 0; c < layout_.copies; ++c) {
      const double factor = detuned_[static_cast<std::size_t>(c)];
      ExtendedState copy = s;
      for (int r = 0; r < p; ++r) {
        copy.position[passive[r]] = z[layout_.copy_position(c, r)];
        copy.velocity[passive[r]] = z[layout_.copy_velocity(c, r)];
      }
      const HoistMotion copy_hoist{factor * hoist.cable_length, factor * hoist.cable_length_rate,
                                   factor * hoist.cable_length_acceleration};
      ExtendedMatrix copy_mass;
      ExtendedVector copy_bias;
      model_->compute_extended_dynamics(copy, copy_hoist, copy_mass, copy_bias);
      ExtendedVector copy_acceleration = acceleration;
      passive_accelerations(copy_mass, copy_bias, copy_acceleration);
      for (int r = 0; r < p; ++r) {
        derivative[layout_.copy_position(c, r)] = copy.velocity[passive[r]];
        derivative[layout_.copy_velocity(c, r)] = copy_acceleration[passive[r]];
      }
    }
    for (int i = 0; i < n; ++i) {
      derivative[layout_.position(i)] = s.velocity[i];
      derivative[layout_.velocity(i)] = acceleration[i];
    }
    derivative[layout_.cable_length()] = hoist.cable_length_rate;
    derivative[layout_.cable_rate()] = hoist.cable_length_acceleration;

    // Drive rows: Q_A = M_A. q'' + b_A.
    voltage.resize(layout_.voltages);
    const double trolley_force = mass.row(kTrolleyIndex).head(n).dot(acceleration.head(n)) + bias[kTrolleyIndex];
    voltage[0] = drive_voltage(trolley_force, trolley_force_per_volt_, s.velocity[kTrolleyIndex], trolley_friction_,
                               smoothing_);
    if (layout_.voltages > 1) {
      const double second_force = mass.row(kSlewIndex).head(n).dot(acceleration.head(n)) + bias[kSlewIndex];
      voltage[1] = drive_voltage(second_force, second_force_per_volt_, s.velocity[kSlewIndex], second_friction_,
                                 smoothing_);
    }
  }

  // Central differences of evaluate() over the node's variables (header: step 1e-6 scaled).
  void jacobian(const double* z, NodeJacobian& derivative_jacobian, NodeJacobian& voltage_jacobian) const {
    const int width = layout_.stride;
    derivative_jacobian.resize(layout_.states, width);
    voltage_jacobian.resize(layout_.voltages, width);
    double perturbed[kMaxNodeVariables];
    std::copy(z, z + width, perturbed);
    NodeVector f_plus, f_minus, v_plus, v_minus;
    for (int j = 0; j < width; ++j) {
      const double step = 1e-6 * (1.0 + std::abs(z[j]));
      perturbed[j] = z[j] + step;
      evaluate(perturbed, f_plus, v_plus);
      perturbed[j] = z[j] - step;
      evaluate(perturbed, f_minus, v_minus);
      perturbed[j] = z[j];
      derivative_jacobian.col(j) = (f_plus - f_minus) / (2.0 * step);
      voltage_jacobian.col(j) = (v_plus - v_minus) / (2.0 * step);
    }
  }

 private:
  std::unique_ptr<plant::CraneDynamics> model_;
  Layout layout_;
  std::vector<double> detuned_;  // the copies' length factors
  common::AxisFriction trolley_friction_;
  common::AxisFriction second_friction_;
  double smoothing_;
  double trolley_force_per_volt_;
  double second_force_per_volt_;
};

// The nonlinear program of the header for IPOPT.
class MinimumTimeProgram final : public Ipopt::TNLP {
 public:
  // fixed_duration > 0: the second, least-effort solve at that duration (header: least_effort).
  MinimumTimeProgram(const MinimumTimeProblem& problem, const Layout& layout, std::vector<double> initial_guess,
                     double fixed_duration = 0.0)
      : problem_(problem),
        layout_(layout),
        dynamics_(problem, layout),
        initial_(std::move(initial_guess)),
        input_scale_{problem.trolley.max_acceleration, problem.second.max_acceleration, problem.hoist.max_acceleration},
        fixed_duration_(fixed_duration) {
    // The detuned pendulums' residual swing at the end, weighted as an amplitude: (q / max_swing)^2 +
    // (q' / (omega max_swing))^2, omega = sqrt(g / (factor L_target)) (header: detuned_pendulums).
    for (int c = 0; c < layout_.copies; ++c) {
      const double omega = detuned_frequency(problem, c);
      for (int r = 0; r < layout_.passive; ++r) {
        residual_.push_back({layout_.duration_index() - layout_.stride + layout_.copy_position(c, r),
                             problem.detuned_weight / (problem.max_swing * problem.max_swing)});
        residual_.push_back({layout_.duration_index() - layout_.stride + layout_.copy_velocity(c, r),
                             problem.detuned_weight / std::pow(omega * problem.max_swing, 2)});
      }
    }
  }

  bool get_nlp_info(Ipopt::Index& n, Ipopt::Index& m, Ipopt::Index& nnz_jac_g, Ipopt::Index& nnz_h_lag,
                    IndexStyleEnum& index_style) override {
    n = layout_.variable_count();
    m = layout_.constraint_count();
    nnz_jac_g = (layout_.nodes - 1) * layout_.states * (2 * layout_.stride + 1) +
                layout_.nodes * layout_.voltages * layout_.stride;
    nnz_h_lag = 0;
    index_style = C_STYLE;
    return true;
  }

  bool get_bounds_info(Ipopt::Index n, Ipopt::Number* x_l, Ipopt::Number* x_u, Ipopt::Index m, Ipopt::Number* g_l,
                       Ipopt::Number* g_u) override {
    std::fill(x_l, x_l + n, -kInfinity);
    std::fill(x_u, x_u + n, kInfinity);
    const bool second_driven = layout_.voltages > 1;
    const bool hoisting = problem_.hoist.start != problem_.hoist.target;
    for (int k = 0; k < layout_.nodes; ++k) {
      double* lo = x_l + k * layout_.stride;
      double* hi = x_u + k * layout_.stride;
      const bool end = k == 0 || k == layout_.nodes - 1;
      auto axis = [&](int slot, int input, const AxisRange& range, bool driven) {
        if (!driven) {
          lo[layout_.position(slot)] = hi[layout_.position(slot)] = 0.0;
          lo[layout_.velocity(slot)] = hi[layout_.velocity(slot)] = 0.0;
          lo[layout_.input(input)] = hi[layout_.input(input)] = 0.0;
          return;
        }
        lo[layout_.position(slot)] = range.min_position;
        hi[layout_.position(slot)] = range.max_position;
        lo[layout_.velocity(slot)] = -range.max_speed;
        hi[layout_.velocity(slot)] = range.max_speed;
        lo[layout_.input(input)] = -range.max_acceleration;
        hi[layout_.input(input)] = range.max_acceleration;
        if (end) {
          lo[layout_.position(slot)] = hi[layout_.position(slot)] = k == 0 ? range.start : range.target;
          lo[layout_.velocity(slot)] = hi[layout_.velocity(slot)] = 0.0;
        }
      };
      axis(kTrolleyIndex, 0, problem_.trolley, true);
      axis(kSlewIndex, 1, problem_.second, second_driven);
      for (int i = 0; i < layout_.n; ++i) {
        if (i == kTrolleyIndex || i == kSlewIndex) continue;
        lo[layout_.position(i)] = end ? 0.0 : -problem_.max_swing;
        hi[layout_.position(i)] = end ? 0.0 : problem_.max_swing;
        if (end) lo[layout_.velocity(i)] = hi[layout_.velocity(i)] = 0.0;
      }
      for (int c = 0; c < layout_.copies; ++c) {  // at rest at the start; their end is in the objective
        for (int r = 0; r < layout_.passive; ++r) {
          if (k == 0) {
            lo[layout_.copy_position(c, r)] = hi[layout_.copy_position(c, r)] = 0.0;
            lo[layout_.copy_velocity(c, r)] = hi[layout_.copy_velocity(c, r)] = 0.0;
          }
        }
      }
      if (hoisting) {
        lo[layout_.cable_length()] = problem_.hoist.min_position;
        hi[layout_.cable_length()] = problem_.hoist.max_position;
        lo[layout_.cable_rate()] = end ? 0.0 : -problem_.hoist.max_speed;
        hi[layout_.cable_rate()] = end ? 0.0 : problem_.hoist.max_speed;
        lo[layout_.input(2)] = -problem_.hoist.max_acceleration;
        hi[layout_.input(2)] = problem_.hoist.max_acceleration;
        if (end) {
          lo[layout_.cable_length()] = hi[layout_.cable_length()] = k == 0 ? problem_.hoist.start : problem_.hoist.target;
        }
      } else {
        lo[layout_.cable_length()] = hi[layout_.cable_length()] = problem_.hoist.start;
        lo[layout_.cable_rate()] = hi[layout_.cable_rate()] = 0.0;
        lo[layout_.input(2)] = hi[layout_.input(2)] = 0.0;
      }
    }
    x_l[layout_.duration_index()] = fixed_duration_ > 0.0 ? fixed_duration_ : 1e-2;
    x_u[layout_.duration_index()] = fixed_duration_ > 0.0 ? fixed_duration_ : 1e3;
    std::fill(g_l, g_l + layout_.defect_rows(), 0.0);
    std::fill(g_u, g_u + layout_.defect_rows(), 0.0);
    std::fill(g_l + layout_.defect_rows(), g_l + m, -problem_.voltage_limit);
    std::fill(g_u + layout_.defect_rows(), g_u + m, problem_.voltage_limit);
    return true;
  }

  bool get_starting_point(Ipopt::Index n, bool init_x, Ipopt::Number* x, bool init_z, Ipopt::Number*, Ipopt::Number*,
                          Ipopt::Index, bool init_lambda, Ipopt::Number*) override {
    if (!init_x || init_z || init_lambda) return false;
    std::copy(initial_.begin(), initial_.begin() + n, x);
    return true;
  }

  // T + w sum_k sum_j ((u_j,k+1 - u_j,k) / a_j,max)^2 (header: the input smoothing); at a fixed
  // duration also (1 / (N + 1)) sum_k (sum_j (u_j,k / a_j,max)^2 + sum_i (q_i,k / max_swing)^2), i
  // the swings (header: least_effort).
  bool eval_f(Ipopt::Index, const Ipopt::Number* x, bool, Ipopt::Number& obj_value) override {
    obj_value = x[layout_.duration_index()];
    for (int k = 0; k + 1 < layout_.nodes; ++k) {
      for (int j = 0; j < kInputs; ++j) {
        const double d = (x[(k + 1) * layout_.stride + layout_.input(j)] - x[k * layout_.stride + layout_.input(j)]) /
                         input_scale_[j];
        obj_value += problem_.input_smoothing * d * d;
      }
    }
    if (fixed_duration_ > 0.0) {
      for (int k = 0; k < layout_.nodes; ++k) {
        for (int j = 0; j < kInputs; ++j) {
          const double u = x[k * layout_.stride + layout_.input(j)] / input_scale_[j];
          obj_value += u * u / layout_.nodes;
        }
        for (int i = 0; i < layout_.n; ++i) {
          if (i == kTrolleyIndex || i == kSlewIndex) continue;
          const double swing = x[k * layout_.stride + layout_.position(i)] / problem_.max_swing;
          obj_value += swing * swing / layout_.nodes;
        }
      }
      for (const auto& [index, weight] : residual_) obj_value += weight * x[index] * x[index];
    }
    return true;
  }

  bool eval_grad_f(Ipopt::Index n, const Ipopt::Number* x, bool, Ipopt::Number* grad_f) override {
    std::fill(grad_f, grad_f + n, 0.0);
    grad_f[layout_.duration_index()] = 1.0;
    for (int k = 0; k + 1 < layout_.nodes; ++k) {
      for (int j = 0; j < kInputs; ++j) {
        const int a = k * layout_.stride + layout_.input(j);
        const int b = a + layout_.stride;
        const double d = 2.0 * problem_.input_smoothing * (x[b] - x[a]) / (input_scale_[j] * input_scale_[j]);
        grad_f[b] += d;
        grad_f[a] -= d;
      }
    }
    if (fixed_duration_ > 0.0) {
      for (int k = 0; k < layout_.nodes; ++k) {
        for (int j = 0; j < kInputs; ++j) {
          const int a = k * layout_.stride + layout_.input(j);
          grad_f[a] += 2.0 * x[a] / (input_scale_[j] * input_scale_[j] * layout_.nodes);
        }
        for (int i = 0; i < layout_.n; ++i) {
          if (i == kTrolleyIndex || i == kSlewIndex) continue;
          const int a = k * layout_.stride + layout_.position(i);
          grad_f[a] += 2.0 * x[a] / (problem_.max_swing * problem_.max_swing * layout_.nodes);
        }
      }
      for (const auto& [index, weight] : residual_) grad_f[index] += 2.0 * weight * x[index];
    }
    return true;
  }

  bool eval_g(Ipopt::Index, const Ipopt::Number* x, bool, Ipopt::Index, Ipopt::Number* g) override {
    evaluate_constraints(x, g);
    return true;
  }

  bool eval_jac_g(Ipopt::Index, const Ipopt::Number* x, bool, Ipopt::Index, Ipopt::Index, Ipopt::Index* i_row,
                  Ipopt::Index* j_col, Ipopt::Number* values) override {
    const int stride = layout_.stride;
    const int states = layout_.states;
    const int N = layout_.nodes - 1;
    if (values == nullptr) {
      int e = 0;
      for (int k = 0; k < N; ++k) {
        for (int r = 0; r < states; ++r) {
          const int row = k * states + r;
          for (int c = 0; c < 2 * stride; ++c) {
            i_row[e] = row;
            j_col[e++] = k * stride + c;
          }
          i_row[e] = row;
          j_col[e++] = layout_.duration_index();
        }
      }
      for (int k = 0; k <= N; ++k) {
        for (int r = 0; r < layout_.voltages; ++r) {
          for (int c = 0; c < stride; ++c) {
            i_row[e] = layout_.defect_rows() + k * layout_.voltages + r;
            j_col[e++] = k * stride + c;
          }
        }
      }
      return true;
    }
    const double T = x[layout_.duration_index()];
    const double half_step = 0.5 * T / N;
    std::vector<NodeVector> f(layout_.nodes);
    std::vector<NodeJacobian> jf(layout_.nodes);
    std::vector<NodeJacobian> jv(layout_.nodes);
    NodeVector v;
    for (int k = 0; k <= N; ++k) {
      dynamics_.evaluate(x + k * stride, f[k], v);
      dynamics_.jacobian(x + k * stride, jf[k], jv[k]);
    }
    int e = 0;
    for (int k = 0; k < N; ++k) {
      for (int r = 0; r < states; ++r) {
        for (int c = 0; c < stride; ++c) values[e++] = (c == r ? -1.0 : 0.0) - half_step * jf[k](r, c);
        for (int c = 0; c < stride; ++c) values[e++] = (c == r ? 1.0 : 0.0) - half_step * jf[k + 1](r, c);
        values[e++] = -0.5 / N * (f[k][r] + f[k + 1][r]);
      }
    }
    for (int k = 0; k <= N; ++k) {
      for (int r = 0; r < layout_.voltages; ++r) {
        for (int c = 0; c < stride; ++c) values[e++] = jv[k](r, c);
      }
    }
    return true;
  }

  bool eval_h(Ipopt::Index, const Ipopt::Number*, bool, Ipopt::Number, Ipopt::Index, const Ipopt::Number*, bool,
              Ipopt::Index, Ipopt::Index*, Ipopt::Index*, Ipopt::Number*) override {
    return false;  // limited-memory quasi-Newton
  }

  void finalize_solution(Ipopt::SolverReturn status, Ipopt::Index n, const Ipopt::Number* x, const Ipopt::Number*,
                         const Ipopt::Number*, Ipopt::Index, const Ipopt::Number*, const Ipopt::Number*, Ipopt::Number,
                         const Ipopt::IpoptData*, Ipopt::IpoptCalculatedQuantities*) override {
    solver_return_ = status;
    solution_.assign(x, x + n);
  }

  void evaluate_constraints(const double* x, double* g) const {
    const int stride = layout_.stride;
    const int N = layout_.nodes - 1;
    const double half_step = 0.5 * x[layout_.duration_index()] / N;
    NodeVector f_k, f_next, v;
    dynamics_.evaluate(x, f_k, v);
    for (int r = 0; r < layout_.voltages; ++r) g[layout_.defect_rows() + r] = v[r];
    for (int k = 0; k < N; ++k) {
      dynamics_.evaluate(x + (k + 1) * stride, f_next, v);
      for (int r = 0; r < layout_.voltages; ++r) g[layout_.defect_rows() + (k + 1) * layout_.voltages + r] = v[r];
      for (int r = 0; r < layout_.states; ++r) {
        g[k * layout_.states + r] =
            x[(k + 1) * stride + r] - x[k * stride + r] - half_step * (f_k[r] + f_next[r]);
      }
      f_k = f_next;
    }
  }

  [[nodiscard]] const std::vector<double>& solution() const { return solution_; }
  [[nodiscard]] Ipopt::SolverReturn solver_return() const { return solver_return_; }
  [[nodiscard]] const NodeDynamics& dynamics() const { return dynamics_; }

 private:
  const MinimumTimeProblem& problem_;
  Layout layout_;
  NodeDynamics dynamics_;
  std::vector<double> initial_;
  double input_scale_[kInputs];
  double fixed_duration_;
  std::vector<std::pair<int, double>> residual_;  // the last node's detuned variables and their weights
  std::vector<double> solution_;
  Ipopt::SolverReturn solver_return_{Ipopt::INTERNAL_ERROR};
};

const char* solver_return_name(Ipopt::SolverReturn status) {
  switch (status) {
    case Ipopt::SUCCESS: return "Solve_Succeeded";
    case Ipopt::MAXITER_EXCEEDED: return "Maximum_Iterations_Exceeded";
    case Ipopt::CPUTIME_EXCEEDED: return "Maximum_CpuTime_Exceeded";
    case Ipopt::STOP_AT_TINY_STEP: return "Search_Direction_Becomes_Too_Small";
    case Ipopt::STOP_AT_ACCEPTABLE_POINT: return "Solved_To_Acceptable_Level";
    case Ipopt::LOCAL_INFEASIBILITY: return "Infeasible_Problem_Detected";
    case Ipopt::USER_REQUESTED_STOP: return "User_Requested_Stop";
    case Ipopt::DIVERGING_ITERATES: return "Diverging_Iterates";
    case Ipopt::RESTORATION_FAILURE: return "Restoration_Failed";
    case Ipopt::ERROR_IN_STEP_COMPUTATION: return "Error_In_Step_Computation";
    case Ipopt::INVALID_NUMBER_DETECTED: return "Invalid_Number_Detected";
    case Ipopt::TOO_FEW_DEGREES_OF_FREEDOM: return "Not_Enough_Degrees_Of_Freedom";
    default: return "Internal_Error";
  }
}

void validate_axis(const std::string& name, const AxisRange& axis) {
  common::require_finite(name + ".min_position", axis.min_position);
  common::require_finite(name + ".max_position", axis.max_position);
  common::require_greater(name + ".max_position", axis.max_position, axis.min_position);
  common::require_in_range(name + ".start", axis.start, axis.min_position, axis.max_position);
  common::require_in_range(name + ".target", axis.target, axis.min_position, axis.max_position);
  common::require_greater(name + ".max_speed", axis.max_speed, 0.0);
  common::require_finite(name + ".max_speed", axis.max_speed);
  common::require_greater(name + ".max_acceleration", axis.max_acceleration, 0.0);
  common::require_finite(name + ".max_acceleration", axis.max_acceleration);
}

// The initial guess of the header: each axis on its linear profile, the passive coordinates by RK4
// along it, stretched to the longest axis.
std::vector<double> initial_guess(const MinimumTimeProblem& problem, const Layout& layout, double& duration,
                                  double min_duration = 0.0) {
  namespace tp = trajectory_planner;
  const double gravity = problem.model->parameters().gravity;
  const bool second_driven = layout.voltages > 1;
  tp::TimeOptimalProfile trolley;
  tp::TimeOptimalProfile second;
  tp::TrapezoidProfile hoist;
  const double frequency = std::sqrt(gravity / std::max(problem.hoist.start, problem.hoist.target));
  (void)trolley.plan(problem.trolley.start, problem.trolley.target,
                     {problem.trolley.max_speed, problem.trolley.max_acceleration}, frequency);
  if (second_driven) {
    (void)second.plan(problem.second.start, problem.second.target,
                      {problem.second.max_speed, problem.second.max_acceleration}, frequency);
  }
  hoist.plan(problem.hoist.start, problem.hoist.target, {problem.hoist.max_speed, problem.hoist.max_acceleration});
  duration = std::max({trolley.duration(), second.duration(), hoist.duration(), 0.1, min_duration});

  std::vector<double> x(static_cast<std::size_t>(layout.variable_count()), 0.0);
  const int N = layout.nodes - 1;
  NodeDynamics dynamics(problem, layout);
  NodeVector z(layout.stride);
  NodeVector k1, k2, k3, k4, v;
  auto set_drives = [&](NodeVector& node, double t) {
    const common::AxisReference a = trolley.sample(t);
    node[layout.position(kTrolleyIndex)] = a.position;
    node[layout.velocity(kTrolleyIndex)] = a.velocity;
    node[layout.input(0)] = a.acceleration;
    if (second_driven) {
      const common::AxisReference b = second.sample(t);
      node[layout.position(kSlewIndex)] = b.position;
      node[layout.velocity(kSlewIndex)] = b.velocity;
      node[layout.input(1)] = b.acceleration;
    }
    const common::AxisReference h = hoist.sample(t);
    node[layout.cable_length()] = problem.hoist.start == problem.hoist.target ? problem.hoist.start : h.position;
    node[layout.cable_rate()] = problem.hoist.start == problem.hoist.target ? 0.0 : h.velocity;
    node[layout.input(2)] = problem.hoist.start == problem.hoist.target ? 0.0 : h.acceleration;
  };
  z.setZero();
  set_drives(z, 0.0);
  constexpr int kSubsteps = 10;
  const double h = duration / N / kSubsteps;
  for (int k = 0; k <= N; ++k) {
    std::copy(z.data(), z.data() + layout.stride, x.begin() + k * layout.stride);
    if (k == N) break;
    for (int s = 0; s < kSubsteps; ++s) {
      // RK4 on the passive coordinates; the drives follow their profiles exactly.
      const double t = (k * kSubsteps + s) * h;
      NodeVector stage = z;
      dynamics.evaluate(stage.data(), k1, v);
      stage.head(layout.states) = z.head(layout.states) + 0.5 * h * k1;
      set_drives(stage, t + 0.5 * h);
      dynamics.evaluate(stage.data(), k2, v);
      stage.head(layout.states) = z.head(layout.states) + 0.5 * h * k2;
      set_drives(stage, t + 0.5 * h);
      dynamics.evaluate(stage.data(), k3, v);
      stage.head(layout.states) = z.head(layout.states) + h * k3;
      set_drives(stage, t + h);
      dynamics.evaluate(stage.data(), k4, v);
      z.head(layout.states) += h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
      set_drives(z, t + h);
    }
    for (int i = 0; i < layout.n; ++i) {  // keep the guess inside the swing bound
      if (i == kTrolleyIndex || i == kSlewIndex) continue;
      z[layout.position(i)] = std::clamp(z[layout.position(i)], -problem.max_swing, problem.max_swing);
    }
  }
  x[static_cast<std::size_t>(layout.duration_index())] = duration;
  return x;
}

}  // namespace

double drive_voltage(double force, double force_per_volt, double velocity, const common::AxisFriction& friction,
                     double smoothing_speed) noexcept {
  const double positive = 0.5 * (1.0 + std::tanh(velocity / smoothing_speed));
  const double friction_volts = positive * (friction.coulomb_positive + friction.viscous_positive * velocity) +
                                (1.0 - positive) * (-friction.coulomb_negative + friction.viscous_negative * velocity);
  return force / force_per_volt + friction_volts;
}

void validate(const MinimumTimeProblem& problem) {
  if (!problem.model) throw common::ConfigError("minimum_time.model: no crane model");
  const int n = problem.model->coordinate_count();
  if (n != plant::kNumCoordinates && n != plant::kMaxCoordinates) {
    throw common::ConfigError("minimum_time.model: plant.rope.enabled = true is not modelled by the bound (its rest "
                              "stretch depends on the cable length); coordinates = " + std::to_string(n));
  }
  validate_axis("minimum_time.trolley", problem.trolley);
  if (second_axis_driven(*problem.model)) validate_axis("minimum_time.second", problem.second);
  validate_axis("minimum_time.hoist", problem.hoist);
  common::require_greater("minimum_time.hoist.min_position", problem.hoist.min_position, 0.0);
  common::require_greater("minimum_time.voltage_limit", problem.voltage_limit, 0.0);
  common::require_finite("minimum_time.voltage_limit", problem.voltage_limit);
  common::require_in_range("minimum_time.max_swing", problem.max_swing, 1e-3, 1.5);
  common::require_in_range("minimum_time.friction_smoothing_speed", problem.friction_smoothing_speed, 1e-6, 1.0);
  common::require_in_range("minimum_time.intervals", problem.intervals, 4, 2000);
  common::require_in_range("minimum_time.input_smoothing", problem.input_smoothing, 0.0, 1.0);
  common::require_in_range("minimum_time.tolerance", problem.tolerance, 1e-14, 1e-2);
  common::require_in_range("minimum_time.max_iterations", problem.max_iterations, 1, 1e6);
  common::require_in_range("minimum_time.least_effort_margin", problem.least_effort_margin, 0.0, 0.5);
  common::require_in_range("minimum_time.least_effort_tolerance", problem.least_effort_tolerance, 1e-14, 1e-2);
  for (const double stretch : problem.restart_stretch) {
    common::require_in_range("minimum_time.restart_stretch", stretch, 1.0, 10.0);
  }
  for (const double stretch : problem.fallback_stretch) {
    common::require_in_range("minimum_time.fallback_stretch", stretch, 1.0, 10.0);
  }
  if (problem.detuned_pendulums.size() > static_cast<std::size_t>(kMaxDetunedPendulums)) {
    throw common::ConfigError("minimum_time.detuned_pendulums: " + std::to_string(problem.detuned_pendulums.size()) +
                              " pendulums, at most " + std::to_string(kMaxDetunedPendulums));
  }
  for (const double factor : problem.detuned_pendulums) {
    common::require_in_range("minimum_time.detuned_pendulums", factor, 0.5, 2.0);
  }
  common::require_in_range("minimum_time.detuned_weight", problem.detuned_weight, 0.0, 1e12);
  common::require_in_range("minimum_time.detuned_max_iterations", problem.detuned_max_iterations, 1, 1e6);
  common::validate(problem.trolley_friction, "minimum_time.trolley_friction");
  common::validate(problem.second_friction, "minimum_time.second_friction");
}

namespace {
bool solved_status(Ipopt::ApplicationReturnStatus status) {
  return status == Ipopt::Solve_Succeeded || status == Ipopt::Solved_To_Acceptable_Level;
}
}  // namespace

MinimumTimeResult solve_minimum_time(const MinimumTimeProblem& problem) {
  validate(problem);
  Layout layout;
  layout.n = problem.model->coordinate_count();
  layout.passive = layout.n - 2;
  layout.states = 2 * layout.n + 2;
  layout.stride = layout.states + kInputs;
  layout.nodes = problem.intervals + 1;
  layout.voltages = second_axis_driven(*problem.model) ? 2 : 1;
  // The least-effort solve's, with the detuned pendulums (the fallback's has none).
  Layout effort_layout = layout;
  effort_layout.copies = static_cast<int>(problem.detuned_pendulums.size());
  effort_layout.states += effort_layout.copies * 2 * effort_layout.passive;
  effort_layout.stride = effort_layout.states + kInputs;

  MinimumTimeResult result;
  std::vector<double> guess = initial_guess(problem, layout, result.initial_guess_duration);
  Ipopt::SmartPtr<MinimumTimeProgram> program = new MinimumTimeProgram(problem, layout, std::move(guess));
  // One solve at a time in the process: IPOPT's linear solver here, Debian's sequential MUMPS, keeps
  // global state (two concurrent solves abort in DMUMPS_LOAD_INIT or corrupt the heap; measured
  // with crane_sim compare on two threads).
  static std::mutex mumps;
  const std::lock_guard lock(mumps);
  Ipopt::SmartPtr<Ipopt::IpoptApplication> app = IpoptApplicationFactory();
  app->Options()->SetIntegerValue("print_level", 0);
  app->Options()->SetStringValue("sb", "yes");
  app->Options()->SetStringValue("hessian_approximation", "limited-memory");
  app->Options()->SetNumericValue("tol", problem.tolerance);
  app->Options()->SetNumericValue("constr_viol_tol", 1e-9);
  app->Options()->SetIntegerValue("max_iter", problem.max_iterations);
  app->Options()->SetStringValue("mu_strategy", "adaptive");
  if (app->Initialize() != Ipopt::Solve_Succeeded) {
    result.status = "Ipopt_Initialization_Failed";
    return result;
  }
  const auto start = std::chrono::steady_clock::now();
  Ipopt::ApplicationReturnStatus status = app->OptimizeTNLP(program);
  // Not solved from the profiles' guess: again from it stretched in time (restart_stretch).
  for (const double stretch : problem.restart_stretch) {
    if (solved_status(status)) break;
    double stretched_duration = 0.0;
    program = new MinimumTimeProgram(
        problem, layout, initial_guess(problem, layout, stretched_duration, stretch * result.initial_guess_duration));
    status = app->OptimizeTNLP(program);
    ++result.restarts;
  }
  result.status = solver_return_name(program->solver_return());  // the minimum-time solve's, the last
  result.solved = solved_status(status);
  // Still not solved: a trajectory at a fixed, longer duration (fallback_stretch), the least-effort
  // program, which needs no free duration.
  app->Options()->SetNumericValue("tol", problem.least_effort_tolerance);
  for (const double stretch : problem.fallback_stretch) {
    if (solved_status(status)) break;
    const double duration = stretch * result.initial_guess_duration;
    double guess_duration = 0.0;
    program = new MinimumTimeProgram(problem, layout, initial_guess(problem, layout, guess_duration, duration), duration);
    status = app->OptimizeTNLP(program);
    result.fallback = solved_status(status);
  }
  if (result.fallback) result.effort_status = solver_return_name(program->solver_return());
  if (IsValid(app->Statistics())) result.iterations = app->Statistics()->IterationCount();
  const std::vector<double>* solution = &program->solution();
  if (solution->size() != static_cast<std::size_t>(layout.variable_count())) {
    result.solved = false;
    result.fallback = false;
    return result;
  }
  // The least-effort solve at (1 + least_effort_margin) T* (header: least_effort), from the initial
  // guess at that duration, and where IPOPT does not solve it at twice and four times the margin;
  // its solution replaces the first only where IPOPT solved it.
  result.duration = (*solution)[static_cast<std::size_t>(layout.duration_index())];
  const Layout* solution_layout = &layout;
  const MinimumTimeProgram* solution_program = GetRawPtr(program);
  Ipopt::SmartPtr<MinimumTimeProgram> effort;
  // With detuned pendulums, the first attempt carries them, within detuned_max_iterations; where
  // it does not solve, the attempts run again without them (header: detuned_max_iterations).
  app->Options()->SetNumericValue("tol", problem.least_effort_tolerance);
  bool robust = effort_layout.copies > 0;
  for (int attempt = 0; result.solved && problem.least_effort && !result.least_effort && attempt < 3;) {
    const Layout& attempt_layout = robust ? effort_layout : layout;
    app->Options()->SetIntegerValue("max_iter", robust ? problem.detuned_max_iterations : problem.max_iterations);
    const double duration = result.duration * (1.0 + problem.least_effort_margin * (1 << attempt));
    double guess_duration = 0.0;
    std::vector<double> guess_at = initial_guess(problem, attempt_layout, guess_duration, duration);
    effort = new MinimumTimeProgram(problem, attempt_layout, std::move(guess_at), duration);
    const Ipopt::ApplicationReturnStatus effort_status = app->OptimizeTNLP(effort);
    result.effort_status = solver_return_name(effort->solver_return());
    if (IsValid(app->Statistics())) result.effort_iterations += app->Statistics()->IterationCount();
    if (solved_status(effort_status) &&
        effort->solution().size() == static_cast<std::size_t>(attempt_layout.variable_count())) {
      solution = &effort->solution();
      solution_layout = &attempt_layout;
      solution_program = GetRawPtr(effort);
      result.least_effort = true;
      result.robust = robust;
    } else if (robust) {
      robust = false;  // the same attempt again, without the copies
      continue;
    }
    ++attempt;
  }
  result.solve_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const std::vector<double>& x = *solution;
  const Layout& chosen = *solution_layout;

  std::vector<double> g(static_cast<std::size_t>(chosen.constraint_count()));
  solution_program->evaluate_constraints(x.data(), g.data());
  for (int r = 0; r < chosen.defect_rows(); ++r) result.max_defect = std::max(result.max_defect, std::abs(g[r]));
  const double* last = x.data() + (chosen.nodes - 1) * chosen.stride;
  for (int c = 0; c < chosen.copies; ++c) {
    double& residual = result.detuned_residual_swing[static_cast<std::size_t>(c)];
    const double omega = detuned_frequency(problem, c);
    for (int r = 0; r < chosen.passive; ++r) {
      residual =
          std::max(residual, std::hypot(last[chosen.copy_position(c, r)], last[chosen.copy_velocity(c, r)] / omega));
    }
  }

  result.trajectory_duration = x[static_cast<std::size_t>(chosen.duration_index())];
  result.nodes.resize(static_cast<std::size_t>(chosen.nodes));
  for (int k = 0; k < chosen.nodes; ++k) {
    const double* z = x.data() + k * chosen.stride;
    TrajectoryNode& node = result.nodes[static_cast<std::size_t>(k)];
    node.time = result.trajectory_duration * k / problem.intervals;
    for (int i = 0; i < chosen.n; ++i) {
      node.state.position[i] = z[chosen.position(i)];
      node.state.velocity[i] = z[chosen.velocity(i)];
    }
    node.cable_length = z[chosen.cable_length()];
    node.cable_length_rate = z[chosen.cable_rate()];
    node.trolley_acceleration = z[chosen.input(0)];
    node.second_acceleration = z[chosen.input(1)];
    node.hoist_acceleration = z[chosen.input(2)];
    const double* v = g.data() + chosen.defect_rows() + k * chosen.voltages;
    node.trolley_voltage = v[0];
    node.second_voltage = chosen.voltages > 1 ? v[1] : 0.0;
  }
  return result;
}

TrajectoryNode sample(const MinimumTimeResult& result, double time) {
  if (result.nodes.empty()) return {};
  if (result.nodes.size() == 1 || !(time > 0.0)) return result.nodes.front();
  if (time >= result.trajectory_duration) return result.nodes.back();
  const double position = time / result.trajectory_duration * static_cast<double>(result.nodes.size() - 1);
  const std::size_t k = std::min(static_cast<std::size_t>(position), result.nodes.size() - 2);
  const double w = position - static_cast<double>(k);
  const TrajectoryNode& a = result.nodes[k];
  const TrajectoryNode& b = result.nodes[k + 1];
  auto mix = [w](double p, double q) { return (1.0 - w) * p + w * q; };
  TrajectoryNode s;
  s.time = time;
  s.state.position = (1.0 - w) * a.state.position + w * b.state.position;
  s.state.velocity = (1.0 - w) * a.state.velocity + w * b.state.velocity;
  s.cable_length = mix(a.cable_length, b.cable_length);
  s.cable_length_rate = mix(a.cable_length_rate, b.cable_length_rate);
  s.trolley_acceleration = mix(a.trolley_acceleration, b.trolley_acceleration);
  s.second_acceleration = mix(a.second_acceleration, b.second_acceleration);
  s.hoist_acceleration = mix(a.hoist_acceleration, b.hoist_acceleration);
  s.trolley_voltage = mix(a.trolley_voltage, b.trolley_voltage);
  s.second_voltage = mix(a.second_voltage, b.second_voltage);
  return s;
}

}  // namespace crane::optimal_control
