// Shared by the file-reader fuzz targets: the readers take paths, so each input is written to a
// private temporary file with the extension the reader dispatches on.
#ifndef HPOSE_FUZZ_FUZZ_INPUT_FILE_H_
#define HPOSE_FUZZ_FUZZ_INPUT_FILE_H_

#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <system_error>

namespace hpose::fuzz {

// The file behind WriteInput, removed when the process exits normally (libFuzzer's -runs and
// -max_total_time end that way), so fuzz runs leave nothing in the temporary directory. A crash
// leaves it, and libFuzzer saves the crashing input itself.
class InputFile {
 public:
  explicit InputFile(const std::string& ext)
      : path_((std::filesystem::temp_directory_path() /
               ("hpose_fuzz_input_" + std::to_string(::getpid()) + "." + ext))
                  .string()) {}
  ~InputFile() {
    std::error_code ignored;
    std::filesystem::remove(path_, ignored);
  }
  InputFile(const InputFile&) = delete;
  InputFile& operator=(const InputFile&) = delete;
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

// Writes `data` to a file named hpose_fuzz_input_PID.EXT in the temporary directory (one per
// process, overwritten on every input) and returns its path.
inline std::string WriteInput(const std::uint8_t* data, std::size_t size, const std::string& ext) {
  static const InputFile file(ext);
  std::ofstream(file.path(), std::ios::binary | std::ios::trunc)
      .write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  return file.path();
}

}  // namespace hpose::fuzz

#endif  // HPOSE_FUZZ_FUZZ_INPUT_FILE_H_
