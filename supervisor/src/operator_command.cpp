#include "crane/supervisor/operator_command.hpp"

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdarg>
#include <cstdio>
#include <string_view>

#include "crane/config/config_document.hpp"
#include "crane/supervisor/supervisor.hpp"

namespace crane::supervisor {

namespace {

using Status = protocol::SupervisorStatus;  // the protocol's codes: MODE_*, FAULT_*, STAGE_*, ...
using Estimate = protocol::CraneState;      // ADAPTATION_* bits
using CommandCodes = protocol::SupervisorCommand;

[[gnu::format(printf, 2, 3)]] void appendf(std::string& text, const char* format, ...) {
  char buffer[1600];
  va_list args;
  va_start(args, format);
  const int n = std::vsnprintf(buffer, sizeof buffer, format, args);
  va_end(args);
  if (n > 0) text.append(buffer, std::min<std::size_t>(static_cast<std::size_t>(n), sizeof buffer - 1));
}

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
    const auto refusal = zone_command_refusal(site, static_cast<Command>(command), zone);
    if (refusal != ZoneRefusal::none) return describe(refusal, site, zone);
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
  std::string text;
  appendf(text, "c+ %.3f c- %.3f V, b+ %.3f b- %.3f %s, breakaway +%.3f -%.3f V", c_pos, c_neg, b_pos, b_neg,
          viscous_unit, s_pos, s_neg);
  return text;
}

std::string estimate_json(const Estimate* e) {
  if (e == nullptr) return ", \"estimate\": null";
  std::string text;
  appendf(text,
          ", \"estimate\": {\"payload_mass_kg\": %g, \"payload_mass_bound_kg\": %g, \"payload_confident\": %s, "
          "\"adaptation\": [%s], \"trolley_friction_V\": [%g, %g, %g, %g, %g, %g], "
          "\"slew_friction_V\": [%g, %g, %g, %g, %g, %g], \"trolley_voltage_sign_changes\": %u, "
          "\"slew_voltage_sign_changes\": %u, \"swing_length_scale\": %g, \"swing_length_offset_m\": %g, "
          "\"swing_length_bound_m\": %g, \"swing_length_confident\": %s, \"seq\": %llu}",
          e->payload_mass, e->payload_mass_bound, e->payload_confident ? "true" : "false",
          adaptation_list(e->adaptation, ", ", "\"").c_str(), e->trolley_friction_viscous_positive,
          e->trolley_friction_viscous_negative, e->trolley_friction_coulomb_positive,
          e->trolley_friction_coulomb_negative, e->trolley_friction_static_positive,
          e->trolley_friction_static_negative, e->slew_friction_viscous_positive, e->slew_friction_viscous_negative,
          e->slew_friction_coulomb_positive, e->slew_friction_coulomb_negative, e->slew_friction_static_positive,
          e->slew_friction_static_negative, e->trolley_voltage_sign_changes, e->slew_voltage_sign_changes,
          e->swing_length_scale, e->swing_length_offset, e->swing_length_bound,
          e->swing_length_confident ? "true" : "false", static_cast<unsigned long long>(e->header.seq));
  return text;
}

void append_estimate(std::string& text, const Estimate* e) {
  if (e == nullptr) {
    text += "payload         no estimate (the state estimator is silent)\n";
    return;
  }
  const bool enabled = (e->adaptation & Estimate::ADAPTATION_ENABLED) != 0;
  if (!enabled) {
    appendf(text, "payload         %.2f kg (configured; online estimation off)\n", e->payload_mass);
  } else if (!e->payload_confident && e->payload_mass_bound == 0.0) {
    appendf(text, "payload         %.2f kg (configured; online estimate: not identified yet, the load needs to move)\n",
            e->payload_mass);
  } else if (e->payload_confident) {
    appendf(text, "payload         %.3f kg +- %.3f kg (online estimate, 2 sigma; in use)\n", e->payload_mass,
            e->payload_mass_bound);
  } else {
    appendf(text, "payload         %.3f kg +- %.3f kg (online estimate, not yet confident: the configured mass is used)\n",
            e->payload_mass, e->payload_mass_bound);
  }
  const auto axis = [&](const char* label, std::uint8_t adapted, std::uint8_t cycle, const std::string& friction) {
    const char* source = (e->adaptation & cycle) ? "configured (limit cycle detected: fallback)"
                         : (e->adaptation & adapted) ? "online re-estimate"
                                                     : "configured";
    appendf(text, "%s %s: %s\n", label, source, friction.c_str());
  };
  axis("trolley friction", Estimate::ADAPTATION_TROLLEY_FRICTION_ADAPTED, Estimate::ADAPTATION_TROLLEY_LIMIT_CYCLE,
       friction_text(e->trolley_friction_viscous_positive, e->trolley_friction_viscous_negative,
                     e->trolley_friction_coulomb_positive, e->trolley_friction_coulomb_negative,
                     e->trolley_friction_static_positive, e->trolley_friction_static_negative, "V s/m"));
  axis("slew friction   ", Estimate::ADAPTATION_SLEW_FRICTION_ADAPTED, Estimate::ADAPTATION_SLEW_LIMIT_CYCLE,
       friction_text(e->slew_friction_viscous_positive, e->slew_friction_viscous_negative,
                     e->slew_friction_coulomb_positive, e->slew_friction_coulomb_negative,
                     e->slew_friction_static_positive, e->slew_friction_static_negative, "V s/rad"));
  if (enabled) {
    appendf(text, "sign changes    drive voltage at rest: trolley %u, slew %u\n", e->trolley_voltage_sign_changes,
            e->slew_voltage_sign_changes);
  }
  if (e->swing_length_confident) {
    appendf(text, "pendulum        %.4f L %+.4f m, +- %.4f m where learnt (online estimate, 2 sigma; the plans swing it)\n",
            e->swing_length_scale, e->swing_length_offset, e->swing_length_bound);
  } else {
    text += "pendulum        the planner's configured a L + c (trajectory_planner.manual; no online estimate)\n";
  }
}

}  // namespace

