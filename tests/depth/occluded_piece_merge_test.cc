#include "core/depth/occluded_piece_merge.h"

#include <random>

#include <gtest/gtest.h>

namespace hpose {
namespace {

// The sensor 0.34 m above the ground origin, looking along +x.
const Eigen::Vector3f kSensor(0.0f, 0.0f, 0.34f);

// A vertical slab of points facing the sensor.
Cluster Slab(float x, float y_lo, float y_hi, float z_lo, float z_hi) {
  Cluster c;
  for (float y = y_lo; y <= y_hi + 1e-4f; y += 0.01f)
    for (float z = z_lo; z <= z_hi + 1e-4f; z += 0.01f) c.points.emplace_back(x, y, z);
  return c;
}

// A body 1 m away, its top 0.40 m high (0.06 rad above the sensor's horizon), and an arm raised
// behind it at distance x: the part of the arm the sensor sees starts just above the body's top
// edge in the image (the rest is hidden behind the body).
Cluster ArmBehind(float x, float y_lo = -0.02f, float y_hi = 0.02f) {
  const float z_visible = 0.34f + x * 0.0605f;
  return Slab(x, y_lo, y_hi, z_visible, z_visible + 0.09f);
}

Cluster Body() { return Slab(1.0f, -0.07f, 0.07f, 0.05f, 0.40f); }

TEST(MergeOccludedPiecesTest, MergesALimbBehindTheBodysSilhouette) {
  std::vector<Cluster> clusters = {Body(), ArmBehind(1.15f)};
  const size_t total = clusters[0].points.size() + clusters[1].points.size();
  MergeOccludedPieces(kSensor, {}, &clusters);
  ASSERT_EQ(clusters.size(), 1u);
  EXPECT_EQ(clusters[0].points.size(), total);
  // The order of the pieces does not matter: the body keeps its place and takes the arm.
  std::vector<Cluster> reversed = {ArmBehind(1.15f), Body(), Slab(2.0f, 0.5f, 0.7f, 0.05f, 0.3f)};
  MergeOccludedPieces(kSensor, {}, &reversed);
  ASSERT_EQ(reversed.size(), 2u);
  EXPECT_EQ(reversed[0].points.size(), total);
}

TEST(MergeOccludedPiecesTest, KeepsPiecesFarBehindApartInTheImageOrInFrontOrLarge) {
  // 45 cm behind: farther than a body is deep.
  std::vector<Cluster> far = {Body(), ArmBehind(1.45f)};
  MergeOccludedPieces(kSensor, {}, &far);
  EXPECT_EQ(far.size(), 2u);
  // Behind, but beside the body in the image (0.17 rad of bearing away).
  std::vector<Cluster> beside = {Body(), ArmBehind(1.15f, 0.18f, 0.22f)};
  MergeOccludedPieces(kSensor, {}, &beside);
  EXPECT_EQ(beside.size(), 2u);
  // A piece in front of the cluster does not hide behind it.
  std::vector<Cluster> in_front = {Slab(1.15f, -0.07f, 0.07f, 0.05f, 0.40f),
                                   Slab(1.0f, -0.02f, 0.02f, 0.41f, 0.50f)};
  MergeOccludedPieces(kSensor, {}, &in_front);
  EXPECT_EQ(in_front.size(), 2u);
  // A second object behind the first, with more than half its points: not a limb.
  std::vector<Cluster> large = {Body(), ArmBehind(1.15f, -0.07f, 0.07f)};
  large[1].points.insert(large[1].points.end(), large[0].points.begin(), large[0].points.end());
  for (size_t i = large[1].points.size() / 2; i < large[1].points.size(); ++i)
    large[1].points[i].x() = 1.3f;
  MergeOccludedPieces(kSensor, {}, &large);
  EXPECT_EQ(large.size(), 2u);
  // Disabled.
  OccludedPieceOptions off;
  off.max_depth_gap_m = 0.0;
  std::vector<Cluster> arm = {Body(), ArmBehind(1.15f)};
  MergeOccludedPieces(kSensor, off, &arm);
  EXPECT_EQ(arm.size(), 2u);
}

TEST(MergeOccludedPiecesTest, KeepsAnObjectStandingBehindTheBodyApart) {
  // A box 0.2 m behind the body, on the floor, seen beside its right edge in the image: a
  // neighbour behind the silhouette, small enough, near enough, but standing where the body
  // stands (its lowest point as low as the body's) and no higher than the body's lower half.
  const Cluster box = Slab(1.2f, 0.085f, 0.25f, 0.05f, 0.15f);
  std::vector<Cluster> standing = {Body(), box};
  MergeOccludedPieces(kSensor, {}, &standing);
  EXPECT_EQ(standing.size(), 2u);
  // Without the rule (min_lift_m 0, as before) it merged as a hidden limb would.
  OccludedPieceOptions any_piece;
  any_piece.min_lift_m = 0.0;
  std::vector<Cluster> merged = {Body(), box};
  MergeOccludedPieces(kSensor, any_piece, &merged);
  EXPECT_EQ(merged.size(), 1u);
  // The same box lifted off the floor by the rule's margin (a limb hanging from a hidden
  // joint) merges again; lifted by less it does not.
  OccludedPieceOptions o;
  std::vector<Cluster> lifted = {Body(), Slab(1.2f, 0.085f, 0.25f, 0.11f, 0.21f)};
  MergeOccludedPieces(kSensor, o, &lifted);
  EXPECT_EQ(lifted.size(), 1u);
  std::vector<Cluster> low = {Body(), Slab(1.2f, 0.085f, 0.25f, 0.08f, 0.18f)};
  MergeOccludedPieces(kSensor, o, &low);
  EXPECT_EQ(low.size(), 2u);
  // A piece from the floor up into the body's upper half (a far foot and the arm above it,
  // joined along the line of sight before) is still a limb: it merges.
  std::vector<Cluster> tall = {Body(), Slab(1.2f, 0.085f, 0.12f, 0.05f, 0.30f)};
  const size_t tall_total = tall[0].points.size() + tall[1].points.size();
  ASSERT_LE(tall[1].points.size(), tall[0].points.size() / 2);
  MergeOccludedPieces(kSensor, o, &tall);
  ASSERT_EQ(tall.size(), 1u);
  EXPECT_EQ(tall[0].points.size(), tall_total);
}

TEST(MergeOccludedPiecesTest, MergesChainsAndIgnoresEmptyOrDegenerateInput) {
  // A hand behind the arm behind the body: both join the body.
  Cluster hand =
      Slab(1.25f, -0.01f, 0.01f, 0.34f + 1.25f * 0.1345f, 0.34f + 1.25f * 0.1345f + 0.03f);
  std::vector<Cluster> chain = {Body(), ArmBehind(1.15f), hand};
  MergeOccludedPieces(kSensor, {}, &chain);
  EXPECT_EQ(chain.size(), 1u);
  std::vector<Cluster> none;
  MergeOccludedPieces(kSensor, {}, &none);
  EXPECT_TRUE(none.empty());
  // A point at the sensor itself has no direction: skipped, nothing else changes.
  std::vector<Cluster> odd = {Body(), Cluster{}};
  odd[1].points.push_back(kSensor);
  MergeOccludedPieces(kSensor, {}, &odd);
  EXPECT_EQ(odd.size(), 2u);
}

// Screening pairs by their boxes merges exactly what searching every cluster's points does:
// random scenes of bodies and pieces around, behind and beside them (some near enough to merge,
// some just too far), with the default depth gap and a short one, with and without the screen.
TEST(MergeOccludedPiecesTest, ScreenedByBoxesMergesWhatTheFullSearchMerges) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  int merged_scenes = 0, kept_scenes = 0;
  for (int scene = 0; scene < 80; ++scene) {
    // Every other scene with a short depth gap and its pieces close behind: there the
    // neighbour angle, not the gap, makes most of the screen's reach.
    const bool short_gap = scene % 2 == 1;
    OccludedPieceOptions options;
    if (short_gap) options.max_depth_gap_m = 0.03;
    std::vector<Cluster> clusters;
    const int bodies = 1 + scene % 3;
    for (int k = 0; k < bodies; ++k) {
      const float x = 0.8f + 2.5f * u(rng), y = -1.0f + 2.0f * u(rng);
      clusters.push_back(Slab(x, y - 0.07f, y + 0.07f, 0.05f, 0.40f));
      // Pieces behind its top edge in the image, at depths up to 0.45 m behind, some beside it.
      const int pieces = static_cast<int>(3 * u(rng));
      for (int j = 0; j < pieces; ++j) {
        const float behind = x + (short_gap ? 0.005f + 0.05f * u(rng) : 0.05f + 0.4f * u(rng));
        const float bearing = (y + (u(rng) - 0.5f) * 0.4f) / x;
        const float z = 0.34f + behind * (0.06f / x) * (1.0f + 0.2f * (u(rng) - 0.5f));
        clusters.push_back(Slab(behind, bearing * behind - 0.02f, bearing * behind + 0.02f,
                                z - 0.01f, z + 0.06f + 0.05f * u(rng)));
      }
    }
    // Small debris anywhere.
    for (int j = 0; j < 4; ++j) {
      const float x = 0.6f + 3.0f * u(rng), y = -1.5f + 3.0f * u(rng), z = 0.5f * u(rng);
      clusters.push_back(Slab(x, y, y + 0.02f, z, z + 0.02f));
    }
    std::shuffle(clusters.begin(), clusters.end(), rng);
    std::vector<Cluster> screened = clusters, full = clusters;
    OccludedPieceOptions reference = options;
    reference.screen_by_boxes = false;
    MergeOccludedPieces(kSensor, options, &screened);
    MergeOccludedPieces(kSensor, reference, &full);
    ASSERT_EQ(screened.size(), full.size()) << "scene " << scene;
    for (size_t c = 0; c < full.size(); ++c) {
      EXPECT_EQ(screened[c].points, full[c].points) << "scene " << scene << " cluster " << c;
    }
    (full.size() < clusters.size() ? merged_scenes : kept_scenes) += 1;
  }
  // Both kinds of scene occur: some merges, some not.
  EXPECT_GT(merged_scenes, 5);
  EXPECT_GT(kept_scenes, 5);
}

}  // namespace
}  // namespace hpose
