// The convergence study (crane/stack/convergence_study.hpp, docs/integration.md): the plant's
// integration at the configured settings against references, on every demo maneuver of the three
// crane kinds, the friction compensation on and off.
#include <gtest/gtest.h>

#include <string>

#include "crane/stack/convergence_study.hpp"

namespace {

using crane::plant::IntegrationMethod;
using crane::plant::IntegratorSettings;
using crane::stack::ConvergenceCase;
using crane::stack::InProcessRun;
using crane::stack::StackConfig;

StackConfig config(const std::string& name) {
  return crane::stack::load_stack_config(std::string(CRANE_SOURCE_DIR) + "/deploy/config/" + name + ".yaml");
}

// The demo's runs: every maneuver of the config, compensation on and off, the default controller.
std::vector<InProcessRun> demo_runs(const StackConfig& c) {
  std::vector<InProcessRun> runs;
  std::uint32_t id = 1;
  for (const auto& m : c.maneuvers) {
    for (const bool compensation : {true, false}) {
      InProcessRun run;
      run.maneuver = m;
      run.friction_compensation = compensation;
      run.controller = crane::stack::choose_controller("delay1", m, false);
      run.request_id = id++;
      runs.push_back(run);
    }
  }
  return runs;
}

IntegratorSettings settings(IntegrationMethod method, double rtol, double atol) {
  IntegratorSettings s;
  s.method = method;
  s.relative_tolerance = rtol;
  s.absolute_tolerance = atol;
  return s;
}

class ConvergenceStudy : public ::testing::TestWithParam<const char*> {};

// What the demo table prints is decided by the crane, not by the integrator: every printed figure at
// the configured settings within half a unit of its last digit of the reference's, and the
// integration error (the same inputs) far below the encoders' quanta (trolley 7.9 um, swing
// 0.26 mrad).
TEST_P(ConvergenceStudy, DefaultSettingsAgreeWithTheReferenceToEveryPrintedDigit) {
  const StackConfig c = config(GetParam());
  EXPECT_EQ(c.plant.integrator.method, IntegratorSettings{}.method) << "the configs and the code share one default";
  EXPECT_EQ(c.plant.integrator.relative_tolerance, IntegratorSettings{}.relative_tolerance);
  const auto cases = crane::stack::run_convergence_study(c, demo_runs(c), crane::stack::reference_integrator_settings());
  ASSERT_EQ(cases.size(), 2 * c.maneuvers.size());
  for (const ConvergenceCase& k : cases) {
    SCOPED_TRACE(k.maneuver + (k.friction_compensation ? " comp_on" : " comp_off"));
    for (const auto& f : k.figures) {
      EXPECT_TRUE(f.agrees()) << f.name << ": " << f.at_settings << " against the reference's " << f.at_reference
                              << " (" << f.decimals << " decimals printed)";
    }
    EXPECT_LT(k.integration_error.position, 1e-7);
    EXPECT_LT(k.integration_error.angle, 1e-7);
    EXPECT_EQ(k.friction_events, k.reference_friction_events);
    EXPECT_GT(k.work.steps, 0);
    EXPECT_GT(k.work.right_hand_sides, 6 * k.work.steps) << "an explicit 7-stage method restarted at every sample";
  }
}

INSTANTIATE_TEST_SUITE_P(Cranes, ConvergenceStudy, ::testing::Values("lab_tower_crane", "gantry_crane", "overhead_crane"));

// The reference is itself converged: two other solvers at the same tolerance (Adams, and the
// explicit Verner 6(5)) follow the same inputs to within 1e-8 of it, a thousandth of the smallest
// encoder quantum.
TEST(ConvergenceStudyReference, IndependentSolversAgreeWithTheReference) {
  StackConfig c = config("lab_tower_crane");
  for (const auto method : {IntegrationMethod::adams, IntegrationMethod::verner}) {
    c.plant.integrator = settings(method, 1e-12, 1e-14);
    const auto cases = crane::stack::run_convergence_study(c, demo_runs(c), crane::stack::reference_integrator_settings());
    for (const ConvergenceCase& k : cases) {
      SCOPED_TRACE(std::string(crane::plant::integration_method_name(method)) + " " + k.maneuver);
      EXPECT_LT(k.integration_error.position, 1e-8);
      EXPECT_LT(k.integration_error.angle, 1e-8);
      EXPECT_TRUE(k.agrees());
    }
  }
}

// The study can fail: the former integrator (CVODE BDF at rtol 1e-8, restarted at every sample) errs
// by up to 5e-6 rad and prints final errors one encoder count off on the tower crane.
TEST(ConvergenceStudyReference, TheFormerIntegratorSettingsAreCaught) {
  StackConfig c = config("lab_tower_crane");
  c.plant.integrator = settings(IntegrationMethod::bdf, 1e-8, 1e-10);
  const auto cases = crane::stack::run_convergence_study(c, demo_runs(c), crane::stack::reference_integrator_settings());
  int disagreements = 0;
  double worst_angle = 0.0;
  for (const ConvergenceCase& k : cases) {
    for (const auto& f : k.figures) disagreements += f.agrees() ? 0 : 1;
    worst_angle = std::max(worst_angle, k.integration_error.angle);
  }
  EXPECT_GE(disagreements, 1);
  EXPECT_GT(worst_angle, 1e-6);
}

}  // namespace
