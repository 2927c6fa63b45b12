#include "core/stereo/stereo_calibrator.h"

#include <sys/stat.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "core/stereo/rgb_image_io.h"
#include "core/stereo/stereo_estimator.h"
#include "core/stereo/stereo_rig.h"

namespace hpose {
namespace {

// OpenCV's sample chessboard pairs (9x6 inner corners), as Debian's opencv-doc installs them;
// HPOSE_OPENCV_SAMPLES may point elsewhere.
std::string SampleDir() {
  const char* env = std::getenv("HPOSE_OPENCV_SAMPLES");
  return env != nullptr ? env : "/usr/share/doc/opencv-doc/examples/data";
}

bool Exists(const std::string& path) {
  struct stat st {};
  return stat(path.c_str(), &st) == 0;
}

std::vector<StereoCalibrationView> LoadSamples() {
  std::vector<StereoCalibrationView> views;
  for (int i = 1; i <= 14; ++i) {
    char l[32], r[32];
    std::snprintf(l, sizeof(l), "/left%02d.jpg", i);
    std::snprintf(r, sizeof(r), "/right%02d.jpg", i);
    if (!Exists(SampleDir() + l)) continue;  // the set has no pair 10.
    auto li = ReadRgbImage(SampleDir() + l);
    auto ri = ReadRgbImage(SampleDir() + r);
    if (!li.ok() || !ri.ok()) continue;
    views.push_back(StereoCalibrationView{l + 1, std::move(li).value(), std::move(ri).value()});
  }
  return views;
}

TEST(StereoCalibratorTest, CalibratesOpenCvSamplePairsAndTheEstimatorReadsTheFile) {
  if (!Exists(SampleDir() + "/left01.jpg")) {
    GTEST_SKIP() << "OpenCV's sample chessboard pairs not found in " << SampleDir()
                 << " (install opencv-doc)";
  }
  const std::vector<StereoCalibrationView> views = LoadSamples();
  ASSERT_GE(views.size(), 10u);
  ChessboardOptions board;  // 9x6, 25 mm.
  int progress_calls = 0;
  auto report = CalibrateStereo(views, board, [&](const auto&) { ++progress_calls; });
  ASSERT_TRUE(report.ok()) << report.error().message;
  EXPECT_EQ(progress_calls, static_cast<int>(views.size()));
  EXPECT_GT(report->rms_px, 0.0);
  EXPECT_LT(report->rms_px, 1.0);  // OpenCV's own sample reaches well under a pixel.
  int used = 0;
  for (const auto& v : report->views) {
    used += v.used;
    if (v.used) EXPECT_LT(v.left_rms_px, 2.0) << v.name;
  }
  EXPECT_GE(used, 10);
  EXPECT_EQ(report->calibration.image_width, 640);
  EXPECT_EQ(report->calibration.image_height, 480);
  // The cameras sit side by side: the right one along the left one's +x.
  EXPECT_LT(report->calibration.right_t_left.x(), 0.0);

  std::string tmpl = (std::filesystem::temp_directory_path() / "hpose_calib_XXXXXX").string();
  ASSERT_NE(mkdtemp(tmpl.data()), nullptr);
  const std::string path = tmpl + "/stereo.yaml";
  ASSERT_TRUE(WriteStereoCalibrationReport(*report, path).ok());
  auto read = ReadStereoCalibration({path});
  ASSERT_TRUE(read.ok()) << read.error().message;
  EXPECT_LT((read->right_t_left - report->calibration.right_t_left).norm(), 1e-9);
  auto estimator = StereoEstimator::Create(*read);
  ASSERT_TRUE(estimator.ok()) << estimator.error().message;
  auto frame = (*estimator)->Process(views[0].left, views[0].right, 0.0);
  ASSERT_TRUE(frame.ok()) << frame.error().message;
  EXPECT_FALSE(frame->ok());  // a chessboard, no landmarks: rejected with a reason.
  EXPECT_FALSE(frame->reason.empty());

  // Triangulating the board's corners with the written calibration gives the square size.
  auto rig = StereoRig::Create(*read);
  ASSERT_TRUE(rig.ok());
  for (const auto& v : report->views) {
    if (!v.used) continue;
    const auto ln = (*rig)->Normalize(StereoSide::kLeft, v.left_corners);
    const auto rn = (*rig)->Normalize(StereoSide::kRight, v.right_corners);
    double sum = 0;
    int n = 0;
    for (int row = 0; row < board.inner_rows; ++row) {
      for (int col = 0; col + 1 < board.inner_columns; ++col) {
        const int i = row * board.inner_columns + col;
        bool ok_a = false, ok_b = false;
        const Eigen::Vector3d a = (*rig)->Triangulate(ln[i], rn[i], &ok_a);
        const Eigen::Vector3d b = (*rig)->Triangulate(ln[i + 1], rn[i + 1], &ok_b);
        ASSERT_TRUE(ok_a && ok_b) << v.name;
        sum += (a - b).norm();
        ++n;
      }
    }
    EXPECT_NEAR(sum / n, board.square_m, 0.02 * board.square_m) << v.name;
  }
  std::remove(path.c_str());
  rmdir(tmpl.c_str());
}

TEST(StereoCalibratorTest, TooFewBoardsAndBadInputAreReported) {
  StereoCalibrationView blank{"blank", RgbImage(64, 48), RgbImage(64, 48)};
  auto r = CalibrateStereo({blank, blank, blank}, ChessboardOptions{});
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().code, ErrorCode::kFailedPrecondition);
  EXPECT_NE(r.error().message.find("only 0 of 3"), std::string::npos) << r.error().message;
  StereoCalibrationView odd{"odd", RgbImage(64, 48), RgbImage(32, 48)};
  r = CalibrateStereo({blank, odd}, ChessboardOptions{});
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().code, ErrorCode::kInvalidArgument);
  EXPECT_NE(r.error().message.find("odd"), std::string::npos);
  ChessboardOptions bad;
  bad.square_m = 0;
  EXPECT_EQ(CalibrateStereo({blank}, bad).error().code, ErrorCode::kInvalidArgument);
  // Boards OpenCV's corner search refuses (2 corners a side threw out of it and aborted), and
  // squares of 1e300 m, are errors naming the board.
  bad = ChessboardOptions{};
  bad.inner_columns = 2;
  bad.inner_rows = 2;
  r = CalibrateStereo({blank, blank, blank}, bad);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().code, ErrorCode::kInvalidArgument);
  EXPECT_NE(r.error().message.find("got 2x2 corners"), std::string::npos) << r.error().message;
  bad = ChessboardOptions{};
  bad.square_m = 1e300;
  EXPECT_EQ(CalibrateStereo({blank}, bad).error().code, ErrorCode::kInvalidArgument);
  bad = ChessboardOptions{};
  bad.inner_columns = 100000;
  EXPECT_EQ(CalibrateStereo({blank}, bad).error().code, ErrorCode::kInvalidArgument);
}

}  // namespace
}  // namespace hpose
