// crane_safety: the operator's commands to the supervisor, and its status.
//
//   crane_safety arm | disarm | estop | reset   send the command on rt/crane/safety/command and wait
//                                              for the supervisor to answer it on the status topic
//   crane_safety mode manual | semiautomatic | fullautomatic | maintenance
//                                              change the operating mode (OPC 40020): the same
//   crane_safety zone enable | disable N        switch no-go zone N (index in site.zones): the same
//   crane_safety status [--json]                print the supervisor's latest status
//
// Exit codes: 0 done (command accepted / status printed), 1 no supervisor answered within
// --timeout, 2 bad usage, 3 the supervisor refused the command (the reason is in its log: arm needs
// a healthy chain and no latched fault, reset needs a healthy chain and no active fault, zone needs
// an index of site.zones and disable one that is not fixed). With --config (deploy/crane passes its
// configuration) a refused zone command names the zone and why (supervisor::zone_command_refusal).
#include <spdlog/spdlog.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include "crane/config/config_document.hpp"
#include "crane/protocol/messages.hpp"
#include "crane/supervisor/supervisor.hpp"
#include "crane/runtime/node_runtime.hpp"

namespace {

using namespace crane;
namespace tp = transport::topics;
using Clock = std::chrono::steady_clock;

using Status = protocol::SupervisorStatus;  // the protocol's codes: MODE_*, FAULT_*, STAGE_*, ...

/// The names of the codes of `group` (FAULT, STAGE: one bit each, in the IDL's order) whose bit is
/// set in `bits` (or clear, with want_set false), joined by `separator`, each between `quote`s.
std::string bit_names(std::string_view group, std::uint32_t bits, bool want_set, const char* separator,
                      const char* quote) {
  std::string text;
  for (const auto& code : Status::kCodes) {
    if (code.group != group || ((bits & code.value) != 0) != want_set) continue;
    if (!text.empty()) text += separator;
    text += quote + std::string(code.name) + quote;
  }
  return text;
}

std::string fault_list(std::uint32_t bits) { return bit_names("FAULT", bits, true, ",", ""); }
std::string quoted_list(std::uint32_t bits) { return "[" + bit_names("FAULT", bits, true, ", ", "\"") + "]"; }
std::string stage_list(std::uint32_t alive, bool want_alive) { return bit_names("STAGE", alive, want_alive, ",", ""); }
std::string code_name(std::string_view group, std::uint64_t value) {
  return std::string(protocol::code_name(Status::kCodes, group, value));
}

// Why the supervisor refused a zone command, from the configuration it runs with (the same rule).
std::string zone_refusal_text(const std::string& config_path, std::uint8_t command, std::uint8_t zone) {
  if (config_path.empty()) return "zone " + std::to_string(zone) + ": not in site.zones, or fixed (--config names it)";
  try {
    const auto site = config::ConfigDocument::load(config_path).facts().site;
    const auto refusal = supervisor::zone_command_refusal(site, static_cast<supervisor::Command>(command), zone);
    if (refusal != supervisor::ZoneRefusal::none) return supervisor::describe(refusal, site, zone);
    return "zone " + std::to_string(zone) + ": " + config_path + " allows it (the supervisor runs another configuration?)";
  } catch (const std::exception& error) {
    return "zone " + std::to_string(zone) + ": " + error.what();
  }
}

std::string zone_list(std::uint32_t enabled) {
  std::string text;
  for (int i = 0; i < 32; ++i) {
    if ((enabled & (1U << i)) == 0) continue;
    if (!text.empty()) text += ",";
    text += std::to_string(i);
  }
  return text.empty() ? "none" : text;
}

using Estimate = protocol::CraneState;  // ADAPTATION_* bits

// The online estimate (state estimator, crane::adaptation): payload, friction in use, limit cycles.
std::string adaptation_list(std::uint8_t bits, const char* separator, const char* quote) {
  std::string text;
  for (const auto& code : Estimate::kCodes) {
    if (code.group != "ADAPTATION" || (bits & code.value) == 0) continue;
    if (!text.empty()) text += separator;
    text += quote + std::string(code.name) + quote;
  }
  return text;
}

std::string friction_text(double b_pos, double b_neg, double c_pos, double c_neg, double s_pos, double s_neg,
                          const char* viscous_unit) {
  char text[200];
  std::snprintf(text, sizeof text, "c+ %.3f c- %.3f V, b+ %.3f b- %.3f %s, breakaway +%.3f -%.3f V", c_pos, c_neg, b_pos,
                b_neg, viscous_unit, s_pos, s_neg);
  return text;
}

std::string estimate_json(const tp::msgs::CraneState_* e) {
  if (e == nullptr) return ", \"estimate\": null";
  char text[1200];
  std::snprintf(text, sizeof text,
                ", \"estimate\": {\"payload_mass_kg\": %g, \"payload_mass_bound_kg\": %g, \"payload_confident\": %s, "
                "\"adaptation\": [%s], \"trolley_friction_V\": [%g, %g, %g, %g, %g, %g], "
                "\"slew_friction_V\": [%g, %g, %g, %g, %g, %g], \"trolley_voltage_sign_changes\": %u, "
                "\"slew_voltage_sign_changes\": %u, \"seq\": %llu}",
                e->payload_mass(), e->payload_mass_bound(), e->payload_confident() ? "true" : "false",
                adaptation_list(e->adaptation(), ", ", "\"").c_str(), e->trolley_friction_viscous_positive(),
                e->trolley_friction_viscous_negative(), e->trolley_friction_coulomb_positive(),
                e->trolley_friction_coulomb_negative(), e->trolley_friction_static_positive(),
                e->trolley_friction_static_negative(), e->slew_friction_viscous_positive(),
                e->slew_friction_viscous_negative(), e->slew_friction_coulomb_positive(),
                e->slew_friction_coulomb_negative(), e->slew_friction_static_positive(),
                e->slew_friction_static_negative(), e->trolley_voltage_sign_changes(), e->slew_voltage_sign_changes(),
                static_cast<unsigned long long>(e->header().seq()));
  return text;
}

void print_estimate(const tp::msgs::CraneState_* e) {
  if (e == nullptr) {
    std::printf("payload         no estimate (the state estimator is silent)\n");
    return;
  }
  const bool enabled = (e->adaptation() & Estimate::ADAPTATION_ENABLED) != 0;
  if (!enabled) {
    std::printf("payload         %.2f kg (configured; online estimation off)\n", e->payload_mass());
  } else if (!e->payload_confident() && e->payload_mass_bound() == 0.0) {
    std::printf("payload         %.2f kg (configured; online estimate: not identified yet, the load needs to move)\n",
                e->payload_mass());
  } else if (e->payload_confident()) {
    std::printf("payload         %.3f kg +- %.3f kg (online estimate, 2 sigma; in use)\n", e->payload_mass(),
                e->payload_mass_bound());
  } else {
    std::printf("payload         %.3f kg +- %.3f kg (online estimate, not yet confident: the configured mass is used)\n",
                e->payload_mass(), e->payload_mass_bound());
  }
  const auto axis = [&](const char* label, std::uint8_t adapted, std::uint8_t cycle, const std::string& text) {
    const char* source = (e->adaptation() & cycle) ? "configured (limit cycle detected: fallback)"
                         : (e->adaptation() & adapted) ? "online re-estimate"
                                                       : "configured";
    std::printf("%s %s: %s\n", label, source, text.c_str());
  };
  axis("trolley friction", Estimate::ADAPTATION_TROLLEY_FRICTION_ADAPTED, Estimate::ADAPTATION_TROLLEY_LIMIT_CYCLE,
       friction_text(e->trolley_friction_viscous_positive(), e->trolley_friction_viscous_negative(),
                     e->trolley_friction_coulomb_positive(), e->trolley_friction_coulomb_negative(),
                     e->trolley_friction_static_positive(), e->trolley_friction_static_negative(), "V s/m"));
  axis("slew friction   ", Estimate::ADAPTATION_SLEW_FRICTION_ADAPTED, Estimate::ADAPTATION_SLEW_LIMIT_CYCLE,
       friction_text(e->slew_friction_viscous_positive(), e->slew_friction_viscous_negative(),
                     e->slew_friction_coulomb_positive(), e->slew_friction_coulomb_negative(),
                     e->slew_friction_static_positive(), e->slew_friction_static_negative(), "V s/rad"));
  if (enabled) {
    std::printf("sign changes    drive voltage at rest: trolley %u, slew %u\n", e->trolley_voltage_sign_changes(),
                e->slew_voltage_sign_changes());
  }
}

void print_status(const tp::msgs::SupervisorStatus_& s, const tp::msgs::CraneState_* estimate, bool json) {
  const auto mode = code_name("MODE", s.mode());
  const auto operating = code_name("OPERATION", s.operating_mode());
  if (json) {
    std::printf(
        "{\"mode\": \"%s\", \"motion_enabled\": %s, \"brakes_released\": %s, \"active_faults\": %s, "
        "\"latched_faults\": %s, \"fault_count\": %u, \"last_fault\": \"%s\", \"last_fault_seq\": %llu, "
        "\"stages_alive\": %u, \"warnings\": %u, \"trolley_voltage_limit_V\": %g, \"slew_voltage_limit_V\": %g, "
        "\"trolley_velocity_mps\": %g, \"slew_rate_radps\": %g, \"nonfinite_rejected\": %u, \"seq\": %llu, "
        "\"operating_mode\": \"%s\", \"zones_enabled\": %u, \"bridge_voltage_limit_V\": %g, "
        "\"bridge_velocity_mps\": %g%s}\n",
        mode.c_str(), s.motion_enabled() ? "true" : "false", s.brakes_released() ? "true" : "false",
        quoted_list(s.active_faults()).c_str(), quoted_list(s.latched_faults()).c_str(), s.fault_count(),
        s.last_fault() != 0 ? code_name("FAULT", s.last_fault()).c_str() : "",
        static_cast<unsigned long long>(s.last_fault_seq()),
        s.stages_alive(), s.warnings(), s.trolley_voltage_limit(), s.slew_voltage_limit(), s.trolley_velocity(),
        s.slew_rate(), s.nonfinite_rejected(), static_cast<unsigned long long>(s.header().seq()), operating.c_str(),
        s.zones_enabled(), s.bridge_voltage_limit(), s.bridge_velocity(), estimate_json(estimate).c_str());
    return;
  }
  std::printf("mode            %s\n", mode.c_str());
  std::printf("operating mode  %s\n", operating.c_str());
  std::printf("zones enforced  %s%s\n", zone_list(s.zones_enabled()).c_str(),
              (s.warnings() & Status::WARNING_ZONE_APPROACH) ? " (approaching one: soft stop)" : "");
  std::printf("motion          %s, brakes %s\n", s.motion_enabled() ? "enabled" : "disabled",
              s.brakes_released() ? "released" : "engaged");
  std::printf("active faults   %s\n", s.active_faults() ? fault_list(s.active_faults()).c_str() : "none");
  std::printf("latched faults  %s\n", s.latched_faults() ? fault_list(s.latched_faults()).c_str() : "none");
  std::printf("faults raised   %u, last: %s at cycle %llu\n", s.fault_count(),
              s.last_fault() ? code_name("FAULT", s.last_fault()).c_str() : "none",
              static_cast<unsigned long long>(s.last_fault_seq()));
  std::printf("stages alive    %s%s%s\n", stage_list(s.stages_alive(), true).c_str(),
              s.stages_alive() != Status::STAGES_ALL ? "; silent: " : "",
              s.stages_alive() != Status::STAGES_ALL ? stage_list(s.stages_alive(), false).c_str() : "");
  std::printf("voltage limits  trolley %.2f V, slew %.2f V%s\n", s.trolley_voltage_limit(), s.slew_voltage_limit(),
              (s.warnings() & Status::WARNING_SPEED_LIMITED) ? " (approach speed exceeded)" : "");
  std::printf("speeds          trolley %.3f m/s, slew %.3f rad/s\n", s.trolley_velocity(), s.slew_rate());
  if (s.bridge_voltage_limit() != 0.0 || s.bridge_velocity() != 0.0) {  // an overhead crane's bridge
    std::printf("bridge          %.3f m/s, voltage limit %.2f V%s\n", s.bridge_velocity(), s.bridge_voltage_limit(),
                (s.warnings() & Status::WARNING_BRIDGE_APPROACH) ? " (approaching a runway limit)" : "");
  }
  std::printf("cycle           %llu\n", static_cast<unsigned long long>(s.header().seq()));
  print_estimate(estimate);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"crane_safety: arm, disarm, emergency stop, reset and status of the crane supervisor"};
  std::string action;
  runtime::NodeOptions options;
  double timeout = 3.0;
  bool json = false;
  std::vector<std::string> arguments;
  app.add_option("action", action, "arm | disarm | estop | reset | status | mode | zone")
      ->required()
      ->check(CLI::IsMember({"arm", "disarm", "estop", "reset", "status", "mode", "zone"}));
  app.add_option("arguments", arguments, "mode: manual | semiautomatic | fullautomatic | maintenance; "
                                         "zone: enable | disable N");
  app.add_option("--dds", options.dds, "DDS vendor: fast | cyclone (default: $CRANE_DDS, else fast)");
  app.add_option("--domain", options.domain_id, "DDS domain id")->check(CLI::Range(0, 232));
  runtime::add_security_options(app, options);  // identity: the participant's, "operator"
  app.add_option("--timeout", timeout, "[s] longest wait for the supervisor")->check(CLI::Range(0.1, 60.0));
  app.add_flag("--json", json, "status as one JSON object");
  std::string config_path;
  app.add_option("--config", config_path, "the stack's configuration (a refused zone command names the zone)");
  CLI11_PARSE(app, argc, argv);
  using Command = protocol::SupervisorCommand;
  std::uint8_t operating_mode = 0, zone = 0;
  std::uint8_t zone_command = 0;
  if (action == "mode") {
    for (const auto& code : Status::kCodes) {
      if (code.group == "OPERATION" && arguments.size() == 1 && code.name == arguments[0]) {
        operating_mode = static_cast<std::uint8_t>(code.value);
      }
    }
    if (operating_mode == 0) {
      std::fprintf(stderr, "crane_safety: mode needs one of manual, semiautomatic, fullautomatic, maintenance\n");
      return 2;
    }
  } else if (action == "zone") {
    const bool shape = arguments.size() == 2 && (arguments[0] == "enable" || arguments[0] == "disable");
    int index = -1;
    if (shape) {
      try {
        std::size_t used = 0;
        index = std::stoi(arguments[1], &used);
        if (used != arguments[1].size()) index = -1;
      } catch (const std::exception&) {
        index = -1;
      }
    }
    if (!shape || index < 0 || index > 31) {
      std::fprintf(stderr, "crane_safety: zone needs enable | disable and a zone index in [0, 31]\n");
      return 2;
    }
    zone = static_cast<std::uint8_t>(index);
    zone_command = arguments[0] == "enable" ? Command::COMMAND_ENABLE_ZONE : Command::COMMAND_DISABLE_ZONE;
  } else if (!arguments.empty()) {
    std::fprintf(stderr, "crane_safety: %s takes no argument\n", action.c_str());
    return 2;
  }
  try {
    runtime::configure_logging("warn", "crane_safety");
    auto participant = runtime::make_participant(options, "operator");
    transport::Wakeup wakeup;
    auto status_reader = participant->make_reader<tp::SafetyStatus>(&wakeup);
    const auto deadline = Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(timeout));
    tp::msgs::SupervisorStatus_ status;

