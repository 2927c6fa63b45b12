#include "core/io/input_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace hpose {
namespace {

const char* KindOf(mode_t mode) {
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISFIFO(mode)) return "a FIFO (named pipe)";
  if (S_ISSOCK(mode)) return "a socket";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  return "not a regular file";
}

}  // namespace

Result<std::uint64_t> CheckInputFile(const std::string& path, std::uint64_t max_bytes) {
  struct stat st;
  if (::stat(path.c_str(), &st) != 0) {
    if (errno == ENOENT || errno == ENOTDIR) {
      return MakeError(ErrorCode::kNotFound, path + ": no such file");
    }
    return MakeError(ErrorCode::kNotFound, path + ": cannot stat: " + std::strerror(errno));
  }
  if (!S_ISREG(st.st_mode)) {
    return MakeError(ErrorCode::kInvalidArgument,
                     path + ": is " + KindOf(st.st_mode) + "; only regular files are read");
  }
  const auto size = static_cast<std::uint64_t>(st.st_size);
  if (size > max_bytes) {
    return MakeError(ErrorCode::kOutOfRange, path + ": the file has " + std::to_string(size) +
                                                 " bytes, more than the " +
                                                 std::to_string(max_bytes) + " read at most");
  }
  return size;
}

Result<std::string> ReadFileHead(const std::string& path, std::size_t max_bytes) {
  // O_NONBLOCK: should the path have been swapped for a FIFO since it was checked, the open
  // does not wait for a writer.
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
  if (fd < 0)
    return MakeError(ErrorCode::kNotFound, path + ": cannot open: " + std::strerror(errno));
  struct stat st;
  if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
    ::close(fd);
    return MakeError(ErrorCode::kInvalidArgument, path + ": is not a regular file");
  }
  std::string head(max_bytes, '\0');
  std::size_t got = 0;
  while (got < max_bytes) {
    const ssize_t n = ::read(fd, head.data() + got, max_bytes - got);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      const std::string reason = std::strerror(errno);
      ::close(fd);
      return MakeError(ErrorCode::kDataLoss, path + ": read failed: " + reason);
    }
    if (n == 0) break;
    got += static_cast<std::size_t>(n);
  }
  ::close(fd);
  head.resize(got);
  return head;
}

Error FileDataLoss(const std::string& path, const std::string& what) {
  return MakeError(ErrorCode::kDataLoss, path + ": " + what);
}

}  // namespace hpose
