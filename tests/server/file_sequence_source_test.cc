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

// A PNG whose header announces a side beyond what hpose decodes: the reader refuses it from
// the header (kOutOfRange) before anything is decoded, so the rest of the file does not matter.
void WriteOversizedPngHeader(const fs::path& path) {
  const unsigned char head[] = {0x89, 'P',  'N', 'G', '\r', '\n', 0x1a, '\n', 0,    0, 0,
                                13,   'I',  'H', 'D', 'R',  0,    1,    0x86, 0xa0, 0, 1,
                                0x86, 0xa0, 16,  0,   0,    0,    0,    0,    0,    0, 0};
  std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(head), sizeof head);
}

TEST_F(FileSequenceSourceTest, AnOversizedFrameIsSkippedNotTakenForTheEnd) {
  WriteFrames(3);
  WriteOversizedPngHeader(dir_ / "f1.png");  // 100000 x 100000 px.
  ReplayOptions replay;
  replay.realtime = false;
  Result<std::unique_ptr<FrameSource>> s = MakeFrameSource(dir_.string(), replay);
  ASSERT_TRUE(s.ok()) << s.error().ToString();
  ASSERT_TRUE((*s)->Open().ok());
  Result<Frame> first = (*s)->Next();
  ASSERT_TRUE(first.ok()) << first.error().ToString();
  Result<Frame> bad = (*s)->Next();
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.error().code, ErrorCode::kInvalidArgument) << bad.error().ToString();
  EXPECT_NE(bad.error().message.find("f1.png"), std::string::npos) << bad.error().message;
  EXPECT_NE(bad.error().message.find("100000x100000"), std::string::npos) << bad.error().message;
  Result<Frame> last = (*s)->Next();
  ASSERT_TRUE(last.ok()) << last.error().ToString();
  EXPECT_EQ(last->depth.at(0, 0), 1002);
  EXPECT_EQ((*s)->Next().error().code, ErrorCode::kOutOfRange);
}

TEST_F(FileSequenceSourceTest, AnOversizedCloudIsSkippedNotTakenForTheEnd) {
  const std::string header_start =
      "VERSION .7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n";
  std::ofstream(dir_ / "a.pcd") << header_start
                                << "WIDTH 1\nHEIGHT 1\nPOINTS 1\nDATA ascii\n0.1 0.2 1.5\n";
  std::ofstream(dir_ / "b.pcd") << header_start
                                << "WIDTH 4000000000\nHEIGHT 1\nPOINTS 4000000000\nDATA binary\n";
  std::ofstream(dir_ / "c.pcd") << header_start
                                << "WIDTH 1\nHEIGHT 1\nPOINTS 1\nDATA ascii\n0.3 0.2 1.5\n";
  ReplayOptions replay;
  replay.realtime = false;
  Result<std::unique_ptr<FrameSource>> s = MakeFrameSource(dir_.string(), replay);
  ASSERT_TRUE(s.ok()) << s.error().ToString();
  ASSERT_TRUE((*s)->Open().ok());
  ASSERT_TRUE((*s)->Next().ok());
  Result<Frame> bad = (*s)->Next();
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.error().code, ErrorCode::kInvalidArgument) << bad.error().ToString();
  EXPECT_NE(bad.error().message.find("b.pcd"), std::string::npos) << bad.error().message;
  Result<Frame> last = (*s)->Next();
  ASSERT_TRUE(last.ok()) << last.error().ToString();
  ASSERT_EQ(last->cloud.size(), 1u);
  EXPECT_FLOAT_EQ(last->cloud.points[0].x(), 0.3f);
  EXPECT_EQ((*s)->Next().error().code, ErrorCode::kOutOfRange);
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
