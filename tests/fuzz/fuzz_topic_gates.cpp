// libFuzzer harness: the per-topic gates and the stage step functions on whatever arrives on the
// bus. The input is a sequence of samples: a selector byte names the topic, then the sample's
// fields are taken from the next bytes in IDL order (visit_fields, as a CDR reader takes them: any
// bit pattern for a double, NaN and Inf included; a bool 0 or 1, which Fast CDR enforces on the
// wire). Each sample goes through protocol::all_finite (the NaN gate of every node) and into the
// stage that reads that topic, exactly as the process would hand it over, with the stages built
// from the lab configuration. Contract: step() never throws (noexcept), never crashes, never trips
// ASan/UBSan, and whatever it returns, every output sample it writes is finite (the next stage's
// gate would otherwise stop the chain) when it returns ok.
#include <array>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <memory>
#include <sstream>
#include <type_traits>
#include <vector>

#include "crane/protocol/messages.hpp"
#include "crane/stack/stack_config.hpp"

namespace protocol = crane::protocol;

namespace {

template <class T>
struct IsStdArray : std::false_type {};
template <class T, std::size_t N>
struct IsStdArray<std::array<T, N>> : std::true_type {};

/// Takes the fields of a message from the input, in IDL order; zero once the input is used up.
class FieldReader {
 public:
  FieldReader(const std::uint8_t* data, std::size_t size) : data_(data), size_(size) {}
  [[nodiscard]] bool empty() const noexcept { return at_ >= size_; }
  std::uint8_t byte() noexcept { return at_ < size_ ? data_[at_++] : 0; }

  template <class T>
  void fill(T& value) {
    if constexpr (std::is_same_v<T, bool>) {
      value = (byte() & 1) != 0;
    } else if constexpr (std::is_arithmetic_v<T>) {
      std::array<std::uint8_t, sizeof(T)> raw{};
      for (auto& b : raw) b = byte();
      std::memcpy(&value, raw.data(), sizeof(T));
    } else if constexpr (IsStdArray<T>::value) {
      for (auto& element : value) fill(element);
    } else {
      // A nested struct (or a message): its own fields in IDL order. visit_fields hands out const
      // references to the fields of `value`, which is not const: writing through them is defined.
      protocol::visit_fields(value, [&](const char*, const auto& field) {
        using Field = std::remove_cvref_t<decltype(field)>;
        fill(const_cast<Field&>(field));
      });
    }
  }