std::string format_status(const Status& s, const Estimate* estimate, bool json) {
  const auto mode = code_name("MODE", s.mode);
  const auto operating = code_name("OPERATION", s.operating_mode);
  std::string text;
  if (json) {
    appendf(text,
            "{\"mode\": \"%s\", \"motion_enabled\": %s, \"brakes_released\": %s, \"active_faults\": %s, "
            "\"latched_faults\": %s, \"fault_count\": %u, \"last_fault\": \"%s\", \"last_fault_seq\": %llu, "
            "\"stages_alive\": %u, \"warnings\": %u, \"trolley_voltage_limit_V\": %g, \"slew_voltage_limit_V\": %g, "
            "\"trolley_velocity_mps\": %g, \"slew_rate_radps\": %g, \"nonfinite_rejected\": %u, \"seq\": %llu, "
            "\"operating_mode\": \"%s\", \"zones_enabled\": %u, \"bridge_voltage_limit_V\": %g, "
            "\"bridge_velocity_mps\": %g",
            mode.c_str(), s.motion_enabled ? "true" : "false", s.brakes_released ? "true" : "false",
            quoted_list(s.active_faults).c_str(), quoted_list(s.latched_faults).c_str(), s.fault_count,
            s.last_fault != 0 ? code_name("FAULT", s.last_fault).c_str() : "",
            static_cast<unsigned long long>(s.last_fault_seq), s.stages_alive, s.warnings, s.trolley_voltage_limit,
            s.slew_voltage_limit, s.trolley_velocity, s.slew_rate, s.nonfinite_rejected,
            static_cast<unsigned long long>(s.header.seq), operating.c_str(), s.zones_enabled, s.bridge_voltage_limit,
            s.bridge_velocity);
    text += estimate_json(estimate) + "}\n";
    return text;
  }
  appendf(text, "mode            %s\n", mode.c_str());
  appendf(text, "operating mode  %s\n", operating.c_str());
  appendf(text, "zones enforced  %s%s\n", zone_list(s.zones_enabled).c_str(),
          (s.warnings & Status::WARNING_ZONE_APPROACH) ? " (approaching one: soft stop)" : "");
  appendf(text, "motion          %s, brakes %s%s\n", s.motion_enabled ? "enabled" : "disabled",
          s.brakes_released ? "released" : "engaged",
          (s.warnings & Status::WARNING_DRIVES_BRAKED) ? " (the drives report them on: braked under way)" : "");
  appendf(text, "active faults   %s\n", s.active_faults ? fault_list(s.active_faults).c_str() : "none");
  appendf(text, "latched faults  %s\n", s.latched_faults ? fault_list(s.latched_faults).c_str() : "none");
  appendf(text, "faults raised   %u, last: %s at cycle %llu\n", s.fault_count,
          s.last_fault ? code_name("FAULT", s.last_fault).c_str() : "none",
          static_cast<unsigned long long>(s.last_fault_seq));
  appendf(text, "stages alive    %s%s%s\n", stage_list(s.stages_alive, true).c_str(),
          s.stages_alive != Status::STAGES_ALL ? "; silent: " : "",
          s.stages_alive != Status::STAGES_ALL ? stage_list(s.stages_alive, false).c_str() : "");
  appendf(text, "voltage limits  trolley %.2f V, slew %.2f V%s\n", s.trolley_voltage_limit, s.slew_voltage_limit,
          (s.warnings & Status::WARNING_SPEED_LIMITED) ? " (approach speed exceeded)" : "");
  appendf(text, "speeds          trolley %.3f m/s, slew %.3f rad/s\n", s.trolley_velocity, s.slew_rate);
  if (s.bridge_voltage_limit != 0.0 || s.bridge_velocity != 0.0) {  // an overhead crane's bridge
    appendf(text, "bridge          %.3f m/s, voltage limit %.2f V%s\n", s.bridge_velocity, s.bridge_voltage_limit,
            (s.warnings & Status::WARNING_BRIDGE_APPROACH) ? " (approaching a runway limit)" : "");
  }
  appendf(text, "cycle           %llu\n", static_cast<unsigned long long>(s.header.seq));
  append_estimate(text, estimate);
  return text;
}

