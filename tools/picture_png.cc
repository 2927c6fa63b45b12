#include "tools/picture_png.h"

#include "core/io/atomic_file.h"
#include "core/io/decoded_image.h"
#include "core/io/png_codec.h"

namespace hpose::tools {

Status WritePicturePng(const Canvas& picture, const std::string& path, int compression_level) {
  Result<std::string> png = EncodePng(picture.ToRgb(), compression_level);
  if (!png.ok()) {
    return MakeError(png.error().code, "cannot write picture " + path + ": " + png.error().message);
  }
  return WriteFileAtomically(path, *png);
}

}  // namespace hpose::tools
