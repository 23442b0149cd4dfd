// crane_gains: prints the gain-scheduling gains of section 3.2 (H. M. Omar 2003) for one operating
// point.
//   crane_gains --kind partial|full --L M --mt R [--K K] [--x M] [--Kmx V] --json
// Trolley: partial (3.19)/(4.18) or full (3.26)/(4.21). With --x the slew gains at that trolley
// position (section 3.2.1, exact pole placement on (2.30)-(2.31)) are printed instead, with the same
// keys (K_phi holds K_theta, K_xd holds K_gammad) plus "axis": "slew".
// Exit codes: 0 ok, 2 bad input (the message names the option, the value and the bound).

#include <cmath>
#include <cstdio>
#include <exception>
#include <optional>
#include <string>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "crane/common/validation.hpp"
#include "crane/gain_scheduling/gain_schedule.hpp"

namespace {

namespace gs = crane::gain_scheduling;
constexpr int kExitBadInput = 2;

nlohmann::json to_json(const gs::GainSchedulingGains& gains, bool full, const char* axis) {
  nlohmann::json out;
  out["axis"] = axis;
  out["K"] = gains.forward_gain;
  out["K_x"] = gains.position_gain;
  out["K_xd"] = gains.velocity_gain;
  out["K_phi"] = gains.swing_gain;
  if (full) {
    out["K_phid"] = gains.swing_rate_gain;
  }
  out["w_n"] = gains.natural_frequency;
  out["a"] = gains.trolley_pole;
  out["zeta"] = gains.damping_ratio;
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Gain-scheduling state-feedback gains (Omar 2003, section 3.2)"};
  std::string kind{"partial"};
  double cable_length{1.0};
  double mass_ratio{0.09};
  std::optional<double> forward_gain;
  std::optional<double> trolley_position;
  double trolley_drive_gain{2.0};
  gs::SlewModel slew;
  bool json{false};
  app.add_option("--kind", kind, "partial (3.19) or full (3.26) state feedback")
      ->check(CLI::IsMember({"partial", "full"}));
  app.add_option("--L", cable_length, "cable length [m], > 0")->required();
  app.add_option("--mt", mass_ratio, "mass ratio m_t = m/M [-], >= 0")->required();
  app.add_option("--K", forward_gain, "forward gain K [V/m] or [V/rad], > 0 (required for full)");
  app.add_option("--x", trolley_position, "trolley position [m], != 0: print the slew gains");
  app.add_option("--Kmx", trolley_drive_gain, "trolley drive gain K_mx [m/s^2/V], > 0")
      ->capture_default_str();
  app.add_option("--Kmg", slew.slew_drive_gain, "slew drive gain K_mgamma [rad/s^2/V], > 0")
      ->capture_default_str();
  app.add_option("--mr", slew.load_inertia_ratio, "m_r = m/J_o [1/m^2], >= 0")->capture_default_str();
  app.add_option("--Mr", slew.trolley_inertia_ratio, "M_r = M/J_o [1/m^2], >= 0")->capture_default_str();
  app.add_flag("--json", json, "print JSON");
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::fprintf(stderr, "crane_gains: %s\n", e.what());
    return kExitBadInput;
  }

  try {
    // Option-level validation so the message names the option as typed.
    namespace cc = crane::common;
    cc::require_greater("--L", cable_length, 0.0);
    cc::require_at_least("--mt", mass_ratio, 0.0);
    cc::require_greater("--Kmx", trolley_drive_gain, 0.0);
    cc::require_greater("--Kmg", slew.slew_drive_gain, 0.0);
    cc::require_at_least("--mr", slew.load_inertia_ratio, 0.0);
    cc::require_at_least("--Mr", slew.trolley_inertia_ratio, 0.0);
    if (forward_gain) {
      cc::require_greater("--K", *forward_gain, 0.0);
    }
    const bool full = kind == "full";
    if (full && !forward_gain) {
      std::fprintf(stderr, "crane_gains: --K is required with --kind full\n");
      return kExitBadInput;
    }
    if (trolley_position) {
      cc::require_finite("--x", *trolley_position);
      if (*trolley_position == 0.0) {
        throw cc::ConfigError("--x = 0 is out of range: must be != 0");
      }
    }

    nlohmann::json out;
    if (trolley_position) {
      const auto gains = full ? gs::slew_full_state_gains(cable_length, *trolley_position, slew, *forward_gain)
                              : gs::slew_partial_state_gains(cable_length, *trolley_position, slew, forward_gain);
      out = to_json(gains, full, "slew");
      out["x"] = *trolley_position;
    } else {
      const auto gains = full ? gs::full_state_gains(cable_length, mass_ratio, trolley_drive_gain, *forward_gain)
                              : gs::partial_state_gains(cable_length, mass_ratio, trolley_drive_gain, forward_gain);
      out = to_json(gains, full, "trolley");
    }
    out["kind"] = kind;
    out["L"] = cable_length;
    if (json) {
      std::printf("%s\n", out.dump(2).c_str());
    } else {
      for (const auto& [key, value] : out.items()) {
        std::printf("%s = %s\n", key.c_str(), value.dump().c_str());
      }
    }
  } catch (const crane::common::ConfigError& e) {
    std::fprintf(stderr, "crane_gains: %s\n", e.what());
    return kExitBadInput;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "crane_gains: %s\n", e.what());
    return 1;
  }
  return 0;
}
