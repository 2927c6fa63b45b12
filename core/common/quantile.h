#ifndef HPOSE_CORE_COMMON_QUANTILE_H_
#define HPOSE_CORE_COMMON_QUANTILE_H_

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

namespace hpose {

// The value at fraction q (0-1) of the values in order, by nearest rank: q = 0.5 the median,
// 1 the largest. 0 for no values.
inline double Quantile(std::vector<double> values, double q) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  const std::size_t rank = static_cast<std::size_t>(std::ceil(q * values.size()));
  return values[std::min(values.size() - 1, rank > 0 ? rank - 1 : 0)];
}

}  // namespace hpose

#endif  // HPOSE_CORE_COMMON_QUANTILE_H_
