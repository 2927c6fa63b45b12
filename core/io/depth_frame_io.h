#ifndef HPOSE_CORE_IO_DEPTH_FRAME_IO_H_
#define HPOSE_CORE_IO_DEPTH_FRAME_IO_H_

#include <string>

#include "core/common/status.h"
#include "core/depth/depth_image.h"
#include "core/depth/intrinsics.h"

namespace hpose {

// A depth frame read from a file, with the intrinsics the file itself carries (if any).
struct DepthFrameFile {
  DepthImage depth;  // millimetres, 0 = no reading.
  bool has_intrinsics = false;
  Intrinsics intrinsics;  // when has_intrinsics (pclzf: from its .xml).
};

// True when `path` names a depth frame format ReadDepthFrame reads (by extension): .png,
// .tif / .tiff, .pclzf.
bool IsDepthFrameFile(const std::string& path);

// Reads one depth frame:
//   .png           single-channel 16-bit PNG, millimetres (ReadDepthPng, libpng);
//   .tif / .tiff   single-channel 16-bit TIFF, millimetres (as PCL's grabbers and many
//                  RGB-D datasets write them; ReadTiff, libtiff);
//   .pclzf         PCL's LZF-compressed 16-bit depth image; its camera parameters come from
//                  the .xml beside it (NAME_depth.pclzf -> NAME.xml, PCL's grabber layout),
//                  the depth unit from its z_multiplication_factor.
// kNotFound (missing file or .xml), kDataLoss (corrupt), kInvalidArgument (not a 16-bit
// single-channel image, e.g. a colour frame), each message naming the path.
Result<DepthFrameFile> ReadDepthFrame(const std::string& path);

// The .xml camera description PCL's grabber writes beside NAME_depth.pclzf (NAME.xml).
std::string PclzfParameterPath(const std::string& pclzf_path);

}  // namespace hpose

#endif  // HPOSE_CORE_IO_DEPTH_FRAME_IO_H_
