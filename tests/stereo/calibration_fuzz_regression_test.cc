// Inputs found by fuzz_stereo_calibration (fuzz/): a matrix whose header announces far more
// values than it holds made OpenCV allocate rows x cols first (48 GB); it is refused instead.
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "core/stereo/stereo_calibration.h"

namespace hpose {
namespace {

std::string WriteYaml(const std::string& name, const std::string& text) {
  const std::string path = (std::filesystem::temp_directory_path() / name).string();
  std::ofstream(path) << text;
  return path;
}

TEST(CalibrationFuzzRegressionTest, HugeMatrixHeaderIsRefusedBeforeAllocating) {
  for (const char* cols : {"1000000000", "-3", "3.5", "\"x\""}) {
    const std::string path =
        WriteYaml("hpose_calib_fuzz.yaml", std::string("%YAML:1.0\n---\nM1: !!opencv-matrix\n"
                                                       "   rows: 3\n   cols: ") +
                                               cols + "\n   dt: d\n   data: [ 1., 0., 0. ]\n");
    const Result<StereoCalibration> cal = ReadStereoCalibration({path});
    ASSERT_FALSE(cal.ok()) << cols;
    EXPECT_EQ(cal.error().code, ErrorCode::kInvalidArgument) << cal.error().ToString();
    EXPECT_NE(cal.error().message.find("M1"), std::string::npos) << cal.error().message;
    std::remove(path.c_str());
  }
}

}  // namespace
}  // namespace hpose
