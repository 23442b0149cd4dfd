#pragma once
// The operator's commands to the supervisor (deploy/crane arm | disarm | estop | reset | mode |
// zone | status) as one exchange, without DDS: the request parsed from the command line, the
// SupervisorCommand it asks to write, the answer printed from the status that echoes its request
// id, and the exit code. The caller takes the status and estimate samples and hands them in, and
// writes the commands the exchange asks for. Two callers (docs/operation.md, "Operator commands"):
//   crane_safety     a participant of its own for one command: it discovers the supervisor first
//                    (about 100-200 ms, sometimes a second);
//   operator_relay   the stack's long-lived operator participant, already matched with the
//                    supervisor, serving crane_operator over a local socket: the command is on the
//                    bus within a millisecond of the relay reading it.
// Both run the same exchange, so a command behaves and prints the same on either path.

#include <chrono>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "crane/protocol/messages.hpp"

namespace CLI {
class App;
}

namespace crane::supervisor {

/// One operator command as typed.
struct OperatorRequest {
  std::string action;                  // arm | disarm | estop | reset | status | mode | zone
  std::vector<std::string> arguments;  // mode: manual | semiautomatic | fullautomatic | maintenance;
                                       // zone: enable | disable N (N: index in site.zones, 0-31)
  double timeout{3.0};                 // [s] longest wait for the supervisor's answer, in [0.1, 60]
  bool json{false};                    // status: one JSON object
  std::string config_path;             // the stack's configuration: a refused zone command names the zone
};

/// Adds the positional action and arguments, --timeout, --json and --config to `app`, bound to
/// `request` (the one definition of the operator commands' syntax: crane_safety and operator_relay).
void add_operator_options(CLI::App& app, OperatorRequest& request);

/// What an exchange prints, and its exit code: 0 done (command accepted, status printed), 1 no
/// supervisor answered within the timeout, 2 bad usage, 3 the supervisor refused the command.
struct OperatorOutcome {
  int exit_code{0};
  std::string out;  // standard output
  std::string err;  // standard error (lines without the program's name: the caller prefixes its own)
};

/// One command from request to answer. Not thread-safe; one exchange per command.
class OperatorExchange {
 public:
  using Clock = std::chrono::steady_clock;
  /// The period at which an unanswered command is written again: discovery is not symmetric, a
  /// writer may match the supervisor's reader before that reader matches it, and a volatile command
  /// written then is lost. Every command is idempotent (the same request twice changes nothing).
  static constexpr std::chrono::milliseconds kResendPeriod{50};
  /// How long status waits for the state estimator's estimate after the supervisor's status.
  static constexpr std::chrono::milliseconds kEstimateWait{500};

  /// `request_id`: the command's id in the supervisor's echo, unique per exchange (0 is refused as
  /// usage: the supervisor's status starts at 0). `domain`: the DDS domain, for the messages. A
  /// request that is not a command (unknown mode, a zone index outside [0, 31], arguments where
  /// none are taken) is done at once with exit code 2 and a message naming what is wrong.
  OperatorExchange(OperatorRequest request, std::uint32_t request_id, std::uint32_t domain, Clock::time_point now);

  /// The command to write now, if any: at the first call where the supervisor's command reader is
  /// matched (`supervisor_matched`), then every kResendPeriod until the echo. Nothing for status
  /// or once done.
  [[nodiscard]] std::optional<protocol::SupervisorCommand> command_due(Clock::time_point now, bool supervisor_matched);
  /// A status sample taken from rt/crane/safety/status at `now`.
  void on_status(const protocol::SupervisorStatus& status, Clock::time_point now);
  /// An estimate sample taken from rt/crane/state/estimate (status prints its payload and friction).
  void on_estimate(const protocol::CraneState& estimate);
  /// True once answered, refused as usage, or past the timeout (then exit code 1 and why).
  [[nodiscard]] bool done(Clock::time_point now);
  /// When the caller should look again at the latest (a resend, the estimate wait, the timeout).
  [[nodiscard]] Clock::time_point next_check(Clock::time_point now) const;
  [[nodiscard]] const OperatorOutcome& outcome() const noexcept { return outcome_; }
  [[nodiscard]] bool is_status() const noexcept { return request_.action == "status"; }

 private:
  void finish(int exit_code);
  OperatorRequest request_;
  std::uint32_t request_id_;
  std::uint32_t domain_;
  Clock::time_point deadline_;
  protocol::SupervisorCommand command_{};
  bool finished_{false};
  bool ever_matched_{false};
  bool sent_{false};
  Clock::time_point next_send_{};
  std::optional<protocol::SupervisorStatus> status_;
  std::optional<protocol::CraneState> estimate_;
  Clock::time_point estimate_deadline_{};
  OperatorOutcome outcome_;
};

/// The status as deploy/crane status prints it (`json`: one JSON object), with the estimate's
/// payload and friction when `estimate` is not null.
[[nodiscard]] std::string format_status(const protocol::SupervisorStatus& status, const protocol::CraneState* estimate,
                                        bool json);

}  // namespace crane::supervisor
