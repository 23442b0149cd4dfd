#include "crane/common/validation.hpp"

#include <cmath>
#include <cstdio>

namespace crane::common {

std::string format_value(double value) {
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), "%.10g", value);
  return buffer;
}

namespace {
[[noreturn]] void fail(std::string_view field, double value, const std::string& bound) {
  throw ConfigError(std::string(field) + " = " + format_value(value) + " is out of range: must be " +
                    bound);
}
}  // namespace

void require_finite(std::string_view field, double value) {
  if (!std::isfinite(value)) fail(field, value, "finite");
}

void require_at_least(std::string_view field, double value, double lower_bound) {
  if (!std::isfinite(value) || value < lower_bound) fail(field, value, ">= " + format_value(lower_bound));
}

void require_greater(std::string_view field, double value, double lower_bound) {
  if (!std::isfinite(value) || value <= lower_bound) fail(field, value, "> " + format_value(lower_bound));
}

void require_in_range(std::string_view field, double value, double lower_bound, double upper_bound) {
  if (!std::isfinite(value) || value < lower_bound || value > upper_bound) {
    fail(field, value, "in [" + format_value(lower_bound) + ", " + format_value(upper_bound) + "]");
  }
}

}  // namespace crane::common
