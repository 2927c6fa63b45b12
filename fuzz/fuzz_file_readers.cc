// One libFuzzer target per file reader, chosen at compile time by HPOSE_FUZZ_READER: every
// input must give a value or an Error, never a crash, a hang or an unbounded allocation.
#include <cstddef>
#include <cstdint>
#include <string>

#include "core/io/cloud_io.h"
#include "core/io/depth_frame_io.h"
#include "core/io/depth_png.h"
#include "core/io/intrinsics_json.h"
#include "core/io/pclzf_reader.h"
#include "core/stereo/rgb_image_io.h"
#include "core/stereo/stereo_calibration.h"
#include "core/stereo/stereo_marker_options.h"
#include "core/templates/template_io.h"
#include "fuzz/fuzz_input_file.h"
#include "server/daemon_config.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace hpose;
  const std::string text(reinterpret_cast<const char*>(data), size);
#if HPOSE_FUZZ_READER == 1
  (void)ReadDepthPng(fuzz::WriteInput(data, size, "png"));
#elif HPOSE_FUZZ_READER == 2
  (void)ReadRgbImage(fuzz::WriteInput(data, size, "tiff"));
#elif HPOSE_FUZZ_READER == 3
  (void)ReadCloud(fuzz::WriteInput(data, size, "pcd"));
#elif HPOSE_FUZZ_READER == 4
  (void)ReadCloud(fuzz::WriteInput(data, size, "ply"));
#elif HPOSE_FUZZ_READER == 5
  (void)ParseIntrinsicsJson(text, "fuzz");
#elif HPOSE_FUZZ_READER == 6
  (void)LoadTemplate(fuzz::WriteInput(data, size, "bt"));
#elif HPOSE_FUZZ_READER == 7
  (void)server::ParseDaemonConfig(text, "fuzz", "");
#elif HPOSE_FUZZ_READER == 8
  // Both readers of OpenCV FileStorage text files (one parser under them).
  const std::string path = fuzz::WriteInput(data, size, "yaml");
  (void)ReadStereoCalibration({path});
  (void)LoadStereoMarkerOptions(path);
#elif HPOSE_FUZZ_READER == 9
  (void)ReadDepthFrame(fuzz::WriteInput(data, size, "tiff"));
#elif HPOSE_FUZZ_READER == 10
  (void)ReadPclzfDepth16(fuzz::WriteInput(data, size, "pclzf"));
#else
#error "HPOSE_FUZZ_READER must name a reader (1-10)"
#endif
  return 0;
}
