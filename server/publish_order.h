#ifndef HPOSE_SERVER_PUBLISH_ORDER_H_
#define HPOSE_SERVER_PUBLISH_ORDER_H_

#include <cstddef>
#include <cstdint>
#include <map>
#include <utility>
#include <vector>

namespace hpose::server {

// Puts the results of frames estimated concurrently (several estimation threads, each on its
// own frame) back into frame order. Every frame gets a ticket when an estimation thread takes
// it from the queue (tickets 0, 1, 2 ... in arrival order); when its estimate is done, Done()
// says which results to publish now:
// - kInOrder: every result, in ticket order; a result waits for the earlier frames still being
//   estimated (recordings replayed as fast as possible: nothing is lost, nothing reordered).
// - kNewestOnly: a result is published at once unless a later frame's result already was; then
//   it is superseded and dropped (live sources: the newest pose matters, never an older one
//   after a newer one).
// With one estimation thread both publish every result at once. Not thread-safe: the caller
// holds its lock around NextTicket() (together with taking the frame) and Done().
template <typename Result>
class PublishOrder {
 public:
  enum class Policy { kInOrder, kNewestOnly };

  explicit PublishOrder(Policy policy) : policy_(policy) {}

  std::uint64_t NextTicket() { return next_ticket_++; }

  // Hands in the result of `ticket`; appends the results to publish now to `publish` (in order)
  // and returns how many results were superseded (0 or 1, kNewestOnly only).
  int Done(std::uint64_t ticket, Result result, std::vector<Result>* publish) {
    if (policy_ == Policy::kNewestOnly) {
      if (ticket < next_to_publish_) return 1;
      next_to_publish_ = ticket + 1;
      publish->push_back(std::move(result));
      return 0;
    }
    waiting_.emplace(ticket, std::move(result));
    for (auto it = waiting_.begin(); it != waiting_.end() && it->first == next_to_publish_;
         it = waiting_.erase(it)) {
      publish->push_back(std::move(it->second));
      ++next_to_publish_;
    }
    return 0;
  }

  // Results held back waiting for an earlier frame (kInOrder).
  std::size_t waiting() const { return waiting_.size(); }

 private:
  const Policy policy_;
  std::uint64_t next_ticket_ = 0;
  std::uint64_t next_to_publish_ = 0;
  std::map<std::uint64_t, Result> waiting_;
};

}  // namespace hpose::server

#endif  // HPOSE_SERVER_PUBLISH_ORDER_H_
