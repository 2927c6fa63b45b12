#include "server/openni2_open_check.h"

#include <OpenNI.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

extern char** environ;

namespace hpose::server {
namespace {

constexpr char kCheckVariable[] = "HPOSE_OPENNI2_OPEN_CHECK";
// The child's exit statuses: it opened the recording and read a frame (or waited for one), or
// OpenNI2 refused it without harm.
constexpr int kOpened = 0;
constexpr int kRefused = 3;

// The child: the recording opened as Openni2Source opens it, its properties read and its first
// frame waited for; no close (its process ends here).
[[noreturn]] void RunCheck(const char* path) {
  if (openni::OpenNI::initialize() != openni::STATUS_OK) _exit(kRefused);
  openni::Device device;
  if (device.open(path) != openni::STATUS_OK) _exit(kRefused);
  openni::VideoStream depth;
  if (!device.hasSensor(openni::SENSOR_DEPTH) ||
      depth.create(device, openni::SENSOR_DEPTH) != openni::STATUS_OK) {
    _exit(kRefused);
  }
  if (openni::PlaybackControl* playback = device.getPlaybackControl()) {
    playback->getNumberOfFrames(depth);
    playback->setRepeatEnabled(true);
    playback->setSpeed(-1.0f);
  }
  depth.getVideoMode();
  depth.getMirroringEnabled();
  depth.getHorizontalFieldOfView();
  depth.getVerticalFieldOfView();
  if (depth.start() != openni::STATUS_OK) _exit(kRefused);
  openni::VideoStream* streams[] = {&depth};
  int ready = -1;
  if (openni::OpenNI::waitForAnyStream(streams, 1, &ready, 2000) == openni::STATUS_OK) {
    openni::VideoFrameRef frame;
    depth.readFrame(&frame);
  }
  _exit(kOpened);
}

// Run at start-up of every program that can open a recording: the child of
// CheckRecordingOpens does its check and ends before main.
const bool kRanAsCheck = [] {
  if (const char* path = std::getenv(kCheckVariable)) RunCheck(path);
  return false;
}();

std::string SignalName(int sig) {
  const char* name = sigabbrev_np(sig);
  return name != nullptr ? "SIG" + std::string(name) : "signal " + std::to_string(sig);
}

}  // namespace

Status CheckRecordingOpens(const std::string& path, double timeout_s) {
  (void)kRanAsCheck;
  std::vector<std::string> variables;
  const std::string prefix = std::string(kCheckVariable) + "=";
  for (char** e = environ; e != nullptr && *e != nullptr; ++e) {
    if (std::strncmp(*e, prefix.c_str(), prefix.size()) != 0) variables.emplace_back(*e);
  }
  variables.push_back(prefix + path);
  std::vector<char*> envp;
  for (std::string& v : variables) envp.push_back(v.data());
  envp.push_back(nullptr);
  std::string name = "hpose-openni2-open-check";
  char* argv[] = {name.data(), nullptr};
  pid_t pid = -1;
  if (posix_spawn(&pid, "/proc/self/exe", nullptr, nullptr, argv, envp.data()) != 0) {
    return Status::Ok();  // no child to be had: the caller's own open goes ahead.
  }
  using Clock = std::chrono::steady_clock;
  const Clock::time_point deadline = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                                        std::chrono::duration<double>(timeout_s));
  int status = 0;
  for (;;) {
    const pid_t done = waitpid(pid, &status, WNOHANG);
    if (done == pid) break;
    if (done < 0 && errno != EINTR) return Status::Ok();  // reaped elsewhere: nothing known.
    if (Clock::now() >= deadline) {
      kill(pid, SIGKILL);
      waitpid(pid, &status, 0);
      return MakeError(ErrorCode::kDataLoss,
                       path + ": damaged recording: OpenNI2 did not open it within " +
                           std::to_string(static_cast<int>(timeout_s)) + " s");
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  if (WIFEXITED(status) && (WEXITSTATUS(status) == kOpened || WEXITSTATUS(status) == kRefused)) {
    return Status::Ok();
  }
  const std::string how = WIFSIGNALED(status)
                              ? "died of " + SignalName(WTERMSIG(status))
                              : "ended with status " + std::to_string(WEXITSTATUS(status));
  return MakeError(ErrorCode::kDataLoss, path + ": damaged recording: OpenNI2's file driver " +
                                             how + " opening it (checked in a separate process)");
}

Status CheckDeviceUriOpens(const std::string& uri) {
  std::error_code ec;
  if (uri.empty() || !std::filesystem::is_regular_file(uri, ec)) return Status::Ok();
  return CheckRecordingOpens(uri);
}

}  // namespace hpose::server
