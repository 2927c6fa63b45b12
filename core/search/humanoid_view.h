#ifndef HPOSE_CORE_SEARCH_HUMANOID_VIEW_H_
#define HPOSE_CORE_SEARCH_HUMANOID_VIEW_H_

#include <cstddef>
#include <iterator>
#include <vector>

namespace hpose {

struct Detection;

// The detections of a list that passed as humanoids (Detection::is_humanoid), in the list's
// order, read in place: no copy is made, so a reference or pointer to one of them stays valid as
// long as the list itself (an Estimate's `detections`) does. Copy it into a
// std::vector<Detection> to keep the humanoids past the list.
class HumanoidView {
 public:
  class Iterator {
   public:
    using iterator_category = std::forward_iterator_tag;
    using value_type = Detection;
    using difference_type = std::ptrdiff_t;
    using pointer = const Detection*;
    using reference = const Detection&;

    Iterator() = default;
    reference operator*() const { return *at_; }
    pointer operator->() const { return at_; }
    Iterator& operator++();
    Iterator operator++(int) {
      Iterator before = *this;
      ++*this;
      return before;
    }
    bool operator==(const Iterator& o) const { return at_ == o.at_; }
    bool operator!=(const Iterator& o) const { return at_ != o.at_; }

   private:
    friend class HumanoidView;
    Iterator(const Detection* at, const Detection* end);  // `at`: the first humanoid from it.
    const Detection* at_ = nullptr;
    const Detection* end_ = nullptr;
  };

  explicit HumanoidView(const std::vector<Detection>& detections) : detections_(&detections) {}

  Iterator begin() const;
  Iterator end() const;
  bool empty() const { return begin() == end(); }
  std::size_t size() const;
  const Detection& front() const { return *begin(); }  // the first humanoid; not when empty().
  // A copy, for keeping the humanoids past the list they were read from.
  operator std::vector<Detection>() const;  // NOLINT(google-explicit-constructor)

 private:
  const std::vector<Detection>* detections_;
};

}  // namespace hpose

#endif  // HPOSE_CORE_SEARCH_HUMANOID_VIEW_H_