void add_operator_options(CLI::App& app, OperatorRequest& request) {
  app.add_option("action", request.action, "arm | disarm | estop | reset | status | mode | zone")
      ->required()
      ->check(CLI::IsMember({"arm", "disarm", "estop", "reset", "status", "mode", "zone"}));
  app.add_option("arguments", request.arguments,
                 "mode: manual | semiautomatic | fullautomatic | maintenance; zone: enable | disable N");
  app.add_option("--timeout", request.timeout, "[s] longest wait for the supervisor")->check(CLI::Range(0.1, 60.0));
  app.add_flag("--json", request.json, "status as one JSON object");
  app.add_option("--config", request.config_path, "the stack's configuration (a refused zone command names the zone)");
}

OperatorExchange::OperatorExchange(OperatorRequest request, std::uint32_t request_id, std::uint32_t domain,
                                   Clock::time_point now)
    : request_(std::move(request)),
      request_id_(request_id),
      domain_(domain),
      deadline_(now + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(request_.timeout))) {
  const auto usage = [&](const std::string& message) {
    outcome_.err = message + "\n";
    finish(2);
  };
  const auto& action = request_.action;
  const auto& arguments = request_.arguments;
  command_.request_id = request_id_;
  if (action == "status") {
    if (!arguments.empty()) usage("status takes no argument");
    return;
  }
  if (request_id_ == 0) {
    usage("request id 0 is the supervisor's 'no request'");
    return;
  }
  if (action == "mode") {
    for (const auto& code : Status::kCodes) {
      if (code.group == "OPERATION" && arguments.size() == 1 && code.name == arguments[0]) {
        command_.operating_mode = static_cast<std::uint8_t>(code.value);
      }
    }
    if (command_.operating_mode == 0) {
      usage("mode needs one of manual, semiautomatic, fullautomatic, maintenance");
      return;
    }
    command_.command = CommandCodes::COMMAND_SET_OPERATING_MODE;
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
      usage("zone needs enable | disable and a zone index in [0, 31]");
      return;
    }
    command_.zone = static_cast<std::uint8_t>(index);
    command_.command = arguments[0] == "enable" ? CommandCodes::COMMAND_ENABLE_ZONE : CommandCodes::COMMAND_DISABLE_ZONE;
  } else if (!arguments.empty()) {
    usage(action + " takes no argument");
    return;
  } else if (action == "arm") {
    command_.command = CommandCodes::COMMAND_ARM;
  } else if (action == "disarm") {
    command_.command = CommandCodes::COMMAND_DISARM;
  } else if (action == "estop") {
    command_.command = CommandCodes::COMMAND_EMERGENCY_STOP;
  } else if (action == "reset") {
    command_.command = CommandCodes::COMMAND_RESET;
  } else {
    usage("unknown command '" + action + "' (arm, disarm, estop, reset, status, mode, zone)");
  }
}

