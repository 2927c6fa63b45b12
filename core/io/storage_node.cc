#include "core/io/storage_node.h"

#include <charconv>
#include <cmath>
#include <cstdlib>
#include <limits>

namespace hpose {

const StorageNode* StorageNode::Find(std::string_view key) const {
  if (kind != Kind::kMap) return nullptr;
  for (const auto& [name, node] : members) {
    if (name == key) return &node;
  }
  return nullptr;
}

bool StorageNode::AsInt(long long* value) const {
  if (kind != Kind::kScalar || quoted || text.empty()) return false;
  const char* begin = text.data() + (text[0] == '+' ? 1 : 0);
  const char* end = text.data() + text.size();
  long long v = 0;
  const auto [ptr, ec] = std::from_chars(begin, end, v);
  if (ec != std::errc() || ptr != end) return false;
  *value = v;
  return true;
}

bool StorageNode::AsNumber(double* value) const {
  if (kind != Kind::kScalar || quoted || text.empty()) return false;
  std::string_view t = text;
  const bool negative = t[0] == '-';
  if (t[0] == '+' || t[0] == '-') t.remove_prefix(1);
  // OpenCV writes .nan, .inf (any case) for non-finite values.
  auto lower_is = [&t](std::string_view word) {
    if (t.size() != word.size()) return false;
    for (std::size_t i = 0; i < t.size(); ++i) {
      const char c = t[i] >= 'A' && t[i] <= 'Z' ? static_cast<char>(t[i] - 'A' + 'a') : t[i];
      if (c != word[i]) return false;
    }
    return true;
  };
  if (lower_is(".nan")) {
    *value = std::numeric_limits<double>::quiet_NaN();
    return true;
  }
  if (lower_is(".inf")) {
    *value = negative ? -std::numeric_limits<double>::infinity()
                      : std::numeric_limits<double>::infinity();
    return true;
  }
  if (t.empty() || !((t[0] >= '0' && t[0] <= '9') || t[0] == '.')) return false;
  double v = 0;
  const auto [ptr, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
  if (ptr != t.data() + t.size()) return false;
  if (ec == std::errc::result_out_of_range) {
    // Too large or too small for a double: what strtod makes of it (inf or 0).
    v = std::strtod(std::string(t).c_str(), nullptr);
  } else if (ec != std::errc()) {
    return false;
  }
  *value = negative ? -v : v;
  return true;
}

bool StorageNode::IsString() const {
  double unused = 0;
  return kind == Kind::kScalar && (quoted || !AsNumber(&unused));
}

}  // namespace hpose
