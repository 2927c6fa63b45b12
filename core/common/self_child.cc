#include "core/common/self_child.h"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <thread>
#include <vector>

extern char** environ;

namespace hpose {
namespace {

constexpr int kOutputFd = 3;

// Closes a descriptor when it goes out of scope.
struct Fd {
  int fd = -1;
  ~Fd() { Reset(); }
  void Reset() {
    if (fd >= 0) close(fd);
    fd = -1;
  }
};

std::string SignalName(int sig) {
  const char* name = sigabbrev_np(sig);
  return name != nullptr ? "SIG" + std::string(name) : "signal " + std::to_string(sig);
}

}  // namespace

int SelfChildOutputFd() { return kOutputFd; }

void LimitSelfChildMemory(unsigned long long bytes) {
#if defined(__SANITIZE_ADDRESS__)
  (void)bytes;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
  (void)bytes;
#else
  const rlimit limit{bytes, bytes};
  setrlimit(RLIMIT_AS, &limit);
#endif
#else
  const rlimit limit{bytes, bytes};
  setrlimit(RLIMIT_AS, &limit);
#endif
}

unsigned long long HalfThePhysicalMemory() {
  const long pages = sysconf(_SC_PHYS_PAGES);
  const long page = sysconf(_SC_PAGESIZE);
  const unsigned long long gib = 1ull << 30;
  if (pages <= 0 || page <= 0) return 4 * gib;
  return std::max(
      gib, static_cast<unsigned long long>(pages) * static_cast<unsigned long long>(page) / 2);
}

const char* RunningAsSelfChild(const char* variable) { return std::getenv(variable); }

bool WriteSelfChildOutput(const void* data, size_t bytes) {
  const char* p = static_cast<const char*>(data);
  while (bytes > 0) {
    const ssize_t n = write(kOutputFd, p, bytes);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    p += n;
    bytes -= static_cast<size_t>(n);
  }
  return true;
}

SelfChildRun RunSelfAsChild(const std::string& variable, const std::string& value,
                            double timeout_s) {
  SelfChildRun run;
  std::vector<std::string> variables;
  const std::string prefix = variable + "=";
  for (char** e = environ; e != nullptr && *e != nullptr; ++e) {
    if (std::strncmp(*e, prefix.c_str(), prefix.size()) != 0) variables.emplace_back(*e);
  }
  variables.push_back(prefix + value);
  std::vector<char*> envp;
  for (std::string& v : variables) envp.push_back(v.data());
  envp.push_back(nullptr);

  int ends[2];
  if (pipe2(ends, O_CLOEXEC) != 0) return run;
  Fd read_end{ends[0]}, write_end{ends[1]};
  posix_spawn_file_actions_t actions;
  if (posix_spawn_file_actions_init(&actions) != 0) return run;
  // dup2 onto the child's descriptor 3 clears close-on-exec there (also when it is 3 already).
  const bool mapped = posix_spawn_file_actions_adddup2(&actions, write_end.fd, kOutputFd) == 0;
  std::string name = "hpose-child";
  char* argv[] = {name.data(), nullptr};
  pid_t pid = -1;
  const bool spawned =
      mapped && posix_spawn(&pid, "/proc/self/exe", &actions, nullptr, argv, envp.data()) == 0;
  posix_spawn_file_actions_destroy(&actions);
  if (!spawned) return run;
  run.started = true;
  write_end.Reset();  // the child's copy is the only writer: its end is the pipe's end.

  using Clock = std::chrono::steady_clock;
  const Clock::duration patience =
      std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(timeout_s));
  Clock::time_point deadline = Clock::now() + patience;
  auto ms_left = [&] {
    const auto left =
        std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now());
    return static_cast<int>(std::max<long long>(0, std::min<long long>(left.count(), 1000)));
  };
  char buffer[1 << 16];
  bool pipe_open = true;
  int status = 0;
  for (;;) {
    if (pipe_open) {
      pollfd p{read_end.fd, POLLIN, 0};
      const int ready = poll(&p, 1, ms_left());
      if (ready > 0) {
        const ssize_t n = read(read_end.fd, buffer, sizeof(buffer));
        if (n > 0) {
          run.output.append(buffer, static_cast<size_t>(n));
          deadline = Clock::now() + patience;
        } else if (n == 0 || errno != EINTR) {
          pipe_open = false;
        }
      }
    }
    const pid_t done = waitpid(pid, &status, WNOHANG);
    if (done == pid && !pipe_open) break;
    if (done == pid) {  // exited: what it wrote is in the pipe (or a descendant holds it open).
      pollfd p{read_end.fd, POLLIN, 0};
      while (poll(&p, 1, 0) > 0) {
        const ssize_t n = read(read_end.fd, buffer, sizeof(buffer));
        if (n <= 0) break;
        run.output.append(buffer, static_cast<size_t>(n));
      }
      break;
    }
    if (done < 0 && errno != EINTR) {  // reaped elsewhere: how it ended is not known.
      run.started = false;
      return run;
    }
    if (Clock::now() >= deadline) {
      kill(pid, SIGKILL);
      waitpid(pid, &status, 0);
      run.timed_out = true;
      return run;
    }
    if (!pipe_open) std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  if (WIFEXITED(status)) run.exit_status = WEXITSTATUS(status);
  if (WIFSIGNALED(status)) run.signal = WTERMSIG(status);
  return run;
}

std::string DescribeSelfChildEnd(const SelfChildRun& run, double timeout_s) {
  if (run.timed_out) {
    char seconds[32];
    std::snprintf(seconds, sizeof(seconds), "%g", timeout_s);
    return "did not finish within " + std::string(seconds) + " s";
  }
  if (run.signal != 0) return "died of " + SignalName(run.signal);
  return "ended with status " + std::to_string(run.exit_status);
}

}  // namespace hpose
