#ifndef HPOSE_CORE_COMMON_QUANTILE_H_
#define HPOSE_CORE_COMMON_QUANTILE_H_

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

namespace hpose {

// The value at fraction q (0-1) of `sorted` (in ascending order), by nearest rank: q = 0.5 the
// median, 1 the largest. 0 for no values.
inline double QuantileOfSorted(const std::vector<double>& sorted, double q) {
  if (sorted.empty()) return 0.0;
  const std::size_t rank = static_cast<std::size_t>(std::ceil(q * sorted.size()));
  return sorted[std::min(sorted.size() - 1, rank > 0 ? rank - 1 : 0)];
}

// The same of values in any order.
inline double Quantile(std::vector<double> values, double q) {
  std::sort(values.begin(), values.end());
  return QuantileOfSorted(values, q);
}

}  // namespace hpose

#endif  // HPOSE_CORE_COMMON_QUANTILE_H_
