#include "core/io/atomic_file.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

#include "core/io/input_file.h"

namespace hpose {
namespace {

// ReadFile reads configuration, sidecars and intrinsics: small text files.
constexpr std::uint64_t kMaxReadFileBytes = std::uint64_t{64} << 20;

std::string ErrnoText() { return std::strerror(errno); }

std::string DirectoryOf(const std::string& path) {
  const size_t slash = path.find_last_of('/');
  if (slash == std::string::npos) return ".";
  if (slash == 0) return "/";
  return path.substr(0, slash);
}

// The start of the names of `path`'s temporary files, without their directory:
// ".BASE.tmp." followed by the writer's process id, a dot and a counter.
std::string TempPrefixFor(const std::string& path) {
  const size_t slash = path.find_last_of('/');
  return "." + (slash == std::string::npos ? path : path.substr(slash + 1)) + ".tmp.";
}

// A name in the same directory as `path` (so rename() stays on one file system) that no other
// writer in this or another process picks at the same time.
std::string TempPathFor(const std::string& path) {
  static std::atomic<unsigned> counter{0};
  const size_t slash = path.find_last_of('/');
  const std::string dir = slash == std::string::npos ? "" : path.substr(0, slash + 1);
  return dir + TempPrefixFor(path) + std::to_string(::getpid()) + "." +
         std::to_string(counter.fetch_add(1));
}

bool AllDigits(const std::string& s) {
  return !s.empty() && s.size() <= 10 && s.find_first_not_of("0123456789") == std::string::npos;
}

// Flushes a file (or directory) to disk; best effort, failures are not fatal for correctness
// of the rename, only for durability across power loss.
void SyncPath(const std::string& path, int flags) {
  const int fd = ::open(path.c_str(), flags | O_CLOEXEC);
  if (fd < 0) return;
  ::fsync(fd);
  ::close(fd);
}

}  // namespace

int RemoveStaleTemporaries(const std::string& path) {
  const std::string prefix = TempPrefixFor(path);
  const std::string dir = DirectoryOf(path);
  int removed = 0;
  std::error_code ec;
  for (std::filesystem::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name.compare(0, prefix.size(), prefix) != 0) continue;
    const std::string rest = name.substr(prefix.size());  // "PID.N"
    const size_t dot = rest.find('.');
    if (dot == std::string::npos || !AllDigits(rest.substr(0, dot)) ||
        !AllDigits(rest.substr(dot + 1))) {
      continue;
    }
    const long long pid = std::stoll(rest.substr(0, dot));
    if (pid <= 0 || pid > std::numeric_limits<pid_t>::max() || pid == ::getpid()) continue;
    // kill(pid, 0) sends nothing: ESRCH says no such process; EPERM one that is running.
    if (::kill(static_cast<pid_t>(pid), 0) == 0 || errno != ESRCH) continue;
    std::error_code remove_ec;
    if (it->is_regular_file(remove_ec) && std::filesystem::remove(it->path(), remove_ec)) {
      ++removed;
    }
  }
  return removed;
}

Status WriteAtomically(const std::string& path,
                       const std::function<Status(const std::string& temp_path)>& write_temp) {
  const Status destination = CheckOutputPath(path);
  if (!destination.ok()) return destination;
  struct stat existing;
  if (::stat(path.c_str(), &existing) == 0 && !S_ISREG(existing.st_mode)) {
    // A device or FIFO (/dev/stdout, /dev/null, a pipe) is written in place: renaming over it
    // would replace the device node with a regular file.
    return write_temp(path);
  }
  const std::string temp = TempPathFor(path);
  Status written = write_temp(temp);
  if (!written.ok()) {
    std::remove(temp.c_str());
    return written;
  }
  struct stat st;
  if (::stat(temp.c_str(), &st) != 0) {
    return MakeError(ErrorCode::kInternal,
                     path + ": the writer reported success but produced no temporary file");
  }
  SyncPath(temp, O_RDONLY);
  if (std::rename(temp.c_str(), path.c_str()) != 0) {
    const std::string reason = ErrnoText();
    std::remove(temp.c_str());
    return MakeError(ErrorCode::kInternal, path + ": cannot replace the file: " + reason);
  }
  SyncPath(DirectoryOf(path), O_RDONLY | O_DIRECTORY);
  return Status::Ok();
}

Status CheckOutputPath(const std::string& path) {
  if (path.empty()) return MakeError(ErrorCode::kInvalidArgument, "cannot write: empty path");
  if (path.back() == '/') {
    return MakeError(ErrorCode::kInvalidArgument, path + ": is a directory name, not a file");
  }
  struct stat st;
  if (::stat(path.c_str(), &st) == 0 && S_ISDIR(st.st_mode)) {
    return MakeError(ErrorCode::kInvalidArgument, path + ": is a directory, not a file");
  }
  const std::string dir = DirectoryOf(path);
  if (::stat(dir.c_str(), &st) != 0) {
    return MakeError(ErrorCode::kNotFound,
                     path + ": cannot write there: the directory '" + dir + "' does not exist");
  }
  if (!S_ISDIR(st.st_mode)) {
    return MakeError(ErrorCode::kInvalidArgument,
                     path + ": cannot write there: '" + dir + "' is not a directory");
  }
  if (::access(dir.c_str(), W_OK) != 0) {
    return MakeError(ErrorCode::kInvalidArgument,
                     path + ": cannot write there: the directory '" + dir + "' is not writable");
  }
  return Status::Ok();
}

Status WriteFileAtomically(const std::string& path, const std::string& contents) {
  return WriteAtomically(path, [&](const std::string& temp) -> Status {
    std::ofstream out(temp, std::ios::binary | std::ios::trunc);
    if (!out) {
      return MakeError(ErrorCode::kInternal,
                       path + ": cannot create a temporary file (" + temp + "): " + ErrnoText());
    }
    out.write(contents.data(), static_cast<std::streamsize>(contents.size()));
    out.close();
    if (!out) return MakeError(ErrorCode::kInternal, path + ": write failed: " + ErrnoText());
    return Status::Ok();
  });
}

Result<std::string> ReadFile(const std::string& path) {
  Result<std::uint64_t> size = CheckInputFile(path, kMaxReadFileBytes);
  if (!size.ok()) return size.error();
  return ReadFileHead(path, static_cast<std::size_t>(*size));
}

}  // namespace hpose
