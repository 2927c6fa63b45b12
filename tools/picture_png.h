#ifndef HPOSE_TOOLS_PICTURE_PNG_H_
#define HPOSE_TOOLS_PICTURE_PNG_H_

#include <string>

#include "core/common/status.h"
#include "tools/canvas.h"

namespace hpose::tools {

// Writes a picture as an RGB PNG, atomically, with libpng. `compression_level`: zlib's 0
// (fastest) to 9 (smallest).
Status WritePicturePng(const Canvas& picture, const std::string& path, int compression_level = 1);

}  // namespace hpose::tools

#endif  // HPOSE_TOOLS_PICTURE_PNG_H_
