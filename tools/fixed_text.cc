#include "tools/fixed_text.h"

#include <cstdio>

namespace hpose::tools {

std::string Fixed(double v, int decimals) {
  char buf[64];
  std::snprintf(buf, sizeof(buf), "%.*f", decimals, v);
  return buf;
}

}  // namespace hpose::tools
