// The pose pipeline with several estimation threads on a recording of simulated frames: every
// frame published in frame order at rate: fast; never an older frame after a newer one when
// paced.
#include <chrono>
#include <cmath>
#include <filesystem>
#include <map>
#include <memory>
#include <vector>

#include <gtest/gtest.h>

#include "core/templates/template_io.h"
#include "server/frame_source.h"
#include "server/pose_pipeline.h"
#include "tests/integration/test_util.h"

namespace hpose::server {
namespace {

using Clock = std::chrono::steady_clock;
constexpr int kFrames = 6;

class PipelineThreadsTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = testing_util::MakeTempDir("pipeline_threads");
    ASSERT_FALSE(dir_.empty());
    ASSERT_TRUE(testing_util::SimulateFrames(dir_, kFrames, "--clutter 2"));
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  // A pipeline over the frames of `dir` (default: the test's), starting from `initial` (source.
  // initial_pose) when given; `one_threshold`: search.far_score_ratio 1.
  std::unique_ptr<PosePipeline> MakePipeline(bool realtime, double fps, int threads,
                                             const std::string& dir = "",
                                             const Pose2D* initial = nullptr,
                                             bool one_threshold = false) {
    ReplayOptions replay;
    replay.realtime = realtime;
    replay.fps = fps;
    Result<std::unique_ptr<FrameSource>> source = MakeFrameSource(dir.empty() ? dir_ : dir, replay);
    EXPECT_TRUE(source.ok()) << source.error().ToString();
    std::vector<VoxelTemplate> templates;
    for (const char* name : {"standing", "right_arm_raised"}) {
      Result<VoxelTemplate> t = LoadTemplate(testing_util::TemplatePath(name));
      EXPECT_TRUE(t.ok());
      templates.push_back(*t);
    }
    std::vector<std::unique_ptr<Estimator>> estimators;
    for (int i = 0; i < threads; ++i) {
      EstimatorOptions options = DefaultEstimatorOptions();
      if (one_threshold) options.far_score_ratio = 1.0;
      Result<std::unique_ptr<Estimator>> e = Estimator::Create(options, templates);
      EXPECT_TRUE(e.ok());
      estimators.push_back(std::move(*e));
    }
    SourceConfig config;
    config.realtime = realtime;
    config.fps = fps;
    config.queue_capacity = threads + 1;
    config.estimate_threads = threads;
    config.warm_up = warm_up_;
    if (initial != nullptr) {
      config.has_initial_pose = true;
      config.initial_pose = *initial;
    }
    return std::make_unique<PosePipeline>(std::move(*source), std::move(estimators), config);
  }

  // Follows the published estimates until the pipeline has ended (or 120 s pass); returns the
  // frame sequence numbers seen, in publishing order.
  static std::vector<std::uint64_t> Follow(PosePipeline* pipeline) {
    std::vector<std::uint64_t> seen;
    for (const auto& e : FollowEstimates(pipeline)) seen.push_back(e->sequence);
    return seen;
  }

  // The same, returning the estimates seen.
  static std::vector<std::shared_ptr<const PublishedEstimate>> FollowEstimates(
      PosePipeline* pipeline) {
    std::vector<std::shared_ptr<const PublishedEstimate>> seen;
    std::uint64_t last_id = 0;
    const Clock::time_point give_up = Clock::now() + std::chrono::seconds(120);
    for (;;) {
      const bool ended = pipeline->Ended();  // before looking: it then ended with what we see.
      auto e = pipeline->WaitNewer(last_id, Clock::now() + std::chrono::milliseconds(200));
      if (e && e->publish_id > last_id) {
        last_id = e->publish_id;
        seen.push_back(e);
        continue;
      }
      if (ended || Clock::now() >= give_up) break;
    }
    EXPECT_TRUE(pipeline->Ended());
    return seen;
  }

