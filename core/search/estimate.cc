#include "core/search/estimate.h"

namespace hpose {

std::vector<Detection> Estimate::Humanoids() const {
  std::vector<Detection> out;
  for (const Detection& d : detections) {
    if (d.is_humanoid) out.push_back(d);
  }
  return out;
}

}  // namespace hpose