void OperatorExchange::finish(int exit_code) {
  outcome_.exit_code = exit_code;
  finished_ = true;
}

std::optional<protocol::SupervisorCommand> OperatorExchange::command_due(Clock::time_point now, bool supervisor_matched) {
  if (finished_ || is_status() || !supervisor_matched) return std::nullopt;
  ever_matched_ = true;
  if (sent_ && now < next_send_) return std::nullopt;
  sent_ = true;
  next_send_ = now + kResendPeriod;
  return command_;
}

void OperatorExchange::on_status(const Status& status, Clock::time_point now) {
  if (finished_) return;
  if (is_status()) {
    if (!status_) estimate_deadline_ = now + kEstimateWait;
    status_ = status;
    return;
  }
  if (!sent_ || status.last_request_id != request_id_) return;
  const bool accepted = status.last_request_result == Status::RESULT_ACCEPTED;
  const auto& arguments = request_.arguments;
  appendf(outcome_.out, "%s%s%s %s: mode %s, operating mode %s, zones enforced %s, brakes %s\n",
          request_.action.c_str(), arguments.empty() ? "" : " ", arguments.empty() ? "" : arguments.back().c_str(),
          accepted ? "accepted" : "refused", code_name("MODE", status.mode).c_str(),
          code_name("OPERATION", status.operating_mode).c_str(), zone_list(status.zones_enabled).c_str(),
          status.brakes_released ? "released" : "engaged");
  if (!accepted && request_.action == "zone") {
    appendf(outcome_.out, "  %s\n", zone_refusal_text(request_.config_path, command_.command, command_.zone).c_str());
  } else if (!accepted) {
    appendf(outcome_.out, "  latched faults: %s; active: %s; silent stages: %s\n",
            status.latched_faults ? fault_list(status.latched_faults).c_str() : "none",
            status.active_faults ? fault_list(status.active_faults).c_str() : "none",
            status.stages_alive == Status::STAGES_ALL ? "none" : stage_list(status.stages_alive, false).c_str());
  }
  finish(accepted ? 0 : 3);
}

void OperatorExchange::on_estimate(const Estimate& estimate) {
  if (!finished_) estimate_ = estimate;
}

bool OperatorExchange::done(Clock::time_point now) {
  if (finished_) return true;
  if (is_status() && status_ && (estimate_ || now >= std::min(deadline_, estimate_deadline_))) {
    outcome_.out = format_status(*status_, estimate_ ? &*estimate_ : nullptr, request_.json);
    finish(0);
    return true;
  }
  if (now < deadline_) return false;
  if (is_status()) {
    appendf(outcome_.err, "no supervisor status on domain %u within %.1f s\n", domain_, request_.timeout);
  } else if (!ever_matched_) {
    appendf(outcome_.err, "no supervisor listens on rt/crane/safety/command (domain %u) within %.1f s\n",
            domain_, request_.timeout);
  } else {
    appendf(outcome_.err, "the supervisor did not answer request %u within %.1f s\n", request_id_,
            request_.timeout);
  }
  finish(1);
  return true;
}

OperatorExchange::Clock::time_point OperatorExchange::next_check(Clock::time_point now) const {
  if (finished_) return now;
  auto next = deadline_;
  if (is_status() && status_) next = std::min(next, estimate_deadline_);
  if (sent_) next = std::min(next, next_send_);
  return std::max(now, next);
}

}  // namespace crane::supervisor
