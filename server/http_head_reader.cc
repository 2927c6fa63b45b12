#include "server/http_head_reader.h"

#include <fcntl.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <utility>

#include "server/http_request_parser.h"

namespace hpose::server {
namespace {

using Clock = std::chrono::steady_clock;

}  // namespace

Result<std::unique_ptr<HttpHeadReader>> HttpHeadReader::Start(std::chrono::milliseconds timeout,
                                                              std::size_t max_bytes, Ready ready) {
  std::unique_ptr<HttpHeadReader> reader(new HttpHeadReader(timeout, max_bytes, std::move(ready)));
  int wake[2];
  if (pipe2(wake, O_CLOEXEC | O_NONBLOCK) != 0) {
    return MakeError(ErrorCode::kUnavailable, std::string("pipe: ") + std::strerror(errno));
  }
  reader->wake_read_ = wake[0];
  reader->wake_write_ = wake[1];
  reader->thread_ = std::thread([r = reader.get()] { r->Loop(); });
  return reader;
}

HttpHeadReader::HttpHeadReader(std::chrono::milliseconds timeout, std::size_t max_bytes,
                               Ready ready)
    : timeout_(timeout), max_bytes_(max_bytes), ready_(std::move(ready)) {}

HttpHeadReader::~HttpHeadReader() {
  Stop();
  if (wake_read_ >= 0) close(wake_read_);
  if (wake_write_ >= 0) close(wake_write_);
}

void HttpHeadReader::Add(int fd) {
  bool stopped = false;
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    stopped = stopping_;
    if (!stopped) {
      added_.push_back(fd);
      ++reading_;
    }
  }
  if (stopped) {
    HttpHead head;
    head.fd = fd;
    head.closed = true;
    ready_(std::move(head));
    return;
  }
  Wake();
}

void HttpHeadReader::Stop() {
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  Wake();
  if (thread_.joinable()) thread_.join();
}

int HttpHeadReader::reading() const {
  const std::lock_guard<std::mutex> lock(mutex_);
  return reading_;
}

void HttpHeadReader::Wake() {
  const char byte = 'x';
  [[maybe_unused]] const ssize_t n = write(wake_write_, &byte, 1);  // full: awake already.
}

bool HttpHeadReader::Read(Pending* p) const {
  HttpHead& head = p->head;
  char chunk[4096];
  while (true) {
    const std::size_t want = std::min(sizeof(chunk), max_bytes_ + 1 - head.bytes.size());
    const ssize_t n = recv(head.fd, chunk, want, MSG_DONTWAIT);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) return false;  // more to come.
    if (n <= 0) {
      head.closed = true;
      return true;
    }
    // A blank line that ends in the new bytes starts at most three bytes before them.
    const std::size_t from = head.bytes.size() > 3 ? head.bytes.size() - 3 : 0;
    head.bytes.append(chunk, static_cast<std::size_t>(n));
    const std::size_t end = FindHttpHeadEnd(std::string_view(head.bytes).substr(from));
    if (end != std::string_view::npos) {
      head.end = from + end;
      return true;
    }
    if (head.bytes.size() > max_bytes_) {
      head.too_large = true;
      return true;
    }
  }
}

void HttpHeadReader::Loop() {
  std::vector<Pending> pending;
  std::vector<pollfd> polled;
  while (true) {
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      if (stopping_) break;
      const Clock::time_point deadline = Clock::now() + timeout_;
      for (int fd : added_) {
        Pending p;
        p.head.fd = fd;
        p.deadline = deadline;
        pending.push_back(std::move(p));
      }
      added_.clear();
    }
    polled.clear();
    polled.push_back({wake_read_, POLLIN, 0});
    Clock::time_point first_deadline = Clock::time_point::max();
    for (const Pending& p : pending) {
      polled.push_back({p.head.fd, POLLIN, 0});
      first_deadline = std::min(first_deadline, p.deadline);
    }
    int wait_ms = -1;
    if (!pending.empty()) {
      const auto left =
          std::chrono::ceil<std::chrono::milliseconds>(first_deadline - Clock::now()).count();
      wait_ms = static_cast<int>(std::clamp<decltype(left)>(left, 0, 60 * 1000));
    }
    if (poll(polled.data(), polled.size(), wait_ms) < 0 && errno != EINTR) {
      // Cannot happen with valid descriptors; wait rather than spin, and look again.
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
      continue;
    }
    if (polled.front().revents != 0) {
      char drained[64];
      while (read(wake_read_, drained, sizeof(drained)) > 0) {
      }
    }
    // Hand on what is done (counted out first), keep the rest in order.
    const Clock::time_point now = Clock::now();
    std::vector<HttpHead> done;
    std::size_t kept = 0;
    for (std::size_t i = 0; i < pending.size(); ++i) {
      Pending& p = pending[i];
      bool finished = polled[i + 1].revents != 0 && Read(&p);
      if (!finished && now >= p.deadline) {
        p.head.timed_out = true;
        finished = true;
      }
      if (finished) {
        done.push_back(std::move(p.head));
      } else {
        if (kept != i) pending[kept] = std::move(p);
        ++kept;
      }
    }
    pending.resize(kept);
    if (!done.empty()) {
      {
        const std::lock_guard<std::mutex> lock(mutex_);
        reading_ -= static_cast<int>(done.size());
      }
      for (HttpHead& head : done) ready_(std::move(head));
    }
  }
  // Stopping: every connection still being read is handed on, closed.
  std::vector<int> added;
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    added.swap(added_);
    reading_ = 0;
  }
  for (Pending& p : pending) added.push_back(p.head.fd);
  for (int fd : added) {
    HttpHead head;
    head.fd = fd;
    head.closed = true;
    ready_(std::move(head));
  }
}

}  // namespace hpose::server
