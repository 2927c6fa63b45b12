#include "core/io/frame_file_time.h"

#include <cctype>
#include <cstdlib>
#include <ctime>

namespace hpose {

namespace {

bool AllDigits(const std::string& s, size_t pos, size_t n) {
  if (pos + n > s.size()) return false;
  for (size_t i = pos; i < pos + n; ++i) {
    if (!std::isdigit(static_cast<unsigned char>(s[i]))) return false;
  }
  return true;
}

int Number(const std::string& s, size_t pos, size_t n) {
  return std::atoi(s.substr(pos, n).c_str());
}

// Digits after a '.' at `pos` as a fraction of a second (0 when there is none).
double Fraction(const std::string& s, size_t pos) {
  if (pos >= s.size() || s[pos] != '.') return 0.0;
  double scale = 0.1, f = 0.0;
  for (size_t i = pos + 1; i < s.size() && std::isdigit(static_cast<unsigned char>(s[i])); ++i) {
    f += (s[i] - '0') * scale;
    scale *= 0.1;
  }
  return f;
}

std::optional<double> DateTime(const std::string& name) {
  for (size_t t = 8; t + 7 <= name.size(); ++t) {
    if (name[t] != 'T' || !AllDigits(name, t - 8, 8) || !AllDigits(name, t + 1, 6)) continue;
    if (t >= 9 && std::isdigit(static_cast<unsigned char>(name[t - 9]))) continue;
    std::tm tm = {};
    tm.tm_year = Number(name, t - 8, 4) - 1900;
    tm.tm_mon = Number(name, t - 4, 2) - 1;
    tm.tm_mday = Number(name, t - 2, 2);
    tm.tm_hour = Number(name, t + 1, 2);
    tm.tm_min = Number(name, t + 3, 2);
    tm.tm_sec = Number(name, t + 5, 2);
    if (tm.tm_mon < 0 || tm.tm_mon > 11 || tm.tm_mday < 1 || tm.tm_mday > 31 || tm.tm_hour > 23 ||
        tm.tm_min > 59 || tm.tm_sec > 60) {
      continue;
    }
    const std::time_t seconds = timegm(&tm);
    return static_cast<double>(seconds) + Fraction(name, t + 7);
  }
  return std::nullopt;
}

std::optional<double> LeadingSeconds(const std::string& name) {
  size_t i = 0;
  while (i < name.size() && std::isdigit(static_cast<unsigned char>(name[i]))) ++i;
  if (i == 0 || i >= name.size() || name[i] != '.') return std::nullopt;
  size_t j = i + 1;
  while (j < name.size() && std::isdigit(static_cast<unsigned char>(name[j]))) ++j;
  if (j == i + 1) return std::nullopt;  // "12.png": a counter, not seconds.fraction.
  const double seconds = std::strtod(name.substr(0, j).c_str(), nullptr);
  // Up to 1e11 s (the year 5138): longer runs of digits are no clock's (400 of them read as inf).
  if (!(seconds <= 1e11)) return std::nullopt;
  return seconds;
}

}  // namespace

std::optional<double> TimeFromFrameFileName(const std::string& path) {
  const size_t slash = path.find_last_of('/');
  const std::string name = slash == std::string::npos ? path : path.substr(slash + 1);
  if (std::optional<double> t = DateTime(name)) return t;
  return LeadingSeconds(name);
}

}  // namespace hpose
