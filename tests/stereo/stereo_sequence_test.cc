#include "core/stereo/stereo_sequence.h"

#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "core/stereo/rgb_image_io.h"
#include "core/stereo/stereo_calibration.h"
#include "core/stereo/stereo_estimator.h"
#include "core/stereo/stereo_sim_sequence.h"

namespace hpose {
namespace {

// A fresh, empty directory: one left by an earlier process of the same pid (its frames listed
// with these) is removed first.
std::string TempDir(const std::string& name) {
  const std::string dir =
      testing::TempDir() + "/stereo_seq_" + std::to_string(::getpid()) + "_" + name;
  std::filesystem::remove_all(dir);
  mkdir(dir.c_str(), 0755);
  return dir;
}

TEST(StereoSequenceTest, SimulatedSequenceRoundTripsThroughTheDirectoryLayout) {
  const std::string dir = TempDir("sim");
  StereoSimSequenceSpec spec;
  spec.frames = 3;
  spec.fps = 10.0;
  spec.noise.supersample = 1;
  ASSERT_TRUE(WriteStereoSimSequence(spec, dir).ok());
  auto seq = StereoSequence::Open(dir);
  ASSERT_TRUE(seq.ok()) << seq.error().message;
  ASSERT_EQ(seq->size(), 3u);
  EXPECT_DOUBLE_EQ(seq->frame(2).timestamp_s, 0.2);
  EXPECT_EQ(seq->calibration_path(), dir + "/calibration.yaml");
  auto cal = ReadStereoCalibration({seq->calibration_path()});
  ASSERT_TRUE(cal.ok()) << cal.error().message;
  EXPECT_EQ(cal->image_width, 512);
  auto est = StereoEstimator::Create(*cal);
  ASSERT_TRUE(est.ok());
  auto pair = seq->Load(1);
  ASSERT_TRUE(pair.ok());
  auto r = (*est)->Process(pair->first, pair->second, seq->frame(1).timestamp_s);
  ASSERT_TRUE(r.ok());
  EXPECT_TRUE(r->ok()) << r->reason;
  std::ifstream truth(dir + "/ground_truth.csv");
  std::string header;
  std::getline(truth, header);
  EXPECT_EQ(header.rfind("index,timestamp_s,robot_x_m", 0), 0u);
}

TEST(StereoSequenceTest, LeftRightDirectoriesWithoutFramesCsv) {
  const std::string dir = TempDir("plain");
  mkdir((dir + "/left").c_str(), 0755);
  mkdir((dir + "/right").c_str(), 0755);
  RgbImage a(8, 6), b(8, 6), c(9, 6);
  ASSERT_TRUE(WriteRgbPng(a, dir + "/left/0001.png").ok());
  ASSERT_TRUE(WriteRgbPng(b, dir + "/right/0001.png").ok());
  ASSERT_TRUE(WriteRgbPng(a, dir + "/left/0002.png").ok());
  ASSERT_TRUE(WriteRgbPng(c, dir + "/right/0002.png").ok());
  auto seq = StereoSequence::Open(dir, 20.0);
  ASSERT_TRUE(seq.ok()) << seq.error().message;
  ASSERT_EQ(seq->size(), 2u);
  EXPECT_DOUBLE_EQ(seq->frame(1).timestamp_s, 0.05);
  EXPECT_TRUE(seq->calibration_path().empty());
  auto ok = seq->Load(0);
  ASSERT_TRUE(ok.ok());
  EXPECT_EQ(ok->first.width, 8);
  auto mismatch = seq->Load(1);  // images of different sizes.
  ASSERT_FALSE(mismatch.ok());
  EXPECT_EQ(mismatch.error().code, ErrorCode::kInvalidArgument);
  EXPECT_NE(mismatch.error().message.find("9x6"), std::string::npos);

  ASSERT_TRUE(WriteRgbPng(a, dir + "/left/0003.png").ok());  // no partner on the right.
  auto unpaired = StereoSequence::Open(dir);
  ASSERT_FALSE(unpaired.ok());
  EXPECT_NE(unpaired.error().message.find("0003.png"), std::string::npos);
}

TEST(StereoSequenceTest, BadDirectoriesAndFilesGiveClearErrors) {
  auto none = StereoSequence::Open(TempDir("x") + "/does_not_exist");
  ASSERT_FALSE(none.ok());
  EXPECT_EQ(none.error().code, ErrorCode::kNotFound);
  auto empty = StereoSequence::Open(TempDir("empty"));
  ASSERT_FALSE(empty.ok());
  EXPECT_EQ(empty.error().code, ErrorCode::kNotFound);

  const std::string dir = TempDir("badcsv");
  std::ofstream(dir + "/frames.csv") << "timestamp_s,left,right\n0.0,l.png,r.png\nabc,l.png\n";
  auto bad = StereoSequence::Open(dir);
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.error().code, ErrorCode::kDataLoss);
  EXPECT_NE(bad.error().message.find("line 3"), std::string::npos);

  std::ofstream(dir + "/not_an_image.png") << "hello";
  auto img = ReadRgbImage(dir + "/not_an_image.png");
  ASSERT_FALSE(img.ok());
  EXPECT_EQ(img.error().code, ErrorCode::kDataLoss);
  EXPECT_EQ(ReadRgbImage(dir + "/missing.png").error().code, ErrorCode::kNotFound);
  // Formats other than PNG, JPEG and TIFF never reach OpenCV's decoders (a damaged DICOM file
  // made one of them abort): a BMP header and a DICOM preamble are refused by name.
  std::ofstream(dir + "/image.bmp") << "BM" << std::string(60, '\0');
  std::ofstream(dir + "/image.dcm") << std::string(128, '\0') << "DICM" << std::string(64, 'x');
  for (const char* name : {"/image.bmp", "/image.dcm"}) {
    auto other = ReadRgbImage(dir + name);
    ASSERT_FALSE(other.ok()) << name;
    EXPECT_EQ(other.error().code, ErrorCode::kDataLoss) << name;
    EXPECT_NE(other.error().message.find("not a PNG, JPEG or TIFF"), std::string::npos)
        << other.error().message;
  }
}

}  // namespace
}  // namespace hpose
