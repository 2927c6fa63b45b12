#ifndef HPOSE_SERVER_STREAM_LIMITER_H_
#define HPOSE_SERVER_STREAM_LIMITER_H_

#include <cstdint>
#include <map>
#include <mutex>
#include <string>

namespace hpose::server {

// The client a call comes from, for per-client limits: its bearer token when the daemon checks
// tokens (one credential = one client, whatever addresses it connects from), else the peer's
// network address without the port (all connections of one host count together). `peer` is
// gRPC's peer string ("ipv4:10.0.0.5:40312", "ipv6:[::1]:40312", "unix:/path").
std::string ClientKey(bool has_token, const std::string& token, const std::string& peer);
// The address part of a gRPC peer string ("10.0.0.5", "::1"); other forms unchanged.
std::string PeerHost(const std::string& peer);

// Bounds the StreamPoses calls each client holds open at once, so that one client cannot take
// every server thread and connection buffer while others wait. Thread-safe.
class StreamLimiter {
 public:
  explicit StreamLimiter(int max_per_client);  // >= 1.

  // Held while a stream runs; gives its place back when destroyed.
  class Slot {
   public:
    Slot(Slot&& other) noexcept : owner_(other.owner_), key_(std::move(other.key_)) {
      other.owner_ = nullptr;
    }
    Slot(const Slot&) = delete;
    Slot& operator=(const Slot&) = delete;
    Slot& operator=(Slot&&) = delete;
    ~Slot();
    bool admitted() const { return owner_ != nullptr; }

   private:
    friend class StreamLimiter;
    Slot(StreamLimiter* owner, std::string key) : owner_(owner), key_(std::move(key)) {}
    StreamLimiter* owner_;
    std::string key_;
  };

  // A place for one more stream of `client`; not admitted() when it already holds
  // max_per_client() (the caller answers RESOURCE_EXHAUSTED).
  Slot TryOpen(const std::string& client);

  int max_per_client() const { return max_per_client_; }
  int open(const std::string& client) const;  // streams `client` holds now.
  std::uint64_t rejected() const;             // streams refused so far.

 private:
  void Release(const std::string& client);

  const int max_per_client_;
  mutable std::mutex mu_;
  std::map<std::string, int> open_;  // clients with at least one stream.
  std::uint64_t rejected_ = 0;
};

}  // namespace hpose::server

#endif  // HPOSE_SERVER_STREAM_LIMITER_H_
