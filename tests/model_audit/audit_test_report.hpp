#pragma once
// Helpers of the model-audit tests that count and print cases: case counts from the environment
// (the long runs of docs/model_audit.md) and a report's best candidates.
#include <cstddef>
#include <cstdio>
#include <cstdlib>

#include "crane/model_audit/model_audit.hpp"

namespace crane::model_audit::test {

/// The count environment variable `name` gives; `fallback` when it is unset or empty.
inline std::size_t env_count(const char* name, std::size_t fallback) {
  const char* text = std::getenv(name);
  if (text == nullptr || *text == '\0') return fallback;
  return static_cast<std::size_t>(std::strtoul(text, nullptr, 10));
}

/// The first `count` candidates of `report`, one line each: name (`width` characters), delta-BIC,
/// held-out RMS and its gain, whether it qualifies, the fitted parameters.
inline void print_candidates(const AuditReport& report, std::size_t count = 4, int width = 28) {
  for (std::size_t i = 0; i < report.candidates.size() && i < count; ++i) {
    const auto& c = report.candidates[i];
    std::printf("    %-*s dBIC %10.1f held-out %.4g (%+.1f %%)%s", width, c.name.c_str(), c.delta_bic, c.holdout_rms,
                c.holdout_gain_percent, c.qualifies ? " qualifies" : "");
    for (const auto& p : c.parameters) std::printf(" %s=%.4g", p.name.c_str(), p.value);
    std::printf("\n");
  }
}

}  // namespace crane::model_audit::test
