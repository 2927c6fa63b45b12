#ifndef HPOSE_TOOLS_PICTURE_PNG_H_
#define HPOSE_TOOLS_PICTURE_PNG_H_

#include <string>

#include "core/common/status.h"

namespace cv {
class Mat;
}  // namespace cv

namespace hpose::tools {

// Writes a picture drawn with OpenCV (8-bit BGR, as cv::Scalar colours are given) as an RGB PNG,
// atomically, with libpng: programs that draw need not load OpenCV's image codecs.
// `compression_level`: zlib's 0 (fastest) to 9 (smallest).
Status WritePicturePng(const cv::Mat& bgr, const std::string& path, int compression_level = 1);

}  // namespace hpose::tools

#endif  // HPOSE_TOOLS_PICTURE_PNG_H_
