// crane_safety: the operator's commands to the supervisor, and its status, from a participant of
// its own (crane_operator runs it where no operator relay serves the domain, or with --direct).
//
//   crane_safety arm | disarm | estop | reset   send the command on rt/crane/safety/command and wait
//                                              for the supervisor to answer it on the status topic
//   crane_safety mode manual | semiautomatic | fullautomatic | maintenance
//                                              change the operating mode (OPC 40020): the same
//   crane_safety zone enable | disable N        switch no-go zone N (index in site.zones): the same
//   crane_safety status [--json]                print the supervisor's latest status
//
// The exchange (what is sent, when again, what is printed) is crane::supervisor::OperatorExchange,
// the operator relay's too. Exit codes: 0 done (command accepted / status printed), 1 no supervisor
// answered within --timeout, 2 bad usage, 3 the supervisor refused the command (the reason is in
// its log: arm needs a healthy chain and no latched fault, reset needs a healthy chain and no active
// fault, zone needs an index of site.zones and disable one that is not fixed). With --config
// (deploy/crane passes its configuration) a refused zone command names the zone and why.
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <string>

#include "crane/protocol/dds.hpp"
#include "crane/runtime/node_runtime.hpp"
#include "crane/supervisor/operator_command.hpp"

int main(int argc, char** argv) {
  using namespace crane;
  namespace tp = transport::topics;
  using Clock = std::chrono::steady_clock;
  CLI::App app{"crane_safety: arm, disarm, emergency stop, reset and status of the crane supervisor"};
  supervisor::OperatorRequest request;
  supervisor::add_operator_options(app, request);
  runtime::NodeOptions options;
  app.add_option("--dds", options.dds, "DDS vendor: fast | cyclone (default: $CRANE_DDS, else fast)");
  app.add_option("--domain", options.domain_id, "DDS domain id")->check(CLI::Range(0, 232));
  runtime::add_security_options(app, options);  // identity: the participant's, "operator"
  CLI11_PARSE(app, argc, argv);
  const auto id = static_cast<std::uint32_t>((static_cast<std::uint64_t>(getpid()) << 16) ^
                                             static_cast<std::uint64_t>(runtime::now_nanoseconds()));
  supervisor::OperatorExchange exchange(request, id == 0 ? 1U : id, options.domain_id, Clock::now());
  const auto print = [](const supervisor::OperatorOutcome& outcome) {
    std::fputs(outcome.out.c_str(), stdout);
    if (!outcome.err.empty()) std::fprintf(stderr, "crane_safety: %s", outcome.err.c_str());
    return outcome.exit_code;
  };
  if (exchange.done(Clock::now())) return print(exchange.outcome());  // bad usage: no participant
  try {
    runtime::configure_logging("warn", "crane_safety");
    auto participant = runtime::make_participant(options, "operator");
    transport::Wakeup wakeup;
    auto status_reader = participant->make_reader<tp::SafetyStatus>(&wakeup);
    std::unique_ptr<transport::Reader<tp::StateEstimate>> estimate_reader;
    std::unique_ptr<transport::Writer<tp::SafetyCommand>> writer;
    if (exchange.is_status()) {
      estimate_reader = participant->make_reader<tp::StateEstimate>(&wakeup);
    } else {
      writer = participant->make_writer<tp::SafetyCommand>();
    }
    for (auto now = Clock::now(); !exchange.done(now); now = Clock::now()) {
      if (writer) {
        if (auto command = exchange.command_due(now, writer->health().matched_readers > 0)) {
          tp::msgs::SupervisorCommand_ message;
          protocol::to_dds(*command, message);
          runtime::stamp_header(message.header(), 0, runtime::now_stamp());
          writer->write(message);
        }
      }
      tp::msgs::SupervisorStatus_ status;
      while (status_reader->take_next(status)) {
        protocol::SupervisorStatus plain;
        protocol::from_dds(status, plain);
        exchange.on_status(plain, now);
      }
      tp::msgs::CraneState_ estimate;
      while (estimate_reader && estimate_reader->take_next(estimate)) {
        protocol::CraneState plain;
        protocol::from_dds(estimate, plain);
        exchange.on_estimate(plain);
      }
      if (exchange.done(now)) break;
      // A writer's match wakes no reader: look again within 10 ms while the supervisor is not matched.
      wakeup.wait_until(std::min(exchange.next_check(now), now + std::chrono::milliseconds(10)));
    }
    return print(exchange.outcome());
  } catch (const std::exception& error) {
    std::fprintf(stderr, "crane_safety: %s\n", error.what());
    return 1;
  }
}
