// Helpers shared by the daemon integration tests: temporary directories, simulated frames
// (through the `hpose simulate` program) and running commands.
#ifndef HPOSE_TESTS_INTEGRATION_TEST_UTIL_H_
#define HPOSE_TESTS_INTEGRATION_TEST_UTIL_H_

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

namespace hpose::testing_util {

inline std::string MakeTempDir(const std::string& tag) {
  std::string pattern =
      (std::filesystem::temp_directory_path() / ("hpose_" + tag + "_XXXXXX")).string();
  char* made = mkdtemp(pattern.data());
  return made != nullptr ? std::string(made) : std::string();
}

inline std::string HposeProgram() { return std::string(HPOSE_BINARY_DIR) + "/tools/hpose"; }

inline std::string TemplatePath(const std::string& name) {
  return std::string(HPOSE_SOURCE_DIR) + "/templates/" + name + ".bt";
}

// Runs a shell command; returns its exit status and appends its standard output to *out.
inline int RunCommand(const std::string& command, std::string* out = nullptr) {
  FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) return -1;
  char buf[4096];
  size_t n;
  while ((n = fread(buf, 1, sizeof(buf), pipe)) > 0) {
    if (out != nullptr) out->append(buf, n);
  }
  const int status = pclose(pipe);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

// Renders `frames` simulated 320x240 depth frames of the humanoid 1 m ahead (PNG +
// intrinsics.json, and cloud_NNN.pcd with `clouds`) into `dir`. True on success.
inline bool SimulateFrames(const std::string& dir, int frames, const std::string& extra = "",
                           bool clouds = false) {
  return RunCommand(HposeProgram() + " simulate --out '" + dir + "' --frames " +
                    std::to_string(frames) + " --width 320 --height 240 " +
                    (clouds ? "" : "--no-cloud ") + "--turn-deg 20 " + extra + " > /dev/null") == 0;
}

}  // namespace hpose::testing_util

#endif  // HPOSE_TESTS_INTEGRATION_TEST_UTIL_H_
