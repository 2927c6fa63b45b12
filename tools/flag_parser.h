#ifndef HPOSE_TOOLS_FLAG_PARSER_H_
#define HPOSE_TOOLS_FLAG_PARSER_H_

#include <functional>
#include <string>
#include <vector>

#include "core/common/pose2d.h"

namespace hpose::tools {

// "X,Y,THETA_DEG" (metres, degrees) -> a pose (metres, radians); false unless three finite
// numbers, X and Y within 10 km and THETA_DEG within ten turns.
bool ParsePoseTriple(const std::string& text, Pose2D* pose);

// A small GNU-style flag parser shared by every command: `--name value`, `--name=value`,
// boolean `--name`, repeatable flags, positional arguments, and a generated --help.
class FlagParser {
 public:
  enum class Outcome { kOk, kHelpShown, kError };

  // `usage` is the synopsis line, e.g. "hpose estimate --depth FRAME.png --intrinsics CAM.json".
  // `description` is a paragraph printed under it by --help.
  FlagParser(std::string usage, std::string description);

  void AddString(const std::string& name, std::string* out, const std::string& help,
                 const std::string& metavar = "VALUE");
  void AddStrings(const std::string& name, std::vector<std::string>* out, const std::string& help,
                  const std::string& metavar = "VALUE");  // repeatable
  void AddDouble(const std::string& name, double* out, const std::string& help,
                 const std::string& metavar = "NUM");
  void AddInt(const std::string& name, int* out, const std::string& help,
              const std::string& metavar = "INT");
  void AddBool(const std::string& name, bool* out, const std::string& help);
  // A value of the numeric flag `name` (added before) outside [lo, hi] is a usage error that
  // names the flag, the range and the value given (say the range in the flag's help).
  void Within(const std::string& name, double lo, double hi);
  // Text appended after the flag list in --help (examples, exit statuses).
  void SetEpilog(std::string epilog) { epilog_ = std::move(epilog); }
  // Allow positional arguments (otherwise they are an error).
  void AllowPositional(std::string metavar) { positional_metavar_ = std::move(metavar); }

  // Parses argv[first..argc). On --help prints help to stdout; on an error prints
  // "<usage>\nerror: ..." to stderr. Defaults already in the outputs are kept when a flag is
  // absent.
  Outcome Parse(int argc, char** argv, int first = 1);

  // Parse() for a command's entry point: -1 to go on, else the status to exit with (0 after
  // --help, 2 after a usage error, already reported).
  int ParseOrExitCode(int argc, char** argv, int first = 1) {
    switch (Parse(argc, argv, first)) {
      case Outcome::kHelpShown:
        return 0;
      case Outcome::kError:
        return 2;
      case Outcome::kOk:
        break;
    }
    return -1;
  }

  const std::vector<std::string>& positional() const { return positional_; }
  // True when the named flag appeared on the command line.
  bool Seen(const std::string& name) const;
  std::string Help() const;

 private:
  struct Flag {
    std::string name;
    std::string help;
    std::string metavar;
    bool takes_value = true;
    bool repeatable = false;
    std::string default_text;
    std::function<bool(const std::string&)> set;  // returns false on a bad value.
    std::function<double()> number;               // a numeric flag's value once set.
    bool bounded = false;
    double lo = 0.0, hi = 0.0;
    bool seen = false;
  };
  Flag* Find(const std::string& name);

  std::string usage_;
  std::string description_;
  std::string epilog_;
  std::string positional_metavar_;
  std::vector<Flag> flags_;
  std::vector<std::string> positional_;
};

}  // namespace hpose::tools

#endif  // HPOSE_TOOLS_FLAG_PARSER_H_
