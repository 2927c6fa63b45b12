// Helpers for tests that run the built `hpose` program.
#ifndef HPOSE_TESTS_TOOLS_CLI_TEST_UTIL_H_
#define HPOSE_TESTS_TOOLS_CLI_TEST_UTIL_H_

#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace hpose::testing {

struct CliRun {
  int exit_code = -1;
  std::string out;
  std::string err;
};

// A fresh directory under the system temp dir, removed when the object goes away.
class TempDir {
 public:
  explicit TempDir(const std::string& tag)
      : path_(std::filesystem::temp_directory_path() /
              ("hpose_" + tag + "_" + std::to_string(::getpid()))) {
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  std::string operator/(const std::string& name) const { return (path_ / name).string(); }
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

inline std::string Slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// Runs `program <args>` (args already shell-quoted where needed), capturing stdout and stderr
// into files inside `dir`.
inline CliRun RunProgram(const std::string& program, const std::string& args, const TempDir& dir) {
  const std::string out = dir / "stdout.txt";
  const std::string err = dir / "stderr.txt";
  const std::string cmd = "'" + program + "' " + args + " >'" + out + "' 2>'" + err + "'";
  const int status = std::system(cmd.c_str());
  CliRun run;
  run.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  run.out = Slurp(out);
  run.err = Slurp(err);
  return run;
}

// Runs the built `hpose <args>`.
inline CliRun RunHpose(const std::string& args, const TempDir& dir) {
  return RunProgram(std::string(HPOSE_BINARY_DIR) + "/tools/hpose", args, dir);
}

}  // namespace hpose::testing

#endif  // HPOSE_TESTS_TOOLS_CLI_TEST_UTIL_H_
