// Frame sources over PCL's Kinect grabber sequences (../shared/data; skipped when absent):
// directories of TIFF, pclzf and PCD frames and single files, with the times their names carry.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>

#include "server/frame_source.h"

namespace hpose::server {
namespace {

const std::string kGrabber = std::string(HPOSE_SHARED_DATA_DIR) + "/kinect/grabber_sequences/";

// Reads every frame of `spec` (fast, no loop) and checks kind, count and the file-name times.
void ExpectThreeTimedFrames(const std::string& spec, const std::string& kind, bool is_cloud,
                            double fx = 0.0) {
  ReplayOptions replay;
  replay.realtime = false;
  Result<std::unique_ptr<FrameSource>> source = MakeFrameSource(spec, replay);
  ASSERT_TRUE(source.ok()) << source.error().ToString();
  EXPECT_EQ((*source)->kind(), kind);
  ASSERT_TRUE((*source)->Open().ok());
  EXPECT_EQ((*source)->frame_count(), 3);
  std::vector<double> times;
  for (;;) {
    Result<Frame> f = (*source)->Next();
    if (!f.ok()) {
      EXPECT_EQ(f.error().code, ErrorCode::kOutOfRange) << f.error().ToString();
      break;
    }
    EXPECT_EQ(f->is_cloud, is_cloud);
    if (!is_cloud) {
      EXPECT_EQ(f->depth.width, 640);
      EXPECT_EQ(f->intrinsics.width, 640);
      EXPECT_NEAR(f->intrinsics.fx, fx, 0.1);
    }
    times.push_back(f->source_time_s);
  }
  ASSERT_EQ(times.size(), 3u);
  // 2012-12-14 14:22:55.814212 UTC, then about 0.25 s apart (not 0, 0.033, ...).
  EXPECT_NEAR(times[0], 1355494975.814212, 1e-5);
  EXPECT_NEAR(times[1] - times[0], 0.254471, 1e-5);
  EXPECT_NEAR(times[2] - times[1], 0.263712, 1e-5);
}

class RealSequenceTest : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!std::filesystem::exists(kGrabber)) {
      GTEST_SKIP() << "PCL grabber sequences not found in " << kGrabber
                   << " (third-party data is optional)";
    }
  }
};

TEST_F(RealSequenceTest, TiffDirectory) {
  // TIFF carries no intrinsics: Kinect v1 defaults.
  ExpectThreeTimedFrames(kGrabber + "tiff", "tiff-dir", false, Intrinsics::KinectV1().fx);
}

TEST_F(RealSequenceTest, PclzfDirectory) {
  // The .xml beside each pclzf says fx = 525.
  ExpectThreeTimedFrames(kGrabber + "pclzf", "pclzf-dir", false, 525.0);
}

TEST_F(RealSequenceTest, PcdDirectory) {
  ExpectThreeTimedFrames(kGrabber + "pcd", "pcd-dir", true);
}

TEST_F(RealSequenceTest, SingleFilesAreOneFrameRecordings) {
  for (const std::string& file : {kGrabber + "tiff/frame_20121214T142256.068683_depth.tiff",
                                  kGrabber + "pclzf/frame_20121214T142256.068683_depth.pclzf",
                                  kGrabber + "pcd/frame_20121214T142256.068683.pcd"}) {
    ReplayOptions replay;
    replay.realtime = false;
    Result<std::unique_ptr<FrameSource>> source = MakeFrameSource(file, replay);
    ASSERT_TRUE(source.ok()) << file << ": " << source.error().ToString();
    ASSERT_TRUE((*source)->Open().ok()) << file;
    Result<Frame> f = (*source)->Next();
    ASSERT_TRUE(f.ok()) << f.error().ToString();
    EXPECT_NEAR(f->source_time_s, 1355494976.068683, 1e-5) << file;
    EXPECT_EQ((*source)->Next().error().code, ErrorCode::kOutOfRange) << file;
  }
}

TEST_F(RealSequenceTest, LoopingStartsANewEpoch) {
  ReplayOptions replay;
  replay.realtime = false;
  replay.loop = true;
  Result<std::unique_ptr<FrameSource>> source = MakeFrameSource(kGrabber + "pcd", replay);
  ASSERT_TRUE(source.ok());
  ASSERT_TRUE((*source)->Open().ok());
  std::vector<Frame> frames;
  for (int i = 0; i < 4; ++i) {
    Result<Frame> f = (*source)->Next();
    ASSERT_TRUE(f.ok());
    frames.push_back(std::move(*f));
  }
  EXPECT_EQ(frames[2].epoch, 0u);
  EXPECT_EQ(frames[3].epoch, 1u);  // back to the first file: its time goes back, the epoch up.
  EXPECT_LT(frames[3].source_time_s, frames[2].source_time_s);
  EXPECT_EQ(frames[3].sequence, 4u);  // the sequence keeps counting.
}

}  // namespace
}  // namespace hpose::server
