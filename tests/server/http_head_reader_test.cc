#include "server/http_head_reader.h"

#include <sys/socket.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <chrono>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <set>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include "server/http_request_parser.h"

namespace hpose::server {
namespace {

using std::chrono::milliseconds;

// The heads a reader handed on, and a way to wait for them.
class Received {
 public:
  HttpHeadReader::Ready Callback() {
    return [this](HttpHead head) {
      const std::lock_guard<std::mutex> lock(mutex_);
      heads_.push_back(std::move(head));
      changed_.notify_all();
    };
  }
  // Waits up to `wait` for `n` heads; all received so far.
  std::vector<HttpHead> WaitFor(std::size_t n, milliseconds wait = milliseconds(10000)) {
    std::unique_lock<std::mutex> lock(mutex_);
    changed_.wait_for(lock, wait, [&] { return heads_.size() >= n; });
    return heads_;
  }

 private:
  std::mutex mutex_;
  std::condition_variable changed_;
  std::vector<HttpHead> heads_;
};

// A connected pair of stream sockets: [0] the client's end, [1] the server's.
struct Connection {
  int fds[2] = {-1, -1};
  Connection() { EXPECT_EQ(socketpair(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0, fds), 0); }
  ~Connection() { CloseClient(); }
  void Send(std::string_view bytes) const {
    EXPECT_EQ(send(fds[0], bytes.data(), bytes.size(), MSG_NOSIGNAL),
              static_cast<ssize_t>(bytes.size()));
  }
  void CloseClient() {
    if (fds[0] >= 0) close(fds[0]);
    fds[0] = -1;
  }
  int server() const { return fds[1]; }
};

std::unique_ptr<HttpHeadReader> StartReader(milliseconds timeout, std::size_t max_bytes,
                                            Received* received) {
  Result<std::unique_ptr<HttpHeadReader>> reader =
      HttpHeadReader::Start(timeout, max_bytes, received->Callback());
  EXPECT_TRUE(reader.ok());
  return std::move(*reader);
}

TEST(HttpHeadReaderTest, AHeadSentInPiecesComesOutWholeWithWhatFollows) {
  Received received;
  std::unique_ptr<HttpHeadReader> reader = StartReader(milliseconds(10000), 16384, &received);
  Connection c;
  c.Send("GET /healthz HTTP/1.1\r\nHo");
  reader->Add(c.server());
  c.Send("st: x\r\n\r");
  // Not yet whole: nothing handed on.
  EXPECT_TRUE(received.WaitFor(1, milliseconds(100)).empty());
  EXPECT_EQ(reader->reading(), 1);
  c.Send("\nBODY");
  const std::vector<HttpHead> heads = received.WaitFor(1);
  ASSERT_EQ(heads.size(), 1u);
  const HttpHead& head = heads[0];
  EXPECT_EQ(head.fd, c.server());
  const std::string whole = "GET /healthz HTTP/1.1\r\nHost: x\r\n\r\n";
  EXPECT_EQ(head.end, whole.size());
  EXPECT_EQ(head.bytes.substr(0, head.end), whole);
  EXPECT_FALSE(head.closed || head.too_large || head.timed_out);
  EXPECT_EQ(reader->reading(), 0);
  close(head.fd);
}

TEST(HttpHeadReaderTest, ByteByByteTheHeadEndsWhereTheParserSays) {
  // The end is looked for in each read's new bytes and the three before them: a blank line
  // split over reads at any byte is found, at the place a search of the whole finds it.
  Received received;
  std::unique_ptr<HttpHeadReader> reader = StartReader(milliseconds(10000), 16384, &received);
  const std::vector<std::string> heads = {"GET / HTTP/1.1\r\nHost: x\r\n\r\nBODY",
                                          "GET / HTTP/1.0\n\nrest", "GET /a HTTP/1.1\r\n\r\n"};
  std::vector<std::unique_ptr<Connection>> connections;
  for (std::size_t k = 0; k < heads.size(); ++k) {
    connections.push_back(std::make_unique<Connection>());
    reader->Add(connections.back()->server());
  }
  for (std::size_t i = 0; i < 40; ++i) {
    for (std::size_t k = 0; k < heads.size(); ++k) {
      if (i < heads[k].size()) connections[k]->Send(heads[k].substr(i, 1));
    }
    std::this_thread::sleep_for(milliseconds(1));  // most bytes in reads of their own.
  }
  const std::vector<HttpHead> out = received.WaitFor(heads.size());
  ASSERT_EQ(out.size(), heads.size());
  for (const HttpHead& head : out) {
    std::size_t k = 0;
    while (k < connections.size() && connections[k]->server() != head.fd) ++k;
    ASSERT_LT(k, heads.size());
    EXPECT_EQ(head.end, FindHttpHeadEnd(heads[k])) << heads[k];
    EXPECT_EQ(head.bytes.substr(0, head.end), heads[k].substr(0, head.end));
    close(head.fd);
  }
}

TEST(HttpHeadReaderTest, StalledConnectionsDoNotHoldUpAWholeHead) {
  // Three hundred connections that never finish their head: a whole one behind them comes out
  // while they are still being read (a worker per connection answered it after the timeout).
  Received received;
  std::unique_ptr<HttpHeadReader> reader = StartReader(milliseconds(60000), 16384, &received);
  std::vector<std::unique_ptr<Connection>> stalled;
  for (int i = 0; i < 300; ++i) {
    stalled.push_back(std::make_unique<Connection>());
    stalled.back()->Send("GET / HTTP/1.1\r\n");
    reader->Add(stalled.back()->server());
  }
  Connection whole;
  whole.Send("GET /healthz HTTP/1.1\r\n\r\n");
  reader->Add(whole.server());
  std::vector<HttpHead> heads = received.WaitFor(1);
  ASSERT_EQ(heads.size(), 1u);
  EXPECT_EQ(heads[0].fd, whole.server());
  EXPECT_NE(heads[0].end, std::string_view::npos);
  EXPECT_EQ(reader->reading(), 300);

  // Stopping hands every one of them on, once, as closed.
  reader->Stop();
  heads = received.WaitFor(301);
  ASSERT_EQ(heads.size(), 301u);
  std::set<int> fds;
  for (std::size_t i = 1; i < heads.size(); ++i) {
    EXPECT_TRUE(heads[i].closed);
    EXPECT_EQ(heads[i].end, std::string_view::npos);
    fds.insert(heads[i].fd);
  }
  EXPECT_EQ(fds.size(), 300u);
  for (const auto& c : stalled) EXPECT_EQ(fds.count(c->server()), 1u);
  EXPECT_EQ(reader->reading(), 0);
  for (const HttpHead& h : heads) close(h.fd);

  // A connection added after Stop comes back at once, closed.
  Connection late;
  reader->Add(late.server());
  heads = received.WaitFor(302, milliseconds(0));
  ASSERT_EQ(heads.size(), 302u);
  EXPECT_EQ(heads.back().fd, late.server());
  EXPECT_TRUE(heads.back().closed);
  close(late.server());
}

TEST(HttpHeadReaderTest, TimeoutTooLargeAndClosedEachEndTheRead) {
  Received received;
  std::unique_ptr<HttpHeadReader> reader = StartReader(milliseconds(300), 100, &received);
  Connection partial, silent, large, gone;
  partial.Send("GET / HT");
  large.Send(std::string(250, 'a'));
  gone.Send("GET / HTTP/1.1\r\n");
  gone.CloseClient();
  const auto start = std::chrono::steady_clock::now();
  for (const Connection* c : {&partial, &silent, &large, &gone}) reader->Add(c->server());
  const std::vector<HttpHead> heads = received.WaitFor(4);
  ASSERT_EQ(heads.size(), 4u);
  for (const HttpHead& head : heads) {
    EXPECT_EQ(head.end, std::string_view::npos);
    if (head.fd == partial.server()) {
      EXPECT_TRUE(head.timed_out);
      EXPECT_EQ(head.bytes, "GET / HT");
    } else if (head.fd == silent.server()) {
      EXPECT_TRUE(head.timed_out);
      EXPECT_TRUE(head.bytes.empty());
    } else if (head.fd == large.server()) {
      EXPECT_TRUE(head.too_large);
      EXPECT_FALSE(head.timed_out);
      EXPECT_EQ(head.bytes, std::string(101, 'a'));  // one past the limit, no more.
    } else {
      EXPECT_EQ(head.fd, gone.server());
      EXPECT_TRUE(head.closed);
      EXPECT_FALSE(head.timed_out);
      EXPECT_EQ(head.bytes, "GET / HTTP/1.1\r\n");
    }
    close(head.fd);
  }
  // The timed-out ones waited for the timeout.
  EXPECT_GE(std::chrono::steady_clock::now() - start, milliseconds(300));
}

}  // namespace
}  // namespace hpose::server
