#include "core/stereo/stereo_calibration.h"

#include <unistd.h>

#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <Eigen/Geometry>

namespace hpose {
namespace {

std::string TempPath(const std::string& name) {
  return testing::TempDir() + "/stereo_cal_" + std::to_string(::getpid()) + "_" + name;
}

void WriteText(const std::string& path, const std::string& text) { std::ofstream(path) << text; }

// The layout of OpenCV's stereo_calib sample: intrinsics.yml and extrinsics.yml, T in mm.
const char kIntrinsics[] = R"(%YAML:1.0
M1: !!opencv-matrix
   rows: 3
   cols: 3
   dt: d
   data: [ 440.0, 0., 258.6, 0., 275.0, 117.2, 0., 0., 1. ]
D1: !!opencv-matrix
   rows: 1
   cols: 5
   dt: d
   data: [ -0.22, 0.06, 0.0006, -0.0004, 0. ]
M2: !!opencv-matrix
   rows: 3
   cols: 3
   dt: d
   data: [ 444.4, 0., 251.3, 0., 277.7, 121.2, 0., 0., 1. ]
D2: !!opencv-matrix
   rows: 1
   cols: 5
   dt: d
   data: [ -0.2266, 0.06, 0.0006, -0.0004, 0. ]
)";
const char kExtrinsics[] = R"(%YAML:1.0
R: !!opencv-matrix
   rows: 3
   cols: 3
   dt: d
   data: [ 1., 0., 0., 0., 1., 0., 0., 0., 1. ]
T: !!opencv-matrix
   rows: 3
   cols: 1
   dt: d
   data: [ -70.0, 0.5, 0.2 ]
)";

TEST(StereoCalibrationTest, ReadsOpenCvSampleFilesWithMillimetres) {
  const std::string in = TempPath("intrinsics.yml"), ex = TempPath("extrinsics.yml");
  WriteText(in, kIntrinsics);
  WriteText(ex, kExtrinsics);
  StereoCalibrationReadOptions mm;
  mm.translation_unit_m = 0.001;
  auto cal = ReadStereoCalibration({in, ex}, mm);
  ASSERT_TRUE(cal.ok()) << cal.error().message;
  EXPECT_DOUBLE_EQ(cal->left.camera_matrix(0, 0), 440.0);
  EXPECT_DOUBLE_EQ(cal->right.camera_matrix(1, 2), 121.2);
  ASSERT_EQ(cal->left.distortion.size(), 5u);
  EXPECT_DOUBLE_EQ(cal->right.distortion[0], -0.2266);
  EXPECT_NEAR(cal->right_t_left.x(), -0.070, 1e-12);
  EXPECT_NEAR(cal->BaselineM(), 0.0700021, 1e-6);
  EXPECT_EQ(cal->image_width, 0);  // not stated in these files.

  // Read as metres, a 70 m baseline is implausible and the message suggests the fix.
  auto metres = ReadStereoCalibration({in, ex});
  ASSERT_FALSE(metres.ok());
  EXPECT_EQ(metres.error().code, ErrorCode::kInvalidArgument);
  EXPECT_NE(metres.error().message.find("millimetres"), std::string::npos);
}

TEST(StereoCalibrationTest, WriteReadRoundTripYamlAndXml) {
  StereoCalibration cal;
  cal.left.camera_matrix << 500, 0, 320, 0, 501, 240, 0, 0, 1;
  cal.right.camera_matrix << 502, 0, 318, 0, 503, 242, 0, 0, 1;
  cal.left.distortion = {-0.1, 0.01, 0, 0, 0};
  cal.right.distortion = {-0.11, 0.012, 0.001, 0, 0.002};
  cal.right_R_left = Eigen::AngleAxisd(0.01, Eigen::Vector3d::UnitY()).toRotationMatrix();
  cal.right_t_left = Eigen::Vector3d(-0.09, 0.001, 0);
  cal.image_width = 640;
  cal.image_height = 480;
  for (const char* ext : {".yaml", ".xml"}) {
    const std::string path = TempPath(std::string("roundtrip") + ext);
    ASSERT_TRUE(WriteStereoCalibration(cal, path).ok());
    auto back = ReadStereoCalibration({path});
    ASSERT_TRUE(back.ok()) << back.error().message;
    EXPECT_LT((back->left.camera_matrix - cal.left.camera_matrix).norm(), 1e-9);
    EXPECT_LT((back->right_R_left - cal.right_R_left).norm(), 1e-9);
    EXPECT_LT((back->right_t_left - cal.right_t_left).norm(), 1e-12);
    EXPECT_EQ(back->right.distortion, cal.right.distortion);
    EXPECT_EQ(back->image_width, 640);
    EXPECT_EQ(back->image_height, 480);
  }
}

TEST(StereoCalibrationTest, BadFilesGiveClearErrors) {
  auto missing = ReadStereoCalibration({TempPath("does_not_exist.yaml")});
  ASSERT_FALSE(missing.ok());
  EXPECT_EQ(missing.error().code, ErrorCode::kNotFound);

  const std::string garbage = TempPath("garbage.yaml");
  WriteText(garbage, "this is: [not, an OpenCV\n  file: {{{");
  auto bad = ReadStereoCalibration({garbage});
  ASSERT_FALSE(bad.ok());
  EXPECT_TRUE(bad.error().code == ErrorCode::kDataLoss ||
              bad.error().code == ErrorCode::kInvalidArgument);

  // Only the intrinsics: R and T are missing, and the message names them.
  const std::string in = TempPath("only_intrinsics.yml");
  WriteText(in, kIntrinsics);
  auto partial = ReadStereoCalibration({in});
  ASSERT_FALSE(partial.ok());
  EXPECT_EQ(partial.error().code, ErrorCode::kInvalidArgument);
  EXPECT_NE(partial.error().message.find("missing entry R"), std::string::npos);

  // A depth camera's intrinsics file is the wrong kind of file: no M1.
  const std::string wrong = TempPath("wrong.yml");
  WriteText(wrong, "%YAML:1.0\nfx: 594.2\nfy: 591.0\n");
  auto w = ReadStereoCalibration({wrong});
  ASSERT_FALSE(w.ok());
  EXPECT_NE(w.error().message.find("M1"), std::string::npos);

  // R that is not a rotation.
  const std::string ex = TempPath("bad_r.yml");
  std::string text = kExtrinsics;
  text.replace(text.find("1., 0., 0., 0., 1."), 18, "2., 0., 0., 0., 1.");
  WriteText(ex, text);
  StereoCalibrationReadOptions mm;
  mm.translation_unit_m = 0.001;
  auto r = ReadStereoCalibration({in, ex}, mm);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find("rotation"), std::string::npos);
}

}  // namespace
}  // namespace hpose