  std::string dir_;
  bool warm_up_ = true;  // SourceConfig::warm_up of the pipelines made.
};

TEST_F(PipelineThreadsTest, FastReplayPublishesEveryFrameInOrder) {
  std::unique_ptr<PosePipeline> pipeline = MakePipeline(/*realtime=*/false, 30.0, 2);
  pipeline->Start();
  const std::vector<std::uint64_t> seen = Follow(pipeline.get());
  const PipelineStatus s = pipeline->Status();
  pipeline->Stop();
  EXPECT_EQ(s.frames_in, static_cast<std::uint64_t>(kFrames));
  EXPECT_EQ(s.frames_dropped, 0u);
  EXPECT_EQ(s.frames_estimated + s.frames_failed, static_cast<std::uint64_t>(kFrames));
  ASSERT_FALSE(seen.empty());
  for (size_t i = 1; i < seen.size(); ++i) EXPECT_LT(seen[i - 1], seen[i]);
  const std::shared_ptr<const PublishedEstimate> latest = pipeline->Latest();
  ASSERT_NE(latest, nullptr);
  EXPECT_EQ(latest->publish_id, static_cast<std::uint64_t>(kFrames));
  EXPECT_EQ(latest->sequence, seen.back());
  EXPECT_EQ(latest->sequence, static_cast<std::uint64_t>(kFrames));
  EXPECT_GE(latest->latency_s, latest->queue_s);
}

// Stopped while the recording plays: not ended (a stream on it would be told the daemon is
// shutting down, not that the source ended).
TEST_F(PipelineThreadsTest, StoppingIsNotEnding) {
  std::unique_ptr<PosePipeline> pipeline = MakePipeline(/*realtime=*/true, 1.0, 2);
  pipeline->Start();
  EXPECT_NE(pipeline->WaitNewer(0, Clock::now() + std::chrono::seconds(120)), nullptr);
  pipeline->Stop();
  EXPECT_FALSE(pipeline->Ended());
  EXPECT_LT(pipeline->Status().frames_in, static_cast<std::uint64_t>(kFrames));
}

TEST_F(PipelineThreadsTest, PacedReplayNeverPublishesAnOlderFrameAfterANewerOne) {
  // Faster than the estimators: frames are dropped, the published ones stay in order.
  std::unique_ptr<PosePipeline> pipeline = MakePipeline(/*realtime=*/true, 100.0, 2);
  pipeline->Start();
  const std::vector<std::uint64_t> seen = Follow(pipeline.get());
  const PipelineStatus s = pipeline->Status();
  pipeline->Stop();
  EXPECT_EQ(s.frames_in, static_cast<std::uint64_t>(kFrames));
  EXPECT_EQ(s.frames_estimated + s.frames_failed + s.frames_dropped,
            static_cast<std::uint64_t>(kFrames));
  ASSERT_FALSE(seen.empty());
  for (size_t i = 1; i < seen.size(); ++i) EXPECT_LT(seen[i - 1], seen[i]);
}

// A robot too far to pass the score threshold cold (3.5 m from a sensor 0.9 m high looking 20
// degrees down, one score threshold at every range: the far clusters' lower one would find it):
// found in every frame when the config says where it starts, in none without.
TEST_F(PipelineThreadsTest, AnInitialPoseFindsAFarRobotInEveryFrame) {
  const std::string far = testing_util::MakeTempDir("pipeline_far");
  ASSERT_FALSE(far.empty());
  constexpr int kFarFrames = 3;
  ASSERT_TRUE(testing_util::SimulateFrames(
      far, kFarFrames,
      "--x 3.5 --theta-deg 60 --sensor-height 0.9 --pitch-deg 20 --clutter 3 --seed 4"));
  const Pose2D start{3.5, 0.0, DegToRad(60.0)};
  for (const bool given : {false, true}) {
    std::unique_ptr<PosePipeline> pipeline =
        MakePipeline(/*realtime=*/false, 30.0, 1, far, given ? &start : nullptr,
                     /*one_threshold=*/true);
    pipeline->Start();
    const auto seen = FollowEstimates(pipeline.get());
    const PipelineStatus s = pipeline->Status();
    pipeline->Stop();
    // Every frame estimated; the follower sees the latest whenever it looks (the last always).
    EXPECT_EQ(s.frames_estimated, static_cast<std::uint64_t>(kFarFrames)) << given;
    ASSERT_FALSE(seen.empty()) << given;
    for (const auto& e : seen) {
      ASSERT_TRUE(e->ok) << e->error.message;
      const std::vector<Detection> humans = e->estimate.Humanoids();
      if (!given) {
        EXPECT_TRUE(humans.empty()) << "frame " << e->sequence;
        continue;
      }
      ASSERT_EQ(humans.size(), 1u) << "frame " << e->sequence;
      const Pose2D& p = humans.front().best.pose;
      EXPECT_LT(std::hypot(p.x - 3.5, p.y), 0.05) << "frame " << e->sequence;
    }
  }
  std::filesystem::remove_all(far);
}

// The warm-up estimate before the stream leaves nothing behind: a tracked replay gives the same
// estimate of every frame, tracked alike, with and without it; only the status tells them apart.
// Every frame is estimated in both runs; the follower sees the latest estimate whenever it looks,
// so on a busy machine it may miss one published right after another: the frames both runs'
// followers saw are compared.
TEST_F(PipelineThreadsTest, WarmingUpChangesNoEstimate) {
  std::map<std::uint64_t, std::shared_ptr<const PublishedEstimate>> seen[2];
  for (const bool warm : {false, true}) {
    warm_up_ = warm;
    std::unique_ptr<PosePipeline> pipeline = MakePipeline(/*realtime=*/false, 30.0, 1);
    pipeline->Start();
    for (const auto& e : FollowEstimates(pipeline.get())) seen[warm][e->sequence] = e;
    const PipelineStatus s = pipeline->Status();
    pipeline->Stop();
    EXPECT_EQ(s.frames_in, static_cast<std::uint64_t>(kFrames));
    EXPECT_EQ(s.frames_estimated + s.frames_failed, static_cast<std::uint64_t>(kFrames));
    EXPECT_EQ(s.warmed_up, warm);
    if (warm) {
      EXPECT_GT(s.warm_up_ms, 0.0);
    } else {
      EXPECT_EQ(s.warm_up_ms, 0.0);
    }
  }
  int compared = 0, humanoids = 0, tracked = 0;
  for (const auto& [sequence, seen_cold] : seen[0]) {
    const auto found = seen[1].find(sequence);
    if (found == seen[1].end()) continue;
    ++compared;
    const PublishedEstimate& cold = *seen_cold;
    const PublishedEstimate& warm = *found->second;
    ASSERT_EQ(cold.ok, warm.ok) << "frame " << sequence;
    if (!cold.ok) continue;
    EXPECT_EQ(cold.estimate.tracking.tracked, warm.estimate.tracking.tracked) << sequence;
    EXPECT_EQ(cold.estimate.tracking.floor_reused, warm.estimate.tracking.floor_reused);
    tracked += warm.estimate.tracking.tracked ? 1 : 0;
    EXPECT_EQ(cold.estimate.floor.ground_from_sensor.matrix(),
              warm.estimate.floor.ground_from_sensor.matrix())
        << "frame " << sequence;
    ASSERT_EQ(cold.estimate.candidates.size(), warm.estimate.candidates.size());
    for (size_t c = 0; c < cold.estimate.candidates.size(); ++c) {
      const Candidate& a = cold.estimate.candidates[c];
      const Candidate& b = warm.estimate.candidates[c];
      EXPECT_EQ(a.template_name, b.template_name) << "frame " << sequence;
      EXPECT_EQ(a.score, b.score) << "frame " << sequence;
      EXPECT_EQ(a.pose.x, b.pose.x) << "frame " << sequence;
      EXPECT_EQ(a.pose.y, b.pose.y) << "frame " << sequence;
      EXPECT_EQ(a.pose.theta, b.pose.theta) << "frame " << sequence;
      EXPECT_EQ(a.heading_confirmed, b.heading_confirmed) << "frame " << sequence;
    }
    humanoids += static_cast<int>(warm.estimate.Humanoids().size());
  }
  // The frames hold a robot and most are tracked: the comparison says something.
  EXPECT_GE(compared, kFrames - 2);
  EXPECT_GE(humanoids, compared - 1);
  EXPECT_GE(tracked, compared - 2);
}

// Stopped while its estimators warm up: Stop returns (the capture thread waiting for them is
// woken), and no frame was read before they had warmed up.
TEST_F(PipelineThreadsTest, StopsWhileWarmingUp) {
  std::unique_ptr<PosePipeline> pipeline = MakePipeline(/*realtime=*/false, 30.0, 2);
  pipeline->Start();
  pipeline->Stop();
  const PipelineStatus s = pipeline->Status();
  if (!s.warmed_up) EXPECT_EQ(s.frames_in, 0u);
  EXPECT_FALSE(pipeline->Ended());
}

}  // namespace
}  // namespace hpose::server
