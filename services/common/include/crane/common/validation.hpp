#pragma once
// Validation helpers for configuration-tier errors (STYLE.md, habit 7).
//
// Every check throws crane::common::ConfigError whose message names the field, the offending
// value and the bound, e.g.
//   "friction.trolley.coulomb_positive = -0.1 is out of range: must be >= 0"
// These are for construction time only; never call them from a cyclic step().

#include <stdexcept>
#include <string>
#include <string_view>

namespace crane::common {

/// Thrown for any invalid parameter or configuration field.
class ConfigError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

/// Formats a double the way error messages show it (shortest round-trip form).
std::string format_value(double value);

/// Throws ConfigError unless `value` is finite. `field` is the full dotted field name.
void require_finite(std::string_view field, double value);

/// Throws ConfigError unless value is finite and value >= lower_bound.
void require_at_least(std::string_view field, double value, double lower_bound);

/// Throws ConfigError unless value is finite and value > lower_bound.
void require_greater(std::string_view field, double value, double lower_bound);

/// Throws ConfigError unless value is finite and lower_bound <= value <= upper_bound.
void require_in_range(std::string_view field, double value, double lower_bound, double upper_bound);

}  // namespace crane::common
