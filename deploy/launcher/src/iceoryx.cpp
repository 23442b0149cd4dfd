#include "crane/launch/iceoryx.hpp"

#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <filesystem>
#include <system_error>
#include <stdexcept>
#include <thread>

namespace crane::launch {
namespace {

std::atomic<pid_t> body_pid{0};

void pass_to_body(int signal) {
  const pid_t pid = body_pid.load();
  if (pid > 0) kill(pid, signal);
}

int exit_code(int status) {
  if (WIFEXITED(status)) return WEXITSTATUS(status);
  if (WIFSIGNALED(status)) return 128 + WTERMSIG(status);
  return 1;
}

int wait_for(pid_t pid) {
  int status = 0;
  return reap(pid, status, true) ? exit_code(status) : 1;
}

}  // namespace

ProcessSpec roudi_process(const std::string& log_path) {
  ProcessSpec spec;
  spec.name = kRoudiProcess;
  spec.executable = find_executable("iox-roudi");
  if (spec.executable.empty()) {
    throw std::invalid_argument("iceoryx: iox-roudi is not on PATH (Debian package iceoryx)");
  }
  spec.arguments = {"--log-level", "warning"};
  spec.log_path = log_path;
  spec.outlive_killed = kRoudiOutlivesKilled;
  return spec;
}

int run_beside_roudi(const std::string& roudi_log, const std::function<int()>& body) {
  ProcessGroup roudi;
  roudi.start(roudi_process(roudi_log));
  std::fflush(nullptr);
  const pid_t parent = getpid();
  const pid_t pid = fork();
  if (pid < 0) throw std::runtime_error(std::string("cannot fork the launcher beside RouDi: ") + std::strerror(errno));
  if (pid == 0) {
    prctl(PR_SET_PDEATHSIG, SIGTERM);
    if (getppid() != parent) _exit(1);
    int code = 1;
    try {
      code = body();
    } catch (const std::exception& error) {
      std::fprintf(stderr, "%s\n", error.what());
    }
    std::fflush(nullptr);
    std::exit(code);  // static destructors run: the iceoryx runtime leaves RouDi before it stops
  }
  body_pid.store(pid);
  struct sigaction pass {};
  pass.sa_handler = pass_to_body;
  sigemptyset(&pass.sa_mask);
  struct sigaction old_int {}, old_term {};
  sigaction(SIGINT, &pass, &old_int);
  sigaction(SIGTERM, &pass, &old_term);
  int code = 1;
  for (;;) {
    int status = 0;
    if (reap(pid, status, false)) {
      code = exit_code(status);
      break;
    }
    if (const auto ended = roudi.poll()) {
      std::fprintf(stderr, "%s before the stack: stopping it (one RouDi per machine; see %s)\n",
                   ended->describe().c_str(), roudi_log.empty() ? "its output" : roudi_log.c_str());
      kill(pid, SIGTERM);
      code = wait_for(pid);
      if (code == 0) code = 1;
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  body_pid.store(0);
  sigaction(SIGINT, &old_int, nullptr);
  sigaction(SIGTERM, &old_term, nullptr);
  // A body that failed may have lost a client of RouDi's to a signal (itself, or a stage of its
  // stack, which this group does not see end): RouDi must drop it before it stops.
  if (code != 0 && roudi.children().front().running) std::this_thread::sleep_for(kRoudiOutlivesKilled);
  roudi.stop_all(std::chrono::seconds(10));
  return code;
}

int remove_iceoryx_runtime_files(pid_t pid, const std::string& directory) {
  const std::string prefix = "iceoryx_rt_" + std::to_string(pid) + "_";
  int removed = 0;
  std::error_code error;
  for (const auto& entry : std::filesystem::directory_iterator(directory, error)) {
    if (entry.path().filename().string().rfind(prefix, 0) != 0) continue;
    std::error_code ignored;
    if (std::filesystem::remove(entry.path(), ignored)) ++removed;
  }
  return removed;
}

}  // namespace crane::launch
