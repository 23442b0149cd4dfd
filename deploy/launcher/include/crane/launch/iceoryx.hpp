#pragma once
// iceoryx's RouDi daemon for a stack on shared memory (StackOptions::iceoryx; docs/architecture.md,
// "Shared memory").
//
// RouDi must outlive every process registered with it: when it stops, it sends SIGTERM to each of
// them and, after its kill delay, SIGKILL. A launcher whose own participant is on iceoryx (crane_bench,
// crane_demo, crane_launch) therefore cannot be RouDi's parent and stop it: run_beside_roudi() forks
// the launcher's work into a child and stops RouDi only once that child has exited. A stack started
// from a process that stays off iceoryx (a test's monitor) lists RouDi as its first process instead.
// One RouDi runs per machine (a second one aborts: "Could not acquire lock").

#include <sys/types.h>

#include <chrono>
#include <functional>
#include <string>

#include "crane/launch/process_group.hpp"

namespace crane::launch {

/// RouDi's process name (its log: <log directory>/iox_roudi.log).
inline constexpr const char* kRoudiProcess = "iox_roudi";

/// How long RouDi outlives a client that a signal ended (ProcessSpec::outlive_killed): iceoryx 2.0
/// drops a client whose keep-alive lapsed for PROCESS_KEEP_ALIVE_TIMEOUT (1.5 s); a RouDi stopped
/// while it still holds a dead client fails to signal it and aborts
/// (POSH__ROUDI_PROCESS_SHUTDOWN_FAILED), leaving its shared memory in /dev/shm.
inline constexpr std::chrono::milliseconds kRoudiOutlivesKilled{2000};

/// iox-roudi (found on PATH) at warning log level, its output to `log_path` (empty: inherited),
/// stopped after the rest of its group (kRoudiOutlivesKilled).
/// Throws std::invalid_argument when iox-roudi is not on PATH (Debian package iceoryx).
ProcessSpec roudi_process(const std::string& log_path);

/// Starts RouDi, runs `body` in a forked child process (its return value is the child's exit code,
/// an exception its message on stderr and code 1), and stops RouDi once that child has exited.
/// SIGINT and SIGTERM to this process are passed to the child. If RouDi exits first, the child
/// gets SIGTERM and the result is nonzero. Call it before any thread is started. Returns the
/// child's exit code (128 + the signal if a signal ended it). Throws what roudi_process() throws
/// and std::runtime_error if fork fails.
int run_beside_roudi(const std::string& roudi_log, const std::function<int()>& body);

/// Where iceoryx 2.0 on Linux puts each client runtime's socket and its lock file:
/// <kIceoryxRuntimeDirectory>/iceoryx_rt_<pid>_<time> and the same with ".lock".
inline constexpr const char* kIceoryxRuntimeDirectory = "/tmp";

/// Removes the files whose names begin with "iceoryx_rt_<pid>_" in `directory`: what the iceoryx
/// runtime of process `pid` leaves behind when a signal ends it (a clean exit removes them). Call it
/// only while `pid` cannot be another process's, that is before its parent reaps it (ProcessGroup
/// does, for a child that a signal ended). Returns how many files it removed; a file that is
/// already gone or cannot be removed is skipped, and a missing directory gives 0.
int remove_iceoryx_runtime_files(pid_t pid, const std::string& directory = kIceoryxRuntimeDirectory);

}  // namespace crane::launch