 private:
  const std::uint8_t* data_;
  std::size_t size_;
  std::size_t at_{0};
};

const crane::stack::StackConfig& lab_config() {
  static const crane::stack::StackConfig config = [] {
    std::ifstream in(CRANE_FUZZ_LAB_CONFIG);
    std::stringstream text;
    text << in.rdbuf();
    return crane::stack::parse_stack_config(text.str(), CRANE_FUZZ_LAB_CONFIG);
  }();
  return config;
}

// CRANE_FUZZ_TRACE=1: every sample taken and written, field by field, on stderr (to read a crash).
const bool kTrace = std::getenv("CRANE_FUZZ_TRACE") != nullptr;

template <class T>
void print_fields(const T& value) {
  if constexpr (std::is_arithmetic_v<T>) {
    std::fprintf(stderr, "%.17g", static_cast<double>(value));
  } else if constexpr (IsStdArray<T>::value) {
    std::fprintf(stderr, "[");
    for (const auto& element : value) {
      print_fields(element);
      std::fprintf(stderr, " ");
    }
    std::fprintf(stderr, "]");
  } else {
    std::fprintf(stderr, "{");
    protocol::visit_fields(value, [](const char* name, const auto& field) {
      std::fprintf(stderr, " %s=", name);
      print_fields(field);
    });
    std::fprintf(stderr, " }");
  }
}

template <class Message>
void trace(const char* what, const Message& m) {
  if (!kTrace) return;
  std::fprintf(stderr, "%s ", what);
  print_fields(m);
  std::fprintf(stderr, "\n");
}

template <class Message>
void require_finite(const Message& m) {
  trace("  wrote", m);
  if (!protocol::all_finite(m)) std::abort();  // a stage wrote a sample the next gate would refuse
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto& cfg = lab_config();
  // Fresh stages per input: a crash reproduces from its input alone.
  crane::state_estimator::StateEstimatorStage estimator(cfg.state_estimator);
  crane::trajectory_planner::TrajectoryPlannerStage planner(cfg.trajectory_planner, cfg.facts.sample_period);
  crane::anti_swing::AntiSwingStage anti_swing(cfg.anti_swing);
  crane::tracking::TrackingStage tracking(cfg.tracking);
  const crane::friction_compensation::FrictionCompensationStage compensation(cfg.friction_compensation);
  auto supervisor_params = cfg.supervisor;
  supervisor_params.expected_sensor_source = protocol::SensorSample::SOURCE_PLANT;
  crane::supervisor::SupervisorStage supervisor(supervisor_params);

  // The latest sample of each topic, as each process keeps it (a valid start: the rest state).
  protocol::SensorSample sensors{};
  sensors.source = protocol::SensorSample::SOURCE_PLANT;
  sensors.cable_length = cfg.plant.crane.cable_length;
  protocol::CraneState estimate{};
  estimate.cable_length = cfg.plant.crane.cable_length;
  protocol::Reference reference{};
  protocol::AntiSwingCommand anti_swing_command{};
  protocol::LinearCommand linear{};
  protocol::ActuatorCommand actuators{};
  protocol::SupervisorStatus status{};
  std::vector<protocol::MoveRequest> goals;
  std::vector<protocol::OperatorSpeed> speeds;
  crane::supervisor::SupervisorCycle observed;
  for (auto& stage : observed.stages) stage = crane::supervisor::StageObservation{true, true, 0.0, false};

  FieldReader in(data, size);
  bool nonfinite_seen = false;
  // The NaN/Inf gate of every node at a topic's entry (runtime::take_finite): a sample with a
  // non-finite field is dropped and counted; the stage keeps its previous one.
  const auto gate = [&nonfinite_seen](auto& latest, const auto& sample) {
    trace("took", sample);
    if (!protocol::all_finite(sample)) {
      nonfinite_seen = true;
      return false;
    }
    latest = sample;
    return true;
  };
  while (!in.empty()) {
    switch (in.byte() % 12) {
      case 0: {  // rt/crane/hw/sensors -> state estimator
        protocol::SensorSample sample{};
        in.fill(sample);
        if (!gate(sensors, sample)) break;
        protocol::CraneState out{};
        if (estimator.step(sensors, out) == crane::common::StepStatus::ok) {
          require_finite(out);
          estimate = out;
        }
        break;
      }
      case 1: {  // rt/crane/state (a foreign writer) -> anti-swing, with the latest status (its operating mode)
        protocol::CraneState sample{};
        in.fill(sample);
        if (!gate(estimate, sample)) break;
        protocol::AntiSwingCommand out{};
        if (anti_swing.step(estimate, &status, out) == crane::common::StepStatus::ok) require_finite(out);
        anti_swing_command = out;
        break;
      }
      case 2: {  // rt/crane/planner/goal: queued for the planner's next cycle
        protocol::MoveRequest goal{};
        in.fill(goal);
        trace("took", goal);
        if (goals.size() < 16) goals.push_back(goal);  // the planner counts non-finite goals itself
        break;
      }
      case 3: {  // rt/crane/operator/speed: queued for the planner's next cycle
        protocol::OperatorSpeed speed{};
        in.fill(speed);
        trace("took", speed);
        if (speeds.size() < 16) speeds.push_back(speed);  // the planner refuses bad speeds itself
        break;
      }
      case 4: {  // rt/crane/supervisor/status -> the planner's view of the mode and zones, the anti-swing's of the mode
        protocol::SupervisorStatus sample{};
        in.fill(sample);
        (void)gate(status, sample);
        break;
      }
      case 5: {  // one planner cycle on the latest estimate, the queued goals and speeds
        protocol::Reference out{};
        const crane::trajectory_planner::PlannerCycle cycle{&estimate, goals, speeds, &status};
        if (planner.step(cycle, out) == crane::common::StepStatus::ok) {
          require_finite(out);
          reference = out;
        }
        goals.clear();
        speeds.clear();
        break;
      }
      case 6: {  // rt/crane/planner/reference (a foreign writer) -> tracking
        protocol::Reference sample{};
        in.fill(sample);
        if (!gate(reference, sample)) break;
        [[fallthrough]];
      }
      case 7: {  // tracking on the latest estimate, reference and anti-swing command
        protocol::LinearCommand out{};
        if (tracking.step(estimate, reference, anti_swing_command, out) == crane::common::StepStatus::ok) {
          require_finite(out);
        }
        linear = out;
        break;
      }
      case 8: {  // rt/crane/control/anti_swing (a foreign writer)
        protocol::AntiSwingCommand sample{};
        in.fill(sample);
        (void)gate(anti_swing_command, sample);
        break;
      }
      case 9: {  // rt/crane/control/linear (a foreign writer) -> friction compensation
        protocol::LinearCommand sample{};
        in.fill(sample);
        if (!gate(linear, sample)) break;
        protocol::ActuatorCommand out{};
        if (compensation.step(estimate, linear, out) == crane::common::StepStatus::ok) require_finite(out);
        actuators = out;
        break;
      }
      case 10: {  // rt/crane/hw/actuators (a foreign writer): what the supervisor watches
        protocol::ActuatorCommand sample{};
        in.fill(sample);
        (void)gate(actuators, sample);
        break;
      }
      case 11: {  // rt/crane/supervisor/command -> one supervision cycle
        protocol::SupervisorCommand command{};
        in.fill(command);
        trace("took", command);
        observed.sensors = &sensors;
        observed.actuators = &actuators;
        observed.reference = &reference;
        observed.command = &command;
        observed.nonfinite_seen = nonfinite_seen;
        nonfinite_seen = false;
        protocol::SupervisorStatus out{};
        supervisor.step(observed, out);
        require_finite(out);
        break;
      }
    }
  }
  return 0;
}
