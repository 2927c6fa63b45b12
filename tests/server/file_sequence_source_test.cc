#include "server/file_sequence_source.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "core/io/depth_png.h"
#include "core/io/intrinsics_json.h"
#include "server/frame_source.h"

namespace hpose::server {
namespace {

namespace fs = std::filesystem;

class FileSequenceSourceTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("hpose_fss_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  void WriteFrames(int n) {
    Intrinsics k = Intrinsics::KinectV1(8, 6);
    ASSERT_TRUE(WriteIntrinsicsJson(k, (dir_ / "intrinsics.json").string()).ok());
    for (int i = 0; i < n; ++i) {
      DepthImage d(8, 6);
      d.at(0, 0) = static_cast<std::uint16_t>(1000 + i);
      ASSERT_TRUE(WriteDepthPng(d, (dir_ / ("f" + std::to_string(i) + ".png")).string()).ok());
    }
  }
  fs::path dir_;
};

TEST_F(FileSequenceSourceTest, ReadsInNameOrderThenEnds) {
  WriteFrames(3);
  ReplayOptions replay;
  replay.realtime = false;
  replay.fps = 10.0;
  Result<std::unique_ptr<FrameSource>> s = MakeFrameSource(dir_.string(), replay);
  ASSERT_TRUE(s.ok()) << s.error().ToString();
  EXPECT_EQ((*s)->kind(), "png-dir");
  ASSERT_TRUE((*s)->Open().ok());
  EXPECT_EQ((*s)->frame_count(), 3);
  for (int i = 0; i < 3; ++i) {
    Result<Frame> f = (*s)->Next();
    ASSERT_TRUE(f.ok()) << f.error().ToString();
    EXPECT_EQ(f->depth.at(0, 0), 1000 + i);
    EXPECT_EQ(f->sequence, static_cast<std::uint64_t>(i + 1));
    EXPECT_DOUBLE_EQ(f->source_time_s, i / 10.0);
    EXPECT_EQ(f->intrinsics.width, 8);
  }
  Result<Frame> end = (*s)->Next();
  ASSERT_FALSE(end.ok());
  EXPECT_EQ(end.error().code, ErrorCode::kOutOfRange);
}

TEST_F(FileSequenceSourceTest, LoopsWithIncreasingSequence) {
  WriteFrames(2);
  ReplayOptions replay;
  replay.realtime = false;
  replay.loop = true;
  Result<std::unique_ptr<FrameSource>> s = MakeFrameSource(dir_.string(), replay);
  ASSERT_TRUE(s.ok());
  ASSERT_TRUE((*s)->Open().ok());
  for (int i = 0; i < 5; ++i) {
    Result<Frame> f = (*s)->Next();
    ASSERT_TRUE(f.ok());
    EXPECT_EQ(f->depth.at(0, 0), 1000 + i % 2);
    EXPECT_EQ(f->sequence, static_cast<std::uint64_t>(i + 1));
  }
}

TEST_F(FileSequenceSourceTest, CorruptFrameIsReportedAndSkipped) {
  WriteFrames(2);
  std::ofstream(dir_ / "f0.png") << "not a png";
  ReplayOptions replay;
  replay.realtime = false;
  Result<std::unique_ptr<FrameSource>> s = MakeFrameSource(dir_.string(), replay);
  ASSERT_TRUE(s.ok());
  ASSERT_TRUE((*s)->Open().ok());
  Result<Frame> bad = (*s)->Next();
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.error().message.find("f0.png"), std::string::npos) << bad.error().message;
  Result<Frame> good = (*s)->Next();
  ASSERT_TRUE(good.ok());
  EXPECT_EQ(good->depth.at(0, 0), 1001);
}

TEST_F(FileSequenceSourceTest, MakeFrameSourceExplainsWhatIsWrong) {
  ReplayOptions replay;
  EXPECT_EQ(MakeFrameSource((dir_ / "missing").string(), replay).error().code,
            ErrorCode::kNotFound);
  EXPECT_EQ(MakeFrameSource("", replay).error().code, ErrorCode::kInvalidArgument);
  // PNGs without intrinsics.json.
  DepthImage d(4, 4);
  ASSERT_TRUE(WriteDepthPng(d, (dir_ / "a.png").string()).ok());
  Result<std::unique_ptr<FrameSource>> s = MakeFrameSource(dir_.string(), replay);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.error().message.find("intrinsics.json"), std::string::npos);
  // A plain file that is not a recording.
  std::ofstream(dir_ / "notes.txt") << "x";
  EXPECT_EQ(MakeFrameSource((dir_ / "notes.txt").string(), replay).error().code,
            ErrorCode::kInvalidArgument);
  // A device spec makes an OpenNI2 source (not opened here).
  Result<std::unique_ptr<FrameSource>> dev = MakeFrameSource("openni2://", replay);
  ASSERT_TRUE(dev.ok());
  EXPECT_TRUE((*dev)->live());
}

}  // namespace
}  // namespace hpose::server
