// End to end: simulate a humanoid at a known pose, estimate it, and the pose comes back within
// the paper's accuracy (SPEC §1: standing, theta -3..+6 deg, x -30..-14 mm, y -7..+19 mm; we ask
// for |theta| <= 6 deg and position within 30 mm).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <tuple>
#include <vector>

#include <gtest/gtest.h>

#include "core/search/estimator.h"
#include "core/search/surface_model.h"
#include "core/search/template_models.h"
#include "core/sim/frame_simulator.h"
#include "core/sim/humanoid_model.h"
#include "tests/search/model_templates.h"

namespace hpose {
namespace {

using testing::ModelTemplate;

// Two estimators' i-th candidates are the same: template, cluster, lattice and refined pose,
// scores and fit.
void ExpectSameCandidate(const Candidate& x, const Candidate& y, size_t i) {
  EXPECT_EQ(x.template_name, y.template_name) << i;
  EXPECT_EQ(x.cluster_index, y.cluster_index) << i;
  EXPECT_EQ(x.lattice_pose.x, y.lattice_pose.x) << i;
  EXPECT_EQ(x.lattice_pose.y, y.lattice_pose.y) << i;
  EXPECT_EQ(x.lattice_pose.theta, y.lattice_pose.theta) << i;
  EXPECT_EQ(x.pose.x, y.pose.x) << i;
  EXPECT_EQ(x.pose.y, y.pose.y) << i;
  EXPECT_EQ(x.pose.theta, y.pose.theta) << i;
  EXPECT_EQ(x.score, y.score) << i;
  EXPECT_EQ(x.runner_up_score, y.runner_up_score) << i;
  EXPECT_EQ(x.fit.fit, y.fit.fit) << i;
}

// A frame with clutter: several clusters, both templates searched.
FrameSpec ClutteredSpec() {
  FrameSpec spec;
  spec.preset = "right_arm_raised";
  spec.humanoid_pose = Pose2D{1.5, 0.2, DegToRad(120.0)};
  spec.clutter = 4;
  spec.seed = 3;
  return spec;
}

class RoundTripTest : public ::testing::TestWithParam<std::tuple<SearchKind, double, double>> {};

TEST_P(RoundTripTest, PoseComesBackWithinThePapersAccuracy) {
  const auto [kind, distance, theta_deg] = GetParam();
  EstimatorOptions options = DefaultEstimatorOptions();
  options.search = kind;
  auto estimator = std::move(Estimator::Create(options, {ModelTemplate("standing")}).value());
  FrameSpec spec;
  spec.humanoid_pose = Pose2D{distance, 0.05, DegToRad(theta_deg)};
  spec.seed = 42;
  spec.clutter = 3;
  const SimulatedFrame frame = *SimulateFrame(spec);
  Result<Estimate> e = estimator->EstimateDepth(frame.depth, spec.intrinsics);
  ASSERT_TRUE(e.ok()) << e.error().ToString();
  EXPECT_NEAR(e->floor.height_m, 0.34, 0.02);
  const std::vector<Detection> humans = e->Humanoids();
  ASSERT_FALSE(humans.empty());
  const Candidate& c = humans.front().best;
  EXPECT_LT(std::abs(RadToDeg(AngleDiff(c.pose.theta, spec.humanoid_pose.theta))), 6.0);
  EXPECT_LT(std::hypot(c.pose.x - spec.humanoid_pose.x, c.pose.y - spec.humanoid_pose.y), 0.03);
  // The clutter is there, and none of it is taken for the humanoid.
  EXPECT_GE(e->clusters.size(), 2u);
  EXPECT_EQ(humans.size(), 1u);
}

INSTANTIATE_TEST_SUITE_P(Poses, RoundTripTest,
                         ::testing::Values(std::make_tuple(SearchKind::kExact, 1.0, 0.0),
                                           std::make_tuple(SearchKind::kExact, 1.0, -90.0),
                                           std::make_tuple(SearchKind::kExact, 1.5, 150.0),
                                           std::make_tuple(SearchKind::kExact, 2.0, 60.0),
                                           std::make_tuple(SearchKind::kPaper, 1.0, 0.0),
                                           std::make_tuple(SearchKind::kPaper, 1.0, -120.0)));

TEST(RoundTripTest, RaisedArmTellsLeftFromRight) {
  auto estimator =
      std::move(Estimator::Create(DefaultEstimatorOptions(),
                                  {ModelTemplate("standing"), ModelTemplate("right_arm_raised")})
                    .value());
  for (double theta_deg : {-60.0, 30.0}) {
    FrameSpec spec;
    spec.preset = "right_arm_raised";
    spec.humanoid_pose = Pose2D{1.2, -0.1, DegToRad(theta_deg)};
    spec.seed = 7;
    const SimulatedFrame frame = *SimulateFrame(spec);
    Result<Estimate> e = estimator->EstimateDepth(frame.depth, spec.intrinsics);
    ASSERT_TRUE(e.ok()) << e.error().ToString();
    ASSERT_FALSE(e->Humanoids().empty());
    const Detection d = e->Humanoids().front();
    EXPECT_EQ(d.best.template_name, "right_arm_raised") << theta_deg;
    EXPECT_EQ(d.second_template, "standing");
    EXPECT_GT(d.template_margin, 0.0);
  }
}

// Threads change the time, never the result: every candidate equal with 1 and 3 threads, on a
// frame with clutter (several clusters, both templates); so do search tables made at start
// (by the 3 threads) rather than on first use.
TEST(EstimatorTest, ThreadsGiveTheSameCandidates) {
  EstimatorOptions one = DefaultEstimatorOptions();
  EstimatorOptions three = one;
  three.threads = 3;
  three.make_tables_at_start = true;
  const std::vector<VoxelTemplate> tpls = {ModelTemplate("standing"),
                                           ModelTemplate("right_arm_raised")};
  auto serial = std::move(Estimator::Create(one, tpls).value());
  auto parallel = std::move(Estimator::Create(three, tpls).value());
  const FrameSpec spec = ClutteredSpec();
  const SimulatedFrame frame = *SimulateFrame(spec);
  const Estimate a = *serial->EstimateDepth(frame.depth, spec.intrinsics);
  const Estimate b = *parallel->EstimateDepth(frame.depth, spec.intrinsics);
  ASSERT_GE(a.candidates.size(), 2u);
  ASSERT_EQ(a.candidates.size(), b.candidates.size());
  for (size_t i = 0; i < a.candidates.size(); ++i) {
    ExpectSameCandidate(a.candidates[i], b.candidates[i], i);
  }
  ASSERT_EQ(a.clusters.size(), b.clusters.size());
  for (size_t i = 0; i < a.clusters.size(); ++i) {
    EXPECT_EQ(a.clusters[i].searched, b.clusters[i].searched) << i;
  }
  EstimatorOptions bad = one;
  bad.threads = -1;
  EXPECT_FALSE(Estimator::Create(bad, tpls).ok());
  // Cloud options that every frame would refuse are refused when the estimator is made.
  bad = one;
  bad.cloud.stride = 0;
  const Result<std::unique_ptr<Estimator>> no_stride = Estimator::Create(bad, tpls);
  ASSERT_FALSE(no_stride.ok());
  EXPECT_NE(no_stride.error().message.find("stride 0 must be >= 1"), std::string::npos);
  bad = one;
  bad.cloud.min_range_m = 5.0;
  bad.cloud.max_range_m = 1.0;
  const Result<std::unique_ptr<Estimator>> no_range = Estimator::Create(bad, tpls);
  ASSERT_FALSE(no_range.ok());
  EXPECT_NE(no_range.error().message.find("min_range_m < max_range_m"), std::string::npos);
}

// Estimators made with another's models() share each template's rotations (and so the search
// tables, made once: here at start by the second, on three threads, for the first too) and
// surface where they were made alike, and estimate exactly as estimators with their own; a
// different lattice, surface spacing or template under the same name makes its own.
TEST(EstimatorTest, SharedTemplateModelsGiveTheSameCandidates) {
  EstimatorOptions one = DefaultEstimatorOptions();
  const std::vector<VoxelTemplate> tpls = {ModelTemplate("standing"),
                                           ModelTemplate("right_arm_raised")};
  auto own = std::move(Estimator::Create(one, tpls).value());
  auto first = std::move(Estimator::Create(one, tpls).value());
  EstimatorOptions three = one;
  three.threads = 3;
  three.make_tables_at_start = true;
  auto sharing = std::move(Estimator::Create(three, tpls, first->models()).value());
  const std::vector<TemplateModels> a = first->models(), b = sharing->models();
  ASSERT_EQ(a.size(), 2u);
  ASSERT_EQ(b.size(), 2u);
  for (size_t j = 0; j < 2; ++j) {
    EXPECT_EQ(a[j].rotations.get(), b[j].rotations.get()) << j;
    EXPECT_EQ(a[j].surface.get(), b[j].surface.get()) << j;
    EXPECT_NE(own->models()[j].rotations.get(), a[j].rotations.get()) << j;
  }
  const FrameSpec spec = ClutteredSpec();
  const SimulatedFrame frame = *SimulateFrame(spec);
  const Estimate reference = *own->EstimateDepth(frame.depth, spec.intrinsics);
  ASSERT_GE(reference.candidates.size(), 2u);
  for (const Estimator* e : {first.get(), sharing.get()}) {
    const Estimate got = *e->EstimateDepth(frame.depth, spec.intrinsics);
    ASSERT_EQ(got.candidates.size(), reference.candidates.size());
    for (size_t i = 0; i < got.candidates.size(); ++i) {
      ExpectSameCandidate(got.candidates[i], reference.candidates[i], i);
    }
  }

  // A subset shares its template's models.
  auto subset = std::move(Estimator::Create(one, {tpls[1]}, first->models()).value());
  EXPECT_EQ(subset->models()[0].rotations.get(), a[1].rotations.get());
  // Made otherwise, or another template under the name: its own.
  EstimatorOptions coarse = one;
  coarse.lattice.angle_steps = 180;
  EstimatorOptions spaced = one;
  spaced.refine.surface_spacing_m = 2.0 * one.refine.surface_spacing_m + 0.001;
  VoxelTemplate impostor = tpls[1];
  impostor.name = "standing";
  auto e1 = std::move(Estimator::Create(coarse, tpls, first->models()).value());
  auto e2 = std::move(Estimator::Create(spaced, tpls, first->models()).value());
  auto e3 = std::move(Estimator::Create(one, {impostor}, first->models()).value());
  EXPECT_NE(e1->models()[0].rotations.get(), a[0].rotations.get());
  EXPECT_EQ(e1->models()[0].rotations->lattice().angle_steps, 180);
  EXPECT_NE(e2->models()[0].surface.get(), a[0].surface.get());
  EXPECT_NE(e3->models()[0].rotations.get(), a[0].rotations.get());
  EXPECT_EQ(e3->models()[0].rotations->voxels(), tpls[1].voxels.size());
  EXPECT_TRUE(e1->EstimateDepth(frame.depth, spec.intrinsics).ok());
}

// A humanoid taller than 64 voxels (1.23 m) is searched slab by slab: found where it stands, with
// the same candidates as the search of its two-word columns (slabs off), and its tables made
// at start as the daemon makes them.
TEST(RoundTripTest, TallHumanoidIsFoundSlabBySlabAsWithoutSlabs) {
  const std::vector<VoxelTemplate> tpls = {ModelTemplate("standing", "tall"),
                                           ModelTemplate("right_arm_raised", "tall")};
  // Searched at its own 16 mm (by default a body this tall is searched on coarser voxels).
  EstimatorOptions options = DefaultEstimatorOptions();
  options.max_height_voxels = 0;
  options.make_tables_at_start = true;
  options.threads = 2;
  EstimatorOptions no_slabs = options;
  no_slabs.make_tables_at_start = false;
  no_slabs.threads = 1;
  no_slabs.exact.slabs = false;
  auto slabs = std::move(Estimator::Create(options, tpls).value());
  auto columns = std::move(Estimator::Create(no_slabs, tpls).value());
  FrameSpec spec;
  spec.body = "tall";
  spec.preset = "right_arm_raised";
  spec.humanoid_pose = Pose2D{1.6, 0.1, DegToRad(40.0)};
  spec.sensor_height_m = 0.9;
  spec.sensor_pitch_rad = DegToRad(20.0);
  spec.clutter = 2;
  spec.seed = 5;
  const SimulatedFrame frame = *SimulateFrame(spec);
  const Estimate a = *slabs->EstimateDepth(frame.depth, spec.intrinsics);
  const Estimate b = *columns->EstimateDepth(frame.depth, spec.intrinsics);
  const std::vector<Detection> humans = a.Humanoids();
  ASSERT_FALSE(humans.empty());
  const Candidate& c = humans.front().best;
  EXPECT_EQ(c.template_name, "right_arm_raised");
  EXPECT_LT(std::abs(RadToDeg(AngleDiff(c.pose.theta, spec.humanoid_pose.theta))), 3.0);
  EXPECT_LT(std::hypot(c.pose.x - spec.humanoid_pose.x, c.pose.y - spec.humanoid_pose.y), 0.02);
  ASSERT_EQ(a.candidates.size(), b.candidates.size());
  std::int64_t bounds_a = 0, bounds_b = 0;
  for (size_t i = 0; i < a.candidates.size(); ++i) {
    ExpectSameCandidate(a.candidates[i], b.candidates[i], i);
    bounds_a += a.candidates[i].bounds_evaluated;
    bounds_b += b.candidates[i].bounds_evaluated;
  }
  // The slabs' cell tables and swept bounds are what make them pay.
  EXPECT_LT(bounds_a, bounds_b);
  EXPECT_EQ(slabs->options().lattice.resolution_m, 0.016);
}

// Two estimates have the same results whatever bounds their searches took: the same searches
// (cluster, template), those that stopped below the threshold alike, and every optimum, runner-up
// and refined pose of the others the same. (A stopped search's best evaluated pose and bound
// depend on the blocks it opened, so they are not compared.)
void ExpectSameResults(const Estimate& a, const Estimate& b) {
  const auto sorted = [](const Estimate& e) {
    std::vector<const Candidate*> out;
    for (const Candidate& c : e.candidates) out.push_back(&c);
    std::sort(out.begin(), out.end(), [](const Candidate* x, const Candidate* y) {
      return std::tie(x->cluster_index, x->template_name) <
             std::tie(y->cluster_index, y->template_name);
    });
    return out;
  };
  const std::vector<const Candidate*> x = sorted(a), y = sorted(b);
  ASSERT_EQ(x.size(), y.size());
  for (size_t i = 0; i < x.size(); ++i) {
    EXPECT_EQ(x[i]->cluster_index, y[i]->cluster_index) << i;
    EXPECT_EQ(x[i]->template_name, y[i]->template_name) << i;
    EXPECT_EQ(x[i]->stopped_below_threshold, y[i]->stopped_below_threshold) << i;
    EXPECT_EQ(x[i]->has_runner_up, y[i]->has_runner_up) << i;
    if (x[i]->stopped_below_threshold) continue;
    EXPECT_EQ(x[i]->lattice_pose.x, y[i]->lattice_pose.x) << i;
    EXPECT_EQ(x[i]->lattice_pose.y, y[i]->lattice_pose.y) << i;
    EXPECT_EQ(x[i]->lattice_pose.theta, y[i]->lattice_pose.theta) << i;
    EXPECT_EQ(x[i]->pose.x, y[i]->pose.x) << i;
    EXPECT_EQ(x[i]->pose.y, y[i]->pose.y) << i;
    EXPECT_EQ(x[i]->pose.theta, y[i]->pose.theta) << i;
    EXPECT_EQ(x[i]->score, y[i]->score) << i;
    EXPECT_EQ(x[i]->hits, y[i]->hits) << i;
    EXPECT_EQ(x[i]->free_space_hits, y[i]->free_space_hits) << i;
    EXPECT_EQ(x[i]->fit.fit, y[i]->fit.fit) << i;
    if (!x[i]->has_runner_up) continue;
    EXPECT_EQ(x[i]->runner_up_pose.x, y[i]->runner_up_pose.x) << i;
    EXPECT_EQ(x[i]->runner_up_pose.y, y[i]->runner_up_pose.y) << i;
    EXPECT_EQ(x[i]->runner_up_pose.theta, y[i]->runner_up_pose.theta) << i;
    EXPECT_EQ(x[i]->runner_up_score, y[i]->runner_up_score) << i;
  }
}

// A sensor high up and looking steeply down cuts the humanoid and the clutter at the top of the
// image, so the searches see low clusters the templates cover from many poses: the theta blocks'
// free part over pairs of steps refutes blocks the hits alone leave open. The same results as
// without it, with fewer bounds.
TEST(RoundTripTest, CutViewsTakeFewerBoundsForTheSameCandidates) {
  const std::vector<VoxelTemplate> tpls = {ModelTemplate("standing"),
                                           ModelTemplate("right_arm_raised")};
  EstimatorOptions options = DefaultEstimatorOptions();
  options.threads = 1;
  EstimatorOptions before = options;
  before.exact.theta_block_pair_free_part = false;
  auto with_pairs = std::move(Estimator::Create(options, tpls).value());
  auto without = std::move(Estimator::Create(before, tpls).value());
  std::int64_t bounds_with = 0, bounds_without = 0;
  size_t searches = 0;
  for (const int seed : {3, 8}) {
    FrameSpec spec;
    spec.preset = "standing";
    spec.humanoid_pose = Pose2D{1.1 + 0.1 * seed, 0.1, DegToRad(25.0 * seed)};
    spec.sensor_height_m = 0.7;
    spec.sensor_pitch_rad = DegToRad(35.0);
    spec.clutter = 4;
    spec.seed = seed;
    const SimulatedFrame frame = *SimulateFrame(spec);
    const Estimate a = *with_pairs->EstimateDepth(frame.depth, spec.intrinsics);
    const Estimate b = *without->EstimateDepth(frame.depth, spec.intrinsics);
    {
      SCOPED_TRACE("seed " + std::to_string(seed));
      ExpectSameResults(a, b);
    }
    for (const Candidate& c : a.candidates) bounds_with += c.bounds_evaluated;
    for (const Candidate& c : b.candidates) bounds_without += c.bounds_evaluated;
    searches += a.candidates.size();
  }
  EXPECT_GE(searches, 4u);
  EXPECT_LT(bounds_with, bounds_without);
}

// By default a body taller than max_height_voxels (48) voxels is searched on coarser voxels:
// the 1.23 m humanoid's tallest template (1.33 m with its arm raised, 83 voxels of 16 mm) at
// 28 mm, one slab. The templates are voxelised again from their surface points, the refinement
// still fits their own 16 mm surface, and the humanoid is found as accurately.
TEST(RoundTripTest, TallHumanoidIsSearchedOnCoarserVoxels) {
  const std::vector<VoxelTemplate> tpls = {ModelTemplate("standing", "tall"),
                                           ModelTemplate("right_arm_raised", "tall")};
  ASSERT_GT(tpls[1].Height(), 48 * 0.016);
  auto coarse = std::move(Estimator::Create(DefaultEstimatorOptions(), tpls).value());
  const double edge = std::ceil(tpls[1].Height() / 48 * 1000.0 - 1e-6) / 1000.0;
  EXPECT_EQ(coarse->options().lattice.resolution_m, edge);
  EXPECT_NEAR(edge, 0.028, 1e-12);
  // What it searches: the templates voxelised again; what users gave: kept as given.
  for (size_t j = 0; j < tpls.size(); ++j) {
    const TemplateModels m = coarse->models()[j];
    EXPECT_EQ(m.lattice.resolution_m, edge);
    EXPECT_EQ(m.rotations->voxels(), VoxeliseAgain(tpls[j], edge)->voxels.size());
    EXPECT_LE(m.rotations->height_m(), 48 * edge + 1e-9);
    EXPECT_EQ(m.surface->points().size(), SurfaceModel(tpls[j]).points().size());
    EXPECT_EQ(m.surface->spacing_m(), 0.008);
    EXPECT_EQ(coarse->templates()[j].resolution_m, 0.016);
  }
  for (const double heading_deg : {40.0, -150.0}) {
    FrameSpec spec;
    spec.body = "tall";
    spec.preset = "right_arm_raised";
    spec.humanoid_pose = Pose2D{2.6, -0.2, DegToRad(heading_deg)};
    spec.sensor_height_m = 0.9;
    spec.sensor_pitch_rad = DegToRad(20.0);
    spec.clutter = 2;
    spec.seed = 6;
    const SimulatedFrame frame = *SimulateFrame(spec);
    const Estimate e = *coarse->EstimateDepth(frame.depth, spec.intrinsics);
    const std::vector<Detection> humans = e.Humanoids();
    ASSERT_FALSE(humans.empty()) << heading_deg;
    const Candidate& c = humans.front().best;
    EXPECT_EQ(c.template_name, "right_arm_raised") << heading_deg;
    EXPECT_LT(std::abs(RadToDeg(AngleDiff(c.pose.theta, spec.humanoid_pose.theta))), 2.0)
        << heading_deg;
    EXPECT_LT(std::hypot(c.pose.x - spec.humanoid_pose.x, c.pose.y - spec.humanoid_pose.y), 0.01)
        << heading_deg;
  }
}

// The search's voxel edge follows the templates: templates made at 20 mm are searched at 20 mm
// (the edge of EstimatorOptions::lattice is not theirs), templates at 16 and 20 mm at the
// coarser (the finer voxelised again). With resolution_from_templates off the lattice's edge
// holds: finer templates are voxelised again at it, a coarser one is refused by name.
TEST(EstimatorTest, SearchEdgeFollowsTheTemplates) {
  const VoxelTemplate fine = ModelTemplate("standing");
  const VoxelTemplate twenty = ModelTemplate("right_arm_raised", "nao", 0.020);
  const EstimatorOptions options = DefaultEstimatorOptions();
  ASSERT_EQ(options.lattice.resolution_m, 0.016);
  auto own = Estimator::Create(options, {twenty});
  ASSERT_TRUE(own.ok()) << own.error().ToString();
  EXPECT_EQ((*own)->options().lattice.resolution_m, 0.020);
  EXPECT_EQ((*own)->models()[0].rotations->voxels(), twenty.voxels.size());
  auto mixed = Estimator::Create(options, {fine, twenty});
  ASSERT_TRUE(mixed.ok()) << mixed.error().ToString();
  EXPECT_EQ((*mixed)->options().lattice.resolution_m, 0.020);
  EXPECT_EQ((*mixed)->models()[0].rotations->voxels(), VoxeliseAgain(fine, 0.020)->voxels.size());
  EXPECT_NE(VoxeliseAgain(fine, 0.020)->voxels.size(), fine.voxels.size());

  // The humanoid is found on the 20 mm search.
  const FrameSpec spec = ClutteredSpec();
  const SimulatedFrame frame = *SimulateFrame(spec);
  const Estimate e = *(*mixed)->EstimateDepth(frame.depth, spec.intrinsics);
  ASSERT_FALSE(e.Humanoids().empty());
  const Pose2D p = e.Humanoids().front().best.pose;
  EXPECT_LT(std::hypot(p.x - spec.humanoid_pose.x, p.y - spec.humanoid_pose.y), 0.02);

  EstimatorOptions fixed = options;
  fixed.resolution_from_templates = false;
  auto refused = Estimator::Create(fixed, {fine, twenty});
  ASSERT_FALSE(refused.ok());
  EXPECT_EQ(refused.error().code, ErrorCode::kInvalidArgument);
  EXPECT_NE(refused.error().message.find("'right_arm_raised' has voxels of 20.0 mm"),
            std::string::npos)
      << refused.error().message;
  fixed.lattice.resolution_m = 0.024;
  auto coarser = Estimator::Create(fixed, {fine, twenty});
  ASSERT_TRUE(coarser.ok()) << coarser.error().ToString();
  EXPECT_EQ((*coarser)->options().lattice.resolution_m, 0.024);
  EXPECT_EQ((*coarser)->models()[1].rotations->voxels(),
            VoxeliseAgain(twenty, 0.024)->voxels.size());

  EstimatorOptions bad = options;
  bad.max_height_voxels = 3;
  EXPECT_FALSE(Estimator::Create(bad, {fine}).ok());
}

TEST(RoundTripTest, EmptyFloorHasNoHumanoid) {
  auto estimator =
      std::move(Estimator::Create(DefaultEstimatorOptions(), {ModelTemplate("standing")}).value());
  FrameSpec spec;
  spec.humanoid_pose = Pose2D{30.0, 0.0, 0.0};  // far out of range: only the floor is seen.
  const SimulatedFrame frame = *SimulateFrame(spec);
  Result<Estimate> e = estimator->EstimateDepth(frame.depth, spec.intrinsics);
  ASSERT_TRUE(e.ok()) << e.error().ToString();
  EXPECT_TRUE(e->Humanoids().empty());
}

TEST(EstimatorTest, RejectsBadInput) {
  auto estimator =
      std::move(Estimator::Create(DefaultEstimatorOptions(), {ModelTemplate("standing")}).value());
  // Empty and all-NaN clouds.
  EXPECT_EQ(estimator->EstimateCloud(PointCloud{}).error().code, ErrorCode::kInvalidArgument);
  PointCloud nan_cloud;
  nan_cloud.points.assign(100, Eigen::Vector3f::Constant(std::nanf("")));
  Result<Estimate> r = estimator->EstimateCloud(nan_cloud);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find("NaN"), std::string::npos);
  // Intrinsics that do not match the image.
  DepthImage depth(320, 240);
  Result<Estimate> mismatch = estimator->EstimateDepth(depth, Intrinsics::KinectV1(640, 480));
  ASSERT_FALSE(mismatch.ok());
  EXPECT_EQ(mismatch.error().code, ErrorCode::kInvalidArgument);
  // No floor: a wall of points straight ahead.
  PointCloud wall;
  for (int i = 0; i < 2000; ++i)
    wall.points.emplace_back(0.001f * (i % 50), 0.001f * (i / 50), 1.0f);
  EXPECT_EQ(estimator->EstimateCloud(wall).error().code, ErrorCode::kFailedPrecondition);
}

TEST(EstimatorTest, CreateValidates) {
  EXPECT_FALSE(Estimator::Create(DefaultEstimatorOptions(), {}).ok());
  VoxelTemplate t = ModelTemplate("standing");
  EXPECT_FALSE(Estimator::Create(DefaultEstimatorOptions(), {t, t}).ok());
  // A template coarser than a fixed search edge (by default the edge follows the templates:
  // EstimatorTest.SearchEdgeFollowsTheTemplates).
  VoxelTemplate coarse = t;
  coarse.resolution_m = 0.02;
  EstimatorOptions fixed = DefaultEstimatorOptions();
  fixed.resolution_from_templates = false;
  EXPECT_FALSE(Estimator::Create(fixed, {coarse}).ok());
  fixed.lattice.resolution_m = 0.0;
  EXPECT_FALSE(Estimator::Create(fixed, {t}).ok());
}

// Floor and cluster options that every frame would refuse are refused when the estimator is made,
// naming the option; a fixed floor is checked instead of the fit's options.
TEST(EstimatorTest, CreateRefusesFloorAndClusterOptionsEveryFrameWouldRefuse) {
  const VoxelTemplate t = ModelTemplate("standing");
  auto message = [&](const EstimatorOptions& o) {
    Result<std::unique_ptr<Estimator>> e = Estimator::Create(o, {t});
    return e.ok() ? std::string("created") : e.error().message;
  };
  EstimatorOptions o = DefaultEstimatorOptions();
  ASSERT_EQ(message(o), "created");
  o.floor_fit.min_width_m = -0.1;
  EXPECT_NE(message(o).find("min_width_m"), std::string::npos) << message(o);
  o = DefaultEstimatorOptions();
  o.floor_fit.distance_threshold_m = std::numeric_limits<double>::quiet_NaN();
  EXPECT_NE(message(o).find("distance_threshold_m"), std::string::npos) << message(o);
  // With a fixed floor the fit's options are unused; the floor itself must have a ground frame.
  o.use_fixed_floor = true;
  o.fixed_floor = FloorEstimate::FromHeightPitchRoll(0.6, 0.3, 0.0);
  EXPECT_EQ(message(o), "created");
  o.fixed_floor.ground_from_sensor.linear() = Eigen::Matrix3d::Zero();
  EXPECT_NE(message(o), "created");
  o = DefaultEstimatorOptions();
  o.clusters.tolerance_m = 0.0;
  EXPECT_NE(message(o).find("tolerance_m"), std::string::npos) << message(o);
  o = DefaultEstimatorOptions();
  o.clusters.max_points = o.clusters.min_points - 1;
  EXPECT_NE(message(o).find("max_points"), std::string::npos) << message(o);
}

}  // namespace
}  // namespace hpose
