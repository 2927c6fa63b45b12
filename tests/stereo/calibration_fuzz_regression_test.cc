// Inputs found by fuzz_stereo_calibration (fuzz/): a matrix whose header announces far more
// values than it holds made OpenCV allocate rows x cols first (48 GB), and a mutated file made
// OpenCV's YAML parser throw an exception nobody caught; both are errors now.
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

// The YAML parser itself throws std::length_error (not cv::Exception) on this mutated file.
TEST(CalibrationFuzzRegressionTest, ParserExceptionIsAnError) {
  const std::string path = WriteYaml("hpose_calib_fuzz2.yaml", R"(%YAML:1.0
---
image_width: 512
image_height: 240
M1: !!opencv-matrix
   rows: 3
   cols: 3
   dt: d
   data: [ 4.4340500673763262e+02, 0., 2.5860000000000002e+02, 0.,
       2.7712812921102039e+02, 1.1720000000000000e+02, 0., 0., 1. ]
D1: !!opencv-matrix
   rows: 1
   cols: 5
   dt: d
   data: [ -2.2000000000000000e-01, 5.9999999999999998e-02,
       5.9999999999999995e-04, -4.0000000000000002e-04, 0. ]
M2: !!opencv-matrix
   rows: 3
   :olsc 3
   dt: d
   {ata: [ 4.4783905680500897e+02, 0., 2.5130000000000001e+02, 0.,
       2.7989941050313058e+02, 1.212000000000000000702483775353e-04 ]
translation_unit: m
)");
  const Result<StereoCalibration> cal = ReadStereoCalibration({path});
  ASSERT_FALSE(cal.ok());
  EXPECT_EQ(cal.error().code, ErrorCode::kDataLoss) << cal.error().ToString();
  std::remove(path.c_str());
}

// A file whose top-level node is a sequence opens, but looking an entry up in it makes OpenCV
// fail an assertion (cv::Exception from FileStorage::operator[]); found by fuzzing.
TEST(CalibrationFuzzRegressionTest, TopLevelSequenceIsAnError) {
  const std::string path = WriteYaml("hpose_calib_fuzz3.yaml", "%YAML:1.0\n---\n- 1\n- 2\n");
  const Result<StereoCalibration> cal = ReadStereoCalibration({path});
  ASSERT_FALSE(cal.ok());
  EXPECT_EQ(cal.error().code, ErrorCode::kDataLoss) << cal.error().ToString();
  EXPECT_NE(cal.error().message.find("malformed"), std::string::npos) << cal.error().message;
  std::remove(path.c_str());
}

// OpenCV's YAML parser never returns on this fuzzed file (a "%" directive line in the middle,
// then "--0"); hpose's own parser refuses it.
TEST(CalibrationFuzzRegressionTest, DirectiveInTheMiddleIsRefusedBeforeOpenCvHangs) {
  const std::string path =
      WriteYaml("hpose_calib_fuzz4.yaml",
                "%YAML:1.%A-: !!\x84opgncv-matr!!op\n   rows: 9983\n   cols: 3\n   \n%\n--0");
  const Result<StereoCalibration> cal = ReadStereoCalibration({path});
  ASSERT_FALSE(cal.ok());
  EXPECT_EQ(cal.error().code, ErrorCode::kDataLoss) << cal.error().ToString();
  EXPECT_NE(cal.error().message.find("directive"), std::string::npos) << cal.error().message;
  std::remove(path.c_str());
}

// OpenCV's YAML parser never returned on this one either (found by the CI's fuzz run: a key on
// a line of its own with " : [" below it); hpose no longer hands calibration files to OpenCV.
TEST(CalibrationFuzzRegressionTest, FileThatHungOpenCvsParserIsAnError) {
  const std::string path = WriteYaml("hpose_calib_fuzz5.yaml",
                                     std::string("%YAML:1.\xff\xff\xff\xff\xff\xff\xff\xff"
                                                 "4: !!opematrix\n   rows a:3  \n"
                                                 " : [ -6.994\xbf ]\ntran\x8c\x93\x96\x8b: m\n"));
  const Result<StereoCalibration> cal = ReadStereoCalibration({path});
  ASSERT_FALSE(cal.ok());
  EXPECT_EQ(cal.error().code, ErrorCode::kDataLoss) << cal.error().ToString();
  EXPECT_NE(cal.error().message.find("line 3"), std::string::npos) << cal.error().message;
  std::remove(path.c_str());
}

}  // namespace
}  // namespace hpose
