#include "core/search/humanoid_view.h"

#include "core/search/estimate.h"

namespace hpose {

HumanoidView::Iterator::Iterator(const Detection* at, const Detection* end) : at_(at), end_(end) {
  while (at_ != end_ && !at_->is_humanoid) ++at_;
}

HumanoidView::Iterator& HumanoidView::Iterator::operator++() {
  ++at_;
  while (at_ != end_ && !at_->is_humanoid) ++at_;
  return *this;
}

HumanoidView::Iterator HumanoidView::begin() const {
  const Detection* first = detections_->data();
  return Iterator(first, first + detections_->size());
}

HumanoidView::Iterator HumanoidView::end() const {
  const Detection* last = detections_->data() + detections_->size();
  return Iterator(last, last);
}

std::size_t HumanoidView::size() const {
  return static_cast<std::size_t>(std::distance(begin(), end()));
}

HumanoidView::operator std::vector<Detection>() const { return {begin(), end()}; }

}  // namespace hpose
