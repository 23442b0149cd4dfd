#pragma once
// Starts each stage of the stack as its own OS process and stops them all cleanly.
//
// Every child is started with fork/exec, its stdout and stderr appended to a log file, and with
// PR_SET_PDEATHSIG = SIGTERM so it stops if the launcher itself dies. stop_all() sends SIGTERM to
// each child by its pid (only processes this group started), waits up to a grace period and then
// sends SIGKILL to the ones still running.

#include <sys/types.h>

#include <chrono>
#include <optional>
#include <string>
#include <vector>

namespace crane::launch {

struct ProcessSpec {
  std::string name;                // stage name, e.g. "plant"
  std::string executable;          // absolute path
  std::vector<std::string> arguments;
  std::string log_path;            // stdout+stderr go here; empty: inherit
  // >= 0: stop_all() stops this one only after every other child has ended, and no sooner than
  // this after the last child that a signal ended, unless it ends by itself first (iceoryx's RouDi:
  // it must see a killed client's keep-alive lapse before it stops, or it aborts; roudi_process()).
  // < 0 (the default): with the others.
  std::chrono::milliseconds outlive_killed{-1};
};

struct ChildExit {
  std::string name;
  pid_t pid{0};
  int status{0};                   // raw waitpid status
  [[nodiscard]] std::string describe() const;  // "plant (pid 123) exited with code 1" / "killed by signal 9"
};

class ProcessGroup {
 public:
  ProcessGroup() = default;
  ~ProcessGroup();
  ProcessGroup(const ProcessGroup&) = delete;
  ProcessGroup& operator=(const ProcessGroup&) = delete;

  /// Starts one process; throws std::runtime_error naming it if fork fails. An exec failure happens
  /// in the child, which then exits with code 127 (seen by poll()) after writing "exec failed" to
  /// its log.
  pid_t start(const ProcessSpec& spec);
  /// Reaps one child that exited, if any (non-blocking).
  std::optional<ChildExit> poll();
  /// SIGTERM to every running child, wait up to `grace`, then SIGKILL; then the same for those
  /// that outlive the others (ProcessSpec::outlive_killed), after their wait. Returns how each ended.
  std::vector<ChildExit> stop_all(std::chrono::milliseconds grace = std::chrono::milliseconds(3000));

  struct Child {
    std::string name;
    pid_t pid;
    bool running;
    std::chrono::milliseconds outlive_killed;
  };
  [[nodiscard]] const std::vector<Child>& children() const noexcept { return children_; }

 private:
  void ended(Child& child, int status, std::vector<ChildExit>* exits);
  void stop_children(std::vector<ChildExit>& exits, std::chrono::milliseconds grace, bool outliving);

  std::vector<Child> children_;
  std::optional<std::chrono::steady_clock::time_point> last_killed_;  // the last child a signal ended
};

/// Reaps the child `pid` once it has ended, its raw waitpid status in `status`. `block`: waits for
/// that; else returns false at once while it runs. Also false when `pid` is not a child of this
/// process. A child that a signal ended first loses its iceoryx runtime's files
/// (remove_iceoryx_runtime_files, launch/iceoryx.hpp): seen with WNOWAIT, it is still a zombie then,
/// so no other process can hold its pid yet.
bool reap(pid_t pid, int& status, bool block);

/// Absolute path of the directory holding this executable (/proc/self/exe).
std::string executable_directory();

/// The first executable file `name` in the directories of $PATH, as the shell would find it; empty
/// when there is none (or PATH is unset).
std::string find_executable(const std::string& name);

/// Whether a process started from here may run on SCHED_FIFO at `priority` and lock its memory, as
/// every stage does with --realtime-priority: a forked child tries both and exits. Empty string if
/// it may, else what failed and why ("SCHED_FIFO 80: Operation not permitted", "mlockall: ...").
std::string probe_realtime(int priority);

}  // namespace crane::launch
