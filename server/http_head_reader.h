#ifndef HPOSE_SERVER_HTTP_HEAD_READER_H_
#define HPOSE_SERVER_HTTP_HEAD_READER_H_

#include <chrono>
#include <cstddef>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include "core/common/status.h"

namespace hpose::server {

// What a connection sent of its request head before it was handed on.
struct HttpHead {
  int fd = -1;
  std::string bytes;  // everything received, at most max_bytes + 1 of it.
  // Where the head ends in `bytes` (after its blank line); npos when no whole head came.
  std::size_t end = std::string_view::npos;
  bool closed = false;     // the peer closed (or the connection failed) before a whole head.
  bool too_large = false;  // more than max_bytes came without a whole head.
  bool timed_out = false;  // the timeout passed first.
};

// Reads the request heads of many connections at once, on one thread that waits on all of them
// (poll): a connection that stalls or trickles costs a descriptor and a buffer here, not a
// worker thread, so it cannot hold up the others. Each connection added is handed to `ready`
// exactly once, on the reader's thread: when its head is whole, or it closed, sent too much, or
// the timeout (from Add) passed; at Stop, those still being read are handed on as closed. The
// receiver owns the descriptor from then on.
class HttpHeadReader {
 public:
  using Ready = std::function<void(HttpHead)>;

  // Starts the reading thread. kUnavailable when it cannot (no pipe to wake it).
  static Result<std::unique_ptr<HttpHeadReader>> Start(std::chrono::milliseconds timeout,
                                                       std::size_t max_bytes, Ready ready);
  ~HttpHeadReader();  // Stop.
  HttpHeadReader(const HttpHeadReader&) = delete;
  HttpHeadReader& operator=(const HttpHeadReader&) = delete;

  // Starts reading the head of connection `fd`. Any thread. After Stop, `fd` is handed on as
  // closed at once.
  void Add(int fd);
  // Hands on every connection still being read (as closed) and joins the thread. Idempotent.
  void Stop();
  // Connections being read now.
  int reading() const;

 private:
  struct Pending {
    HttpHead head;
    std::chrono::steady_clock::time_point deadline;
  };
  HttpHeadReader(std::chrono::milliseconds timeout, std::size_t max_bytes, Ready ready);
  void Loop();
  // Reads what `p` has; true when it is to be handed on.
  bool Read(Pending* p) const;
  void Wake();

  const std::chrono::milliseconds timeout_;
  const std::size_t max_bytes_;
  const Ready ready_;
  int wake_read_ = -1;  // a pipe: a byte written makes the thread look at added_ and stopping_.
  int wake_write_ = -1;
  mutable std::mutex mutex_;
  std::vector<int> added_;  // connections Add()ed and not yet taken up by the thread.
  int reading_ = 0;
  bool stopping_ = false;
  std::thread thread_;
};

}  // namespace hpose::server

#endif  // HPOSE_SERVER_HTTP_HEAD_READER_H_
