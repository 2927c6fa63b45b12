#include "server/descriptor_budget.h"

#include <dirent.h>
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <mutex>

namespace hpose::server {
namespace {

long SoftDescriptorLimit() {
  rlimit limit{};
  if (getrlimit(RLIMIT_NOFILE, &limit) != 0 || limit.rlim_cur == RLIM_INFINITY) return 1 << 20;
  return static_cast<long>(limit.rlim_cur);
}

}  // namespace

int OpenDescriptors() {
  DIR* dir = opendir("/proc/self/fd");
  if (dir == nullptr) return -1;
  int count = 0;
  while (const dirent* entry = readdir(dir)) {
    if (entry->d_name[0] != '.') ++count;
  }
  closedir(dir);
  return count - 1;  // the directory's own descriptor.
}

int ReservedDescriptors() {
  return static_cast<int>(std::min<long>(128, SoftDescriptorLimit() / 4));
}

bool MayAcceptConnection() {
  // Counting /proc/self/fd costs a directory read: it is done at most every 100 ms, and
  // whenever the last count plus the connections admitted since leaves no room.
  static std::mutex mutex;
  static int counted = -1;
  static int admitted_since = 0;
  static std::chrono::steady_clock::time_point counted_at;
  const long limit = SoftDescriptorLimit();
  const int reserve = ReservedDescriptors();
  const auto now = std::chrono::steady_clock::now();
  std::lock_guard<std::mutex> lock(mutex);
  // The connection to accept is one more.
  const auto fits = [&] { return counted >= 0 && counted + admitted_since + 1 + reserve <= limit; };
  if (counted < 0 || now - counted_at > std::chrono::milliseconds(100) || !fits()) {
    counted = OpenDescriptors();
    admitted_since = 0;
    counted_at = now;
  }
  if (!fits()) return false;
  ++admitted_since;
  return true;
}

}  // namespace hpose::server
