// CraneSimulator::step (and so HybridIntegrator::advance_to) allocates nothing, for every
// integrator but bdf (below): the plant steps on the 100 Hz path. malloc, calloc and realloc are counted by
// interposition in this executable (not built under the sanitizers, which own the allocator).
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstddef>

#include "crane/plant/crane_simulator.hpp"

extern "C" void* __libc_malloc(std::size_t size);
extern "C" void* __libc_calloc(std::size_t count, std::size_t size);
extern "C" void* __libc_realloc(void* pointer, std::size_t size);

namespace {
std::atomic<bool> counting{false};
std::atomic<long> allocations{0};
}  // namespace

extern "C" void* malloc(std::size_t size) {
  if (counting.load(std::memory_order_relaxed)) ++allocations;
  return __libc_malloc(size);
}
extern "C" void* calloc(std::size_t count, std::size_t size) {
  if (counting.load(std::memory_order_relaxed)) ++allocations;
  return __libc_calloc(count, size);
}
extern "C" void* realloc(void* pointer, std::size_t size) {
  if (counting.load(std::memory_order_relaxed)) ++allocations;
  return __libc_realloc(pointer, size);
}

namespace crane::plant {
namespace {

class StepAllocation : public ::testing::TestWithParam<IntegrationMethod> {};

// Three seconds of a bang-bang trolley and slew drive with friction (stick, slip, reversals), the
// hoist paying out, the brakes engaged and released: every restart path of the integrator.
TEST_P(StepAllocation, StepsAllocateNothing) {
  SimulatorParameters p;
  p.integrator.method = GetParam();
  CraneSimulator simulator(p);
  DriveInput input;
  input.brakes_engaged = false;
  (void)simulator.step(input);  // the solver's first start outside the count
  long events_before = simulator.friction_event_count();
  counting = true;
  for (int k = 0; k < 300; ++k) {
    input.trolley_voltage = (k / 40) % 2 == 0 ? 3.0 : -3.0;
    input.slew_voltage = (k / 55) % 2 == 0 ? 2.5 : -2.5;
    input.hoist_speed = k < 150 ? 0.1 : 0.0;
    input.brakes_engaged = k >= 250 && k < 270;
    (void)simulator.step(input);
  }
  counting = false;
  EXPECT_EQ(allocations.load(), 0) << "allocations in 300 steps of " << integration_method_name(GetParam());
  EXPECT_GT(simulator.friction_event_count(), events_before) << "the run crossed friction events";
  EXPECT_EQ(simulator.integrator_failure_count(), 0);
  allocations = 0;
}

// Not bdf: CVODE's difference-quotient Jacobian clones a vector header at each linear-solver
// setup (261 allocations in these 300 steps, 2026-11-25); the former default, no longer used by
// the stack (docs/integration.md).
INSTANTIATE_TEST_SUITE_P(Integrators, StepAllocation,
                         ::testing::Values(IntegrationMethod::dormand_prince, IntegrationMethod::verner,
                                           IntegrationMethod::adams),
                         [](const auto& method) { return std::string(integration_method_name(method.param)); });

}  // namespace
}  // namespace crane::plant
