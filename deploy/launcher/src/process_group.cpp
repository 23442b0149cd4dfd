#include "crane/launch/process_group.hpp"

#include "crane/launch/iceoryx.hpp"

#include <fcntl.h>
#include <sched.h>
#include <signal.h>
#include <sys/mman.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <thread>

namespace crane::launch {

std::string ChildExit::describe() const {
  std::string text = name + " (pid " + std::to_string(pid) + ")";
  if (WIFEXITED(status)) return text + " exited with code " + std::to_string(WEXITSTATUS(status));
  if (WIFSIGNALED(status)) return text + " was killed by signal " + std::to_string(WTERMSIG(status));
  return text + " ended";
}

bool reap(pid_t pid, int& status, bool block) {
  siginfo_t info{};
  while (waitid(P_PID, static_cast<id_t>(pid), &info, WEXITED | WNOWAIT | (block ? 0 : WNOHANG)) != 0) {
    if (errno != EINTR) return false;
  }
  if (info.si_pid != pid) return false;
  if (info.si_code == CLD_KILLED || info.si_code == CLD_DUMPED) remove_iceoryx_runtime_files(pid);
  while (waitpid(pid, &status, 0) < 0) {
    if (errno != EINTR) return false;
  }
  return true;
}

ProcessGroup::~ProcessGroup() { stop_all(); }

pid_t ProcessGroup::start(const ProcessSpec& spec) {
  std::vector<std::string> argv_storage;
  argv_storage.push_back(spec.executable);
  argv_storage.insert(argv_storage.end(), spec.arguments.begin(), spec.arguments.end());
  std::vector<char*> argv;
  for (auto& a : argv_storage) argv.push_back(a.data());
  argv.push_back(nullptr);

  const pid_t parent = getpid();
  const pid_t pid = fork();
  if (pid < 0) throw std::runtime_error("cannot fork for " + spec.name + ": " + std::strerror(errno));
  if (pid == 0) {
    // Child: stop with the launcher, log to file, exec.
    prctl(PR_SET_PDEATHSIG, SIGTERM);
    if (getppid() != parent) _exit(127);
    if (!spec.log_path.empty()) {
      const int fd = open(spec.log_path.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
      if (fd >= 0) {
        dup2(fd, STDOUT_FILENO);
        dup2(fd, STDERR_FILENO);
        close(fd);
      }
    }
    const int null_fd = open("/dev/null", O_RDONLY);
    if (null_fd >= 0) {
      dup2(null_fd, STDIN_FILENO);
      close(null_fd);
    }
    // Restore default signal handling for the child.
    signal(SIGINT, SIG_DFL);
    signal(SIGTERM, SIG_DFL);
    execv(spec.executable.c_str(), argv.data());
    const char* message = "exec failed\n";
    (void)!write(STDERR_FILENO, message, std::strlen(message));
    _exit(127);
  }
  children_.push_back(Child{spec.name, pid, true, spec.outlive_killed});
  return pid;
}

std::optional<ChildExit> ProcessGroup::poll() {
  for (auto& child : children_) {
    if (!child.running) continue;
    int status = 0;
    if (reap(child.pid, status, false)) {
      ended(child, status, nullptr);
      return ChildExit{child.name, child.pid, status};
    }
  }
  return std::nullopt;
}

std::vector<ChildExit> ProcessGroup::stop_all(std::chrono::milliseconds grace) {
  std::vector<ChildExit> exits;
  stop_children(exits, grace, false);
  stop_children(exits, grace, true);
  return exits;
}

void ProcessGroup::ended(Child& child, int status, std::vector<ChildExit>* exits) {
  child.running = false;
  if (WIFSIGNALED(status)) last_killed_ = std::chrono::steady_clock::now();
  if (exits != nullptr) exits->push_back(ChildExit{child.name, child.pid, status});
}

void ProcessGroup::stop_children(std::vector<ChildExit>& exits, std::chrono::milliseconds grace, bool outliving) {
  const auto selected = [outliving](const Child& c) { return c.running && (c.outlive_killed.count() >= 0) == outliving; };
  const auto reap_selected = [&] {
    bool any = false;
    for (auto& child : children_) {
      if (!selected(child)) continue;
      int status = 0;
      if (reap(child.pid, status, false)) {
        ended(child, status, &exits);
      } else {
        any = true;
      }
    }
    return any;
  };
  if (outliving && last_killed_) {
    // Give each one its time after the last child that a signal ended, unless it ends first.
    for (auto& child : children_) {
      if (!selected(child)) continue;
      const auto until = *last_killed_ + child.outlive_killed;
      while (child.running && std::chrono::steady_clock::now() < until) {
        reap_selected();
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
      }
    }
  }
  for (auto& child : children_) {
    if (selected(child)) kill(child.pid, SIGTERM);
  }
  const auto deadline = std::chrono::steady_clock::now() + grace;
  while (reap_selected()) {
    if (std::chrono::steady_clock::now() > deadline) {
      for (auto& child : children_) {
        if (!selected(child)) continue;
        kill(child.pid, SIGKILL);
        int status = 0;
        reap(child.pid, status, true);
        ended(child, status, &exits);
      }
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
}

std::string executable_directory() {
  return std::filesystem::canonical("/proc/self/exe").parent_path().string();
}

std::string find_executable(const std::string& name) {
  const char* path = std::getenv("PATH");
  if (path == nullptr) return {};
  const std::string directories(path);
  std::size_t begin = 0;
  while (begin <= directories.size()) {
    const std::size_t end = std::min(directories.find(':', begin), directories.size());
    const std::string directory = directories.substr(begin, end - begin);
    const std::string candidate = (directory.empty() ? "." : directory) + "/" + name;
    if (access(candidate.c_str(), X_OK) == 0 && std::filesystem::is_regular_file(candidate)) return candidate;
    begin = end + 1;
  }
  return {};
}

std::string probe_realtime(int priority) {
  const pid_t pid = fork();
  if (pid < 0) return std::string("fork: ") + std::strerror(errno);
  if (pid == 0) {
    sched_param param{};
    param.sched_priority = priority;
    if (sched_setscheduler(0, SCHED_FIFO, &param) != 0) _exit(100 + std::min(errno, 100));
    if (mlockall(MCL_CURRENT | MCL_FUTURE) != 0) _exit(std::min(errno, 99));
    _exit(0);
  }
  int status = 0;
  while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  if (!WIFEXITED(status)) return "the probe process did not exit";
  const int code = WEXITSTATUS(status);
  if (code == 0) return {};
  if (code >= 100) return "SCHED_FIFO " + std::to_string(priority) + ": " + std::strerror(code - 100);
  return std::string("mlockall: ") + std::strerror(code);
}

}  // namespace crane::launch
