#include "server/stream_limiter.h"

#include <cassert>

namespace hpose::server {

std::string PeerHost(const std::string& peer) {
  const bool v4 = peer.rfind("ipv4:", 0) == 0;
  const bool v6 = peer.rfind("ipv6:", 0) == 0;
  if (!v4 && !v6) return peer;
  std::string host = peer.substr(5);
  const size_t colon = host.rfind(':');
  if (colon != std::string::npos) host.resize(colon);  // the port.
  if (v6 && host.size() >= 2 && host.front() == '[' && host.back() == ']') {
    host = host.substr(1, host.size() - 2);
  }
  // An IPv4 client reaching a dual-stack socket is the same host as over IPv4.
  const std::string mapped = "::ffff:";
  if (v6 && host.rfind(mapped, 0) == 0 && host.find('.') != std::string::npos) {
    host = host.substr(mapped.size());
  }
  return host;
}

std::string ClientKey(bool has_token, const std::string& token, const std::string& peer) {
  // The prefixes keep a token from ever equalling an address.
  return has_token ? "token " + token : "address " + PeerHost(peer);
}

StreamLimiter::StreamLimiter(int max_per_client) : max_per_client_(max_per_client) {
  assert(max_per_client >= 1);
}

StreamLimiter::Slot::~Slot() {
  if (owner_ != nullptr) owner_->Release(key_);
}

StreamLimiter::Slot StreamLimiter::TryOpen(const std::string& client) {
  std::lock_guard<std::mutex> lock(mu_);
  int& n = open_[client];
  if (n >= max_per_client_) {
    ++rejected_;
    return Slot(nullptr, "");
  }
  ++n;
  return Slot(this, client);
}

int StreamLimiter::open(const std::string& client) const {
  std::lock_guard<std::mutex> lock(mu_);
  const auto it = open_.find(client);
  return it == open_.end() ? 0 : it->second;
}

std::uint64_t StreamLimiter::rejected() const {
  std::lock_guard<std::mutex> lock(mu_);
  return rejected_;
}

void StreamLimiter::Release(const std::string& client) {
  std::lock_guard<std::mutex> lock(mu_);
  const auto it = open_.find(client);
  assert(it != open_.end() && it->second > 0);
  if (--it->second == 0) open_.erase(it);  // the map holds only clients with open streams.
}

}  // namespace hpose::server
