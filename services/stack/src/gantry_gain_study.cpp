#include "crane/stack/gantry_gain_study.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <stdexcept>
#include <string>

#include "crane/common/validation.hpp"
#include "crane/gain_scheduling/gain_schedule.hpp"
#include "crane/plant/crane_simulator.hpp"
#include "crane/stack/maneuver_metrics.hpp"

namespace crane::stack {

namespace {

namespace gs = crane::gain_scheduling;

constexpr double kSamplePeriod = 0.01;  // [s] the stack's 100 Hz

// The gantry crane of section 3.2.2 with load ratio m_t and cable length L: frictionless trolley.
common::CraneParameters study_crane(double mass_ratio, double cable_length) {
  common::CraneParameters crane;
  crane.trolley_drive_gain = kGantryStudyDriveGain;
  crane.trolley_drive_mass = kGantryStudyDriveMass;
  crane.trolley_mass = kGantryStudyDriveMass;
  crane.load_mass = mass_ratio * kGantryStudyDriveMass;
  crane.trolley_friction = {};
  crane.min_cable_length = 0.2;
  crane.max_cable_length = 10.0;
  crane.cable_length = cable_length;
  return crane;
}

GantryGainRow partial_gains(double cable_length, double mass_ratio) {
  GantryGainRow row;
  row.cable_length = cable_length;
  row.mass_ratio = mass_ratio;
  row.gains = gs::partial_state_gains(cable_length, mass_ratio, kGantryStudyDriveGain, std::nullopt,
                                      study_crane(mass_ratio, cable_length).gravity);
  return row;
}

void validate(const GantryStepCase& c) {
  common::require_in_range("gantry_step.cable_length", c.cable_length, 0.2, 10.0);
  common::require_in_range("gantry_step.mass_ratio", c.mass_ratio, 0.0, 10.0);
  common::require_in_range("gantry_step.design_cable_length", c.design_cable_length, 0.2, 10.0);
  common::require_in_range("gantry_step.design_mass_ratio", c.design_mass_ratio, 0.0, 10.0);
  common::require_greater("gantry_step.step_distance", c.step_distance, 0.0);
  common::require_in_range("gantry_step.step_distance", c.step_distance, 0.0, 10.0);
  common::require_in_range("gantry_step.duration_periods", c.duration_periods, 2.0, 50.0);
  if (c.kind == gs::FeedbackKind::full) common::require_greater("gantry_step.forward_gain", c.forward_gain, 0.0);
}

}  // namespace

std::vector<GantryGainRow> gains_over_cable_length(const std::vector<double>& cable_lengths) {
  std::vector<GantryGainRow> rows;
  for (const double L : cable_lengths) rows.push_back(partial_gains(L, 0.0));
  return rows;
}

std::vector<GantryGainRow> gains_over_mass_ratio(const std::vector<double>& mass_ratios) {
  std::vector<GantryGainRow> rows;
  for (const double m_t : mass_ratios) rows.push_back(partial_gains(1.0, m_t));
  return rows;
}

GantryStepResult run_gantry_step(const GantryStepCase& step) {
  validate(step);
  plant::SimulatorParameters plant_params;
  plant_params.kind = plant::PlantKind::gantry;
  plant_params.crane = study_crane(step.mass_ratio, step.cable_length);
  plant_params.sample_period = kSamplePeriod;
  plant_params.initial_state.cable_length = step.cable_length;
  plant::CraneSimulator plant(plant_params);

  gs::GainSchedulingParams control = gs::gain_scheduling_params_from(plant_params.crane);
  control.kind = step.kind;
  control.trolley_forward_gain = step.forward_gain;
  control.mass_ratio = step.design_mass_ratio;  // the load the gains are computed for
  control.slew_enabled = false;                 // a gantry crane
  control.min_cable_length = plant_params.crane.min_cable_length;
  gs::GainSchedulingController controller(control);

  GantryStepResult result;
  result.step = step;
  result.swing_period = 2.0 * std::numbers::pi * std::sqrt(step.cable_length / plant_params.crane.gravity);
  const auto cycles = static_cast<int>(std::ceil(step.duration_periods * result.swing_period / kSamplePeriod));

  common::MotionReference reference;
  reference.trolley.position = step.step_distance;
  std::vector<RecordedCycle> record;
  record.reserve(static_cast<std::size_t>(cycles) + 1);
  const auto record_cycle = [&](double applied_voltage) {
    const plant::PlantState& s = plant.state();
    RecordedCycle c;
    c.time = plant.time();
    c.trolley_position = s.trolley_position;
    c.swing_in_plane = s.swing_in_plane;
    c.trolley_voltage = applied_voltage;
    record.push_back(c);
  };
  record_cycle(0.0);
  for (int k = 0; k < cycles; ++k) {
    const plant::PlantState& s = plant.state();
    common::CraneStateEstimate estimate;
    estimate.trolley_position = s.trolley_position;
    estimate.trolley_velocity = s.trolley_velocity;
    estimate.swing_in_plane = s.swing_in_plane;
    estimate.swing_in_plane_rate = s.swing_in_plane_rate;
    estimate.cable_length = step.design_cable_length;  // the L the gains are computed for
    common::DriveCommand command;
    if (controller.step(estimate, reference, command) != common::StepStatus::ok) {
      throw std::runtime_error("gantry step: the controller rejected cycle " + std::to_string(k));
    }
    plant::DriveInput input;
    input.trolley_voltage = command.trolley_voltage;
    input.brakes_engaged = false;
    if (plant.step(input) != common::StepStatus::ok) {
      throw std::runtime_error("gantry step: the plant failed at cycle " + std::to_string(k));
    }
    record_cycle(plant.output().applied_trolley_voltage);
  }
  result.gains = controller.trolley_gains();

  SettleCriteria criteria;
  criteria.residual_window = result.swing_period;
  const ManeuverMetrics metrics = evaluate_maneuver(record, step.step_distance, 0.0, criteria);
  double max_position = 0.0;
  for (const RecordedCycle& c : record) max_position = std::max(max_position, c.trolley_position);
  result.overshoot = std::max(0.0, max_position - step.step_distance) / step.step_distance;
  result.settle_periods = metrics.settle_time / result.swing_period;
  result.max_swing = metrics.max_swing;
  result.residual_swing = metrics.residual_swing;
  result.final_error = metrics.final_position_error;
  result.max_voltage = metrics.max_voltage;
  return result;
}

std::vector<GantryStepCase> section_322_cases(double full_forward_gain) {
  using gs::FeedbackKind;
  std::vector<GantryStepCase> cases;
  const auto add = [&](const char* label, FeedbackKind kind, double L, double m_t, double design_L,
                       double design_m_t) {
    GantryStepCase c;
    c.label = label;
    c.kind = kind;
    c.forward_gain = full_forward_gain;
    c.cable_length = L;
    c.mass_ratio = m_t;
    c.design_cable_length = design_L;
    c.design_mass_ratio = design_m_t;
    cases.push_back(c);
  };
  add("fig3.7 m_t=5 adapted", FeedbackKind::partial, 1.0, 5.0, 1.0, 5.0);
  add("fig3.7 m_t=5 gains(m_t=0)", FeedbackKind::partial, 1.0, 5.0, 1.0, 0.0);
  add("fig3.8 L=1 adapted", FeedbackKind::full, 1.0, 0.0, 1.0, 0.0);
  add("fig3.8 L=5 gains(L=1)", FeedbackKind::full, 5.0, 0.0, 1.0, 0.0);
  add("fig3.8 L=5 adapted", FeedbackKind::full, 5.0, 0.0, 5.0, 0.0);
  add("text   L=1 gains(L=5)", FeedbackKind::partial, 1.0, 0.0, 5.0, 0.0);
  add("text   L=1 gains(L=5)", FeedbackKind::full, 1.0, 0.0, 5.0, 0.0);
  return cases;
}

std::string format_step_table(const std::vector<GantryStepResult>& results) {
  std::string out;
  char line[256];
  std::snprintf(line, sizeof line, "%-26s %-7s %5s %5s %8s %8s %9s %10s %9s %11s %8s\n", "case", "law", "L_m", "m_t",
                "design_L", "design_mt", "overshoot", "settle_T", "max_swing", "resid_swing", "max_V");
  out += line;
  std::snprintf(line, sizeof line, "%-26s %-7s %5s %5s %8s %8s %9s %10s %9s %11s %8s\n", "", "", "", "", "", "", "[%]",
                "[periods]", "[deg]", "[deg]", "[V]");
  out += line;
  for (const GantryStepResult& r : results) {
    const double deg = 180.0 / std::numbers::pi;
    char settle[32];
    if (std::isnan(r.settle_periods)) {
      std::snprintf(settle, sizeof settle, "-");
    } else {
      std::snprintf(settle, sizeof settle, "%.2f", r.settle_periods);
    }
    std::snprintf(line, sizeof line, "%-26s %-7s %5.1f %5.1f %8.1f %8.1f %9.2f %10s %9.2f %11.3f %8.2f\n",
                  r.step.label.c_str(), r.step.kind == gs::FeedbackKind::full ? "full" : "partial",
                  r.step.cable_length, r.step.mass_ratio, r.step.design_cable_length, r.step.design_mass_ratio,
                  100.0 * r.overshoot, settle, r.max_swing * deg, r.residual_swing * deg, r.max_voltage);
    out += line;
  }
  return out;
}

std::string format_gain_table(const std::vector<GantryGainRow>& rows, const char* title) {
  std::string out = std::string(title) + "\n";
  char line[200];
  std::snprintf(line, sizeof line, "%6s %6s %10s %6s %10s %10s %10s\n", "L_m", "m_t", "K[V/m]", "K_x", "K_xd[s]",
                "K_phi[m]", "w_n[1/s]");
  out += line;
  for (const GantryGainRow& r : rows) {
    std::snprintf(line, sizeof line, "%6.2f %6.2f %10.4f %6.3f %10.4f %10.4f %10.4f\n", r.cable_length, r.mass_ratio,
                  r.gains.forward_gain, r.gains.position_gain, r.gains.velocity_gain, r.gains.swing_gain,
                  r.gains.natural_frequency);
    out += line;
  }
  return out;
}

}  // namespace crane::stack
