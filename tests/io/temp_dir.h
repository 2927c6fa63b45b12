// Test helper: a fresh temporary directory removed (with its files) at the end of the test.
#ifndef HPOSE_TESTS_IO_TEMP_DIR_H_
#define HPOSE_TESTS_IO_TEMP_DIR_H_

#include <stdlib.h>

#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

namespace hpose {

class TempDir {
 public:
  TempDir() {
    std::string pattern = ::testing::TempDir() + "hpose_io_XXXXXX";
    char* made = ::mkdtemp(pattern.data());
    EXPECT_NE(made, nullptr);
    path_ = pattern;
  }
  ~TempDir() {
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  std::string File(const std::string& name) const { return path_ + "/" + name; }

  // Writes raw bytes (test fixtures such as garbage or truncated files).
  std::string Write(const std::string& name, const std::string& bytes) const {
    std::ofstream out(File(name), std::ios::binary);
    out << bytes;
    return File(name);
  }

  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

inline std::string Slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

}  // namespace hpose

#endif  // HPOSE_TESTS_IO_TEMP_DIR_H_
