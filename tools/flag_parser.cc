#include "tools/flag_parser.h"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <memory>
#include <sstream>
#include <stdexcept>

#include "core/common/closest_name.h"

namespace hpose::tools {

bool ParsePoseTriple(const std::string& text, Pose2D* pose) {
  double x = 0.0, y = 0.0, deg = 0.0;
  char c1 = 0, c2 = 0, extra = 0;
  std::istringstream in(text);
  if (!(in >> x >> c1 >> y >> c2 >> deg) || c1 != ',' || c2 != ',' || (in >> extra)) return false;
  // Finite, and within what a floor and a heading can be (NaN fails these too).
  if (!(std::abs(x) <= 1e4 && std::abs(y) <= 1e4 && std::abs(deg) <= 3600.0)) return false;
  *pose = Pose2D{x, y, NormalizeAngle(DegToRad(deg))};
  return true;
}

namespace {

bool ParseDouble(const std::string& s, double* out) {
  if (s.empty()) return false;
  char* end = nullptr;
  errno = 0;
  const double v = std::strtod(s.c_str(), &end);
  if (errno != 0 || end != s.c_str() + s.size() || !std::isfinite(v)) return false;
  *out = v;
  return true;
}

bool ParseInt(const std::string& s, int* out) {
  if (s.empty()) return false;
  char* end = nullptr;
  errno = 0;
  const long v = std::strtol(s.c_str(), &end, 10);
  if (errno != 0 || end != s.c_str() + s.size() || v < -2147483647L || v > 2147483647L) {
    return false;
  }
  *out = static_cast<int>(v);
  return true;
}

std::string FormatDouble(double v) {
  std::ostringstream os;
  if (v == std::floor(v) && std::abs(v) < 1e15) {
    os << static_cast<long long>(v);  // whole numbers in full (2147483647, not 2.14748e+09).
    return os.str();
  }
  os << v;
  return os.str();
}

}  // namespace

FlagParser::FlagParser(std::string usage, std::string description)
    : usage_(std::move(usage)), description_(std::move(description)) {}

void FlagParser::AddString(const std::string& name, std::string* out, const std::string& help,
                           const std::string& metavar) {
  flags_.push_back(
      {name, help, metavar, true, false, out->empty() ? "" : *out, [out](const std::string& v) {
         *out = v;
         return true;
       }});
}

void FlagParser::AddStrings(const std::string& name, std::vector<std::string>* out,
                            const std::string& help, const std::string& metavar) {
  auto cleared = std::make_shared<bool>(false);
  flags_.push_back(
      {name, help + " (repeatable)", metavar, true, true, "", [out, cleared](const std::string& v) {
         if (!*cleared) {  // the command line replaces defaults.
           out->clear();
           *cleared = true;
         }
         out->push_back(v);
         return true;
       }});
}

void FlagParser::AddDouble(const std::string& name, double* out, const std::string& help,
                           const std::string& metavar) {
  flags_.push_back({name, help, metavar, true, false, FormatDouble(*out),
                    [out](const std::string& v) { return ParseDouble(v, out); },
                    [out] { return *out; }});
}

void FlagParser::AddInt(const std::string& name, int* out, const std::string& help,
                        const std::string& metavar) {
  flags_.push_back({name, help, metavar, true, false, std::to_string(*out),
                    [out](const std::string& v) { return ParseInt(v, out); },
                    [out] { return static_cast<double>(*out); }});
}

void FlagParser::AddBool(const std::string& name, bool* out, const std::string& help) {
  flags_.push_back({name, help, "", false, false, "", [out](const std::string& v) {
                      if (v.empty() || v == "true" || v == "1") {
                        *out = true;
                      } else if (v == "false" || v == "0") {
                        *out = false;
                      } else {
                        return false;
                      }
                      return true;
                    }});
}

void FlagParser::Within(const std::string& name, double lo, double hi) {
  Flag* flag = Find(name);
  if (flag == nullptr || !flag->number) {
    throw std::logic_error("FlagParser::Within: --" + name + " is not a numeric flag");
  }
  flag->bounded = true;
  flag->lo = lo;
  flag->hi = hi;
}

FlagParser::Flag* FlagParser::Find(const std::string& name) {
  for (Flag& f : flags_) {
    if (f.name == name) return &f;
  }
  return nullptr;
}

bool FlagParser::Seen(const std::string& name) const {
  for (const Flag& f : flags_) {
    if (f.name == name) return f.seen;
  }
  return false;
}

std::string FlagParser::Help() const {
  std::ostringstream os;
  os << "usage: " << usage_ << "\n\n" << description_ << "\n\noptions:\n";
  for (const Flag& f : flags_) {
    std::string lhs = "  --" + f.name + (f.takes_value ? " " + f.metavar : "");
    os << lhs;
    if (lhs.size() < 28) {
      os << std::string(28 - lhs.size(), ' ');
    } else {
      os << "\n" << std::string(28, ' ');
    }
    os << f.help;
    if (!f.default_text.empty()) os << " [default: " << f.default_text << "]";
    os << "\n";
  }
  os << "  --help                    show this help and exit\n";
  if (!epilog_.empty()) os << "\n" << epilog_ << "\n";
  return os.str();
}

FlagParser::Outcome FlagParser::Parse(int argc, char** argv, int first) {
  auto fail = [this](const std::string& msg) {
    std::cerr << "usage: " << usage_ << "\nerror: " << msg << " (see --help)\n";
    return Outcome::kError;
  };
  bool only_positional = false;
  for (int i = first; i < argc; ++i) {
    const std::string arg = argv[i];
    if (only_positional || arg.size() < 2 || arg.compare(0, 2, "--") != 0 || arg == "--") {
      if (arg == "--" && !only_positional) {
        only_positional = true;
        continue;
      }
      if (positional_metavar_.empty()) return fail("unexpected argument '" + arg + "'");
      positional_.push_back(arg);
      continue;
    }
    if (arg == "--help" || arg == "-h") {
      std::cout << Help();
      return Outcome::kHelpShown;
    }
    std::string name = arg.substr(2);
    std::string value;
    bool has_value = false;
    const size_t eq = name.find('=');
    if (eq != std::string::npos) {
      value = name.substr(eq + 1);
      name = name.substr(0, eq);
      has_value = true;
    }
    Flag* flag = Find(name);
    if (flag == nullptr) {
      std::vector<std::string> names;
      for (const Flag& f : flags_) names.push_back(f.name);
      return fail("unknown flag --" + name + DidYouMean(name, names, "--"));
    }
    if (flag->seen && !flag->repeatable) return fail("--" + name + " given twice");
    if (flag->takes_value && !has_value) {
      if (i + 1 >= argc) return fail("--" + name + " needs a value (" + flag->metavar + ")");
      value = argv[++i];
    }
    if (!flag->set(value)) return fail("bad value '" + value + "' for --" + name);
    if (flag->bounded && !(flag->number() >= flag->lo && flag->number() <= flag->hi)) {
      return fail("--" + name + " must be within [" + FormatDouble(flag->lo) + ", " +
                  FormatDouble(flag->hi) + "], got " + value);
    }
    flag->seen = true;
  }
  return Outcome::kOk;
}

}  // namespace hpose::tools
