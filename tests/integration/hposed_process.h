// hposed in its own process, for tests that measure its memory or read its log.
#ifndef HPOSE_TESTS_INTEGRATION_HPOSED_PROCESS_H_
#define HPOSE_TESTS_INTEGRATION_HPOSED_PROCESS_H_

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace hpose::testing_util {

// Starts hposed (HPOSE_BINARY_DIR/server/hposed) with `args` and waits for its "listening on"
// line; address() is then the address it serves (empty when it did not start). Its standard
// error goes to `log_path` when given. SIGINT and a wait when destroyed.
class HposedProcess {
 public:
  explicit HposedProcess(const std::vector<std::string>& args, const std::string& log_path = "") {
    int fds[2];
    if (::pipe(fds) != 0) return;
    pid_ = ::fork();
    if (pid_ == 0) {
      ::dup2(fds[1], STDOUT_FILENO);
      ::close(fds[0]);
      if (!log_path.empty()) {
        const int log = ::open(log_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
        if (log >= 0) ::dup2(log, STDERR_FILENO);
      }
      const std::string program = std::string(HPOSE_BINARY_DIR) + "/server/hposed";
      std::vector<char*> argv{const_cast<char*>(program.c_str())};
      for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
      argv.push_back(nullptr);
      ::execv(program.c_str(), argv.data());
      ::_exit(127);
    }
    ::close(fds[1]);
    out_ = ::fdopen(fds[0], "r");
    char line[1024];
    while (out_ != nullptr && std::fgets(line, sizeof(line), out_) != nullptr) {
      const std::string text = line;
      const size_t at = text.find("listening on ");
      if (at == std::string::npos) continue;
      address_ = text.substr(at + 13, text.find(' ', at + 13) - (at + 13));
      break;
    }
    // hposed keeps logging to standard output (state changes, streams opening and closing): keep
    // reading it, or a full pipe would block the daemon's logging threads.
    if (out_ != nullptr) {
      drain_ = std::thread([this] {
        char buf[1024];
        while (std::fgets(buf, sizeof(buf), out_) != nullptr) {
          std::lock_guard<std::mutex> lock(output_mu_);
          output_ += buf;
        }
      });
    }
  }
  HposedProcess(const HposedProcess&) = delete;
  HposedProcess& operator=(const HposedProcess&) = delete;
  ~HposedProcess() {
    if (pid_ > 0) {
      ::kill(pid_, SIGINT);
      int status = 0;
      ::waitpid(pid_, &status, 0);
    }
    if (drain_.joinable()) drain_.join();  // ends at the pipe's end of file.
    if (out_ != nullptr) std::fclose(out_);
  }
  const std::string& address() const { return address_; }
  // What hposed has written on its standard output (its log) after the address line so far.
  std::string output() const {
    std::lock_guard<std::mutex> lock(output_mu_);
    return output_;
  }
  bool alive() const { return pid_ > 0 && ::kill(pid_, 0) == 0 && !Exited(); }
  // A field of /proc/PID/status in kB (VmRSS, VmHWM), -1 when unreadable.
  long StatusKb(const std::string& field) const {
    std::ifstream in("/proc/" + std::to_string(pid_) + "/status");
    std::string key;
    long value = -1;
    while (in >> key) {
      if (key == field + ":") {
        in >> value;
        return value;
      }
      std::getline(in, key);
    }
    return -1;
  }

 private:
  // True once the process has ended (a zombie still answers kill(pid, 0)).
  bool Exited() const {
    std::ifstream in("/proc/" + std::to_string(pid_) + "/stat");
    std::string pid, name, state;
    in >> pid >> name >> state;
    return !in || state == "Z";
  }

  pid_t pid_ = -1;
  FILE* out_ = nullptr;
  std::string address_;
  std::thread drain_;
  mutable std::mutex output_mu_;
  std::string output_;
};

}  // namespace hpose::testing_util

#endif  // HPOSE_TESTS_INTEGRATION_HPOSED_PROCESS_H_
