#include "tools/fixed_text.h"

#include <cstdio>

namespace hpose::tools {

std::string Fixed(double v, int decimals) {
  char buf[64];
  std::snprintf(buf, sizeof(buf), "%.*f", decimals, v);
  return buf;
}

std::string FormatNumber(const char* fmt, double v) {
  char buf[64];
  std::snprintf(buf, sizeof(buf), fmt, v);
  return buf;
}

std::string ApproachText(double distance_m, double in_s) {
  char buf[96];
  if (in_s >= 0.0) {
    std::snprintf(buf, sizeof(buf), ", passes %.0f mm from the robot in %.2f s",
                  distance_m * 1000.0, in_s);
  } else {
    std::snprintf(buf, sizeof(buf), ", passed %.0f mm from the robot %.2f s ago",
                  distance_m * 1000.0, -in_s);
  }
  return buf;
}

}  // namespace hpose::tools
