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

namespace hpose::fuzz {

// Writes `data` to a file named fuzz_input_PID.EXT in the temporary directory (one per
// process, overwritten on every input) and returns its path.
inline std::string WriteInput(const std::uint8_t* data, std::size_t size, const std::string& ext) {
  static const std::string path = (std::filesystem::temp_directory_path() /
                                   ("hpose_fuzz_input_" + std::to_string(::getpid()) + "." + ext))
                                      .string();
  std::ofstream(path, std::ios::binary | std::ios::trunc)
      .write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  return path;
}

}  // namespace hpose::fuzz

#endif  // HPOSE_FUZZ_FUZZ_INPUT_FILE_H_