    if (action == "status") {
      // The estimate too (payload and friction of the online estimation): waited for at most 0.5 s
      // after the status (the state estimator may be silent: then printed as missing).
      auto estimate_reader = participant->make_reader<tp::StateEstimate>(&wakeup);
      tp::msgs::CraneState_ estimate;
      bool have_status = false;
      bool have_estimate = false;
      auto estimate_deadline = deadline;
      while (Clock::now() < std::min(deadline, estimate_deadline) && !(have_status && have_estimate)) {
        if (!have_status && status_reader->take_latest(status)) {
          have_status = true;
          estimate_deadline = Clock::now() + std::chrono::milliseconds(500);
        }
        have_estimate = estimate_reader->take_latest(estimate) || have_estimate;
        if (!(have_status && have_estimate)) {
          wakeup.wait_until(std::min({deadline, estimate_deadline, Clock::now() + std::chrono::milliseconds(20)}));
        }
      }
      if (have_status) {
        print_status(status, have_estimate ? &estimate : nullptr, json);
        return 0;
      }
      std::fprintf(stderr, "crane_safety: no supervisor status on domain %u within %.1f s\n", options.domain_id, timeout);
      return 1;
    }

    const std::uint8_t code = action == "arm"      ? Command::COMMAND_ARM
                              : action == "disarm" ? Command::COMMAND_DISARM
                              : action == "estop"  ? Command::COMMAND_EMERGENCY_STOP
                              : action == "mode"   ? Command::COMMAND_SET_OPERATING_MODE
                              : action == "zone"   ? zone_command
                                                   : Command::COMMAND_RESET;
    auto writer = participant->make_writer<tp::SafetyCommand>();
    while (writer->health().matched_readers == 0 && Clock::now() < deadline) {
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    if (writer->health().matched_readers == 0) {
      std::fprintf(stderr, "crane_safety: no supervisor listens on rt/crane/safety/command (domain %u) within %.1f s\n",
                   options.domain_id, timeout);
      return 1;
    }
    tp::msgs::SupervisorCommand_ command;
    const auto request_id = static_cast<std::uint32_t>(
        (static_cast<std::uint64_t>(getpid()) << 16) ^ static_cast<std::uint64_t>(runtime::now_nanoseconds()));
    runtime::stamp_header(command.header(), 0, runtime::now_stamp());
    command.request_id(request_id);
    command.command(code);
    command.operating_mode(operating_mode);
    command.zone(zone);
    writer->write(command);
    // Discovery is not symmetric: this writer may match the supervisor's reader before that reader
    // matches it, and a volatile command written then is lost to it. Every command is idempotent
    // (a second estop, arm, disarm or reset of the same request changes nothing), so it is sent
    // again every 50 ms until the status echoes its request id.
    auto next_send = Clock::now() + std::chrono::milliseconds(50);
    while (Clock::now() < deadline) {
      if (Clock::now() >= next_send) {
        writer->write(command);
        next_send = Clock::now() + std::chrono::milliseconds(50);
      }
      while (status_reader->take_next(status)) {
        if (status.last_request_id() != request_id) continue;
        const bool accepted = status.last_request_result() == Status::RESULT_ACCEPTED;
        std::printf("%s%s%s %s: mode %s, operating mode %s, zones enforced %s, brakes %s\n", action.c_str(),
                    arguments.empty() ? "" : " ", arguments.empty() ? "" : arguments.back().c_str(),
                    accepted ? "accepted" : "refused", code_name("MODE", status.mode()).c_str(),
                    code_name("OPERATION", status.operating_mode()).c_str(), zone_list(status.zones_enabled()).c_str(),
                    status.brakes_released() ? "released" : "engaged");
        if (!accepted && action == "zone") {
          std::printf("  %s\n", zone_refusal_text(config_path, zone_command, zone).c_str());
        } else if (!accepted) {
          std::printf("  latched faults: %s; active: %s; silent stages: %s\n",
                      status.latched_faults() ? fault_list(status.latched_faults()).c_str() : "none",
                      status.active_faults() ? fault_list(status.active_faults()).c_str() : "none",
                      status.stages_alive() == Status::STAGES_ALL ? "none" : stage_list(status.stages_alive(), false).c_str());
        }
        return accepted ? 0 : 3;
      }
      wakeup.wait_until(std::min(deadline, Clock::now() + std::chrono::milliseconds(20)));
    }
    std::fprintf(stderr, "crane_safety: the supervisor did not answer request %u within %.1f s\n", request_id, timeout);
    return 1;
  } catch (const std::exception& error) {
    std::fprintf(stderr, "crane_safety: %s\n", error.what());
    return 1;
  }
}
