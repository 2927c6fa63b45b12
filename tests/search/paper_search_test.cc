#include "core/search/exact_search.h"
#include "core/search/pose_search.h"

#include <gtest/gtest.h>

#include "core/scoring/fast_scorer.h"
#include "tests/search/search_test_scenes.h"

namespace hpose {
namespace {

TEST(PaperSearchTest, EvaluatesTheTable1PoseCountAndNeverBeatsExact) {
  const PoseLattice lattice;
  for (unsigned scene = 0; scene < 4; ++scene) {
    const std::vector<Eigen::Vector3f> robot = testing::RandomRobotPoints(300 + scene);
    const VoxelTemplate tpl = *MakeTemplateFromPoints(robot, "t", lattice.resolution_m);
    const Pose2D truth{1.0, 0.1 * scene, DegToRad(40.0 * scene)};
    const std::vector<Eigen::Vector3f> pts = testing::VisibleCluster(robot, truth, 0.003f, scene);
    const ClusterVoxels cluster = VoxeliseCluster(pts, lattice.resolution_m);
    Eigen::Vector2d centroid = Eigen::Vector2d::Zero();
    for (const auto& p : pts) centroid += p.head<2>().cast<double>();
    centroid /= pts.size();
    const TemplateRotations rot(tpl, lattice);
    const FastScorer scorer(cluster, lattice);
    const SearchProblem problem{&cluster, &scorer, &rot, centroid};
    const SearchResult paper = PaperSearch().Search(problem);
    // Table 1: 72 angles x 17 x 17 translations, then 5 x 9 x 9.
    EXPECT_EQ(paper.poses_evaluated, 72 * 17 * 17 + 5 * 9 * 9);
    EXPECT_EQ(scorer.Hits(rot.Get(paper.best.itheta), paper.best.ix, paper.best.iy), paper.hits);
    const SearchResult exact = ExactSearch().Search(problem);
    EXPECT_LE(paper.hits, exact.hits);
    EXPECT_GT(paper.score, 0.0);
  }
}

}  // namespace
}  // namespace hpose
