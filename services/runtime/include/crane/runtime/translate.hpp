#pragma once
// Translators between the bus types (idl/crane_msgs.idl) and the core structs: the only place
// where the two meet (STYLE.md habit 3). All SI, field for field.

#include "crane/common/crane_signals.hpp"
#include "crane_msgs.h"

namespace crane::runtime {

namespace msgs = crane_msgs::msg::dds_;

[[nodiscard]] common::CraneMeasurement to_measurement(const msgs::SensorSample_& sample) noexcept;
[[nodiscard]] common::CraneStateEstimate to_estimate(const msgs::CraneState_& state) noexcept;
void from_estimate(const common::CraneStateEstimate& estimate, msgs::CraneState_& state) noexcept;
[[nodiscard]] common::MotionReference to_reference(const msgs::Reference_& reference) noexcept;
void from_reference(const common::MotionReference& reference, msgs::Reference_& message) noexcept;

}  // namespace crane::runtime
