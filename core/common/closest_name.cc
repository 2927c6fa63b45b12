#include "core/common/closest_name.h"

#include <algorithm>
#include <cstddef>

namespace hpose {
namespace {

// Edits from `a` to `b`: insertions, deletions, substitutions and transpositions of adjacent
// letters, no letter edited twice (the optimal string alignment distance).
std::size_t EditDistance(const std::string& a, const std::string& b) {
  const std::size_t n = a.size();
  const std::size_t m = b.size();
  // Three rows of the table: i - 2, i - 1 and i.
  std::vector<std::size_t> before(m + 1), previous(m + 1), current(m + 1);
  for (std::size_t j = 0; j <= m; ++j) previous[j] = j;
  for (std::size_t i = 1; i <= n; ++i) {
    current[0] = i;
    for (std::size_t j = 1; j <= m; ++j) {
      const std::size_t changed = a[i - 1] == b[j - 1] ? 0 : 1;
      current[j] = std::min({previous[j] + 1, current[j - 1] + 1, previous[j - 1] + changed});
      if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1]) {
        current[j] = std::min(current[j], before[j - 2] + 1);
      }
    }
    std::swap(before, previous);
    std::swap(previous, current);
  }
  return previous[m];
}

}  // namespace

std::string ClosestName(const std::string& typed, const std::vector<std::string>& names) {
  std::string best;
  std::size_t best_distance = 0;
  for (const std::string& name : names) {
    if (name == typed) return "";
    const std::size_t limit = std::max<std::size_t>(1, name.size() / 3);
    const std::size_t distance = EditDistance(typed, name);
    if (distance > limit) continue;
    if (best.empty() || distance < best_distance) {
      best = name;
      best_distance = distance;
    }
  }
  return best;
}

std::string DidYouMean(const std::string& typed, const std::vector<std::string>& names,
                       const std::string& prefix) {
  const std::string name = ClosestName(typed, names);
  return name.empty() ? "" : " (did you mean '" + prefix + name + "'?)";
}

}  // namespace hpose
