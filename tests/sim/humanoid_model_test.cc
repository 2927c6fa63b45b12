#include "core/sim/humanoid_model.h"

#include <cmath>
#include <set>
#include <tuple>

#include <gtest/gtest.h>

namespace hpose {
namespace {

using Cell = std::tuple<int, int, int>;

std::set<Cell> Voxelise(const std::vector<Eigen::Vector3f>& points, double res, bool mirror_y) {
  std::set<Cell> cells;
  for (const Eigen::Vector3f& p : points) {
    const double y = mirror_y ? -p.y() : p.y();
    cells.insert({static_cast<int>(std::floor(p.x() / res)), static_cast<int>(std::floor(y / res)),
                  static_cast<int>(std::floor(p.z() / res))});
  }
  return cells;
}

// Fraction of `a`'s cells that have a cell of `b` within one cell (26-neighbourhood).
double NearOverlap(const std::set<Cell>& a, const std::set<Cell>& b) {
  int found = 0;
  for (const auto& [x, y, z] : a) {
    bool near = false;
    for (int dx = -1; dx <= 1 && !near; ++dx) {
      for (int dy = -1; dy <= 1 && !near; ++dy) {
        for (int dz = -1; dz <= 1 && !near; ++dz) near = b.count({x + dx, y + dy, z + dz}) > 0;
      }
    }
    found += near ? 1 : 0;
  }
  return a.empty() ? 0.0 : static_cast<double>(found) / a.size();
}

const Primitive* Find(const HumanoidModel& m, const std::string& name) {
  for (const Primitive& p : m.primitives()) {
    if (p.name == name) return &p;
  }
  return nullptr;
}

TEST(HumanoidModelTest, StandingIsNaoSized) {
  const Result<HumanoidModel> model = HumanoidModel::FromPreset("standing");
  ASSERT_TRUE(model.ok()) << model.error().ToString();
  const HumanoidDimensions& d = model->dimensions();
  // Straight legs: sole, shank, thigh, hip offset, neck, head centre, head radius.
  const double expected = d.ankle_height_m + d.tibia_length_m + d.thigh_length_m +
                          d.hip_offset_z_m + d.neck_offset_z_m + d.head_centre_above_neck_m +
                          d.head_radius_m;
  EXPECT_NEAR(model->Height(), expected, 1e-9);
  EXPECT_NEAR(model->Height(), 0.58, 0.02);  // a Nao is about 0.58 m tall.
  // Width across the arms and depth of the feet are Nao-like too (0.2-0.35 m).
  EXPECT_GT(model->bounds().sizes().y(), 0.20);
  EXPECT_LT(model->bounds().sizes().y(), 0.35);
  EXPECT_GT(model->bounds().sizes().x(), 0.10);
  EXPECT_LT(model->bounds().sizes().x(), 0.25);
}

TEST(HumanoidModelTest, FeetTouchTheFloorAndOriginIsBelowTheTorso) {
  for (const std::string& preset : HumanoidJoints::PresetNames()) {
    const Result<HumanoidModel> model = HumanoidModel::FromPreset(preset);
    ASSERT_TRUE(model.ok());
    EXPECT_NEAR(model->bounds().min().z(), 0.0, 1e-9) << preset;
    for (const char* foot : {"left_foot", "right_foot"}) {
      const Primitive* p = Find(*model, foot);
      ASSERT_NE(p, nullptr) << foot;
      EXPECT_NEAR(p->Bounds().min().z(), 0.0, 1e-9) << preset << " " << foot;
    }
    const Primitive* torso = Find(*model, "torso");
    ASSERT_NE(torso, nullptr);
    EXPECT_NEAR(torso->parent_from_local.translation().x(), 0.0, 1e-12);
    EXPECT_NEAR(torso->parent_from_local.translation().y(), 0.0, 1e-12);
    EXPECT_GT(torso->parent_from_local.translation().z(), 0.2);
  }
}

TEST(HumanoidModelTest, BentKneesStillStandOnTheFloor) {
  HumanoidJoints j;
  j.left_hip_pitch_rad = j.right_hip_pitch_rad = 0.4;
  j.left_knee_rad = j.right_knee_rad = 0.8;
  j.left_ankle_pitch_rad = j.right_ankle_pitch_rad = 0.4;  // keeps the soles level.
  const Result<HumanoidModel> crouched = HumanoidModel::Create({}, j);
  const Result<HumanoidModel> standing = HumanoidModel::Create({}, {});
  ASSERT_TRUE(crouched.ok() && standing.ok());
  EXPECT_NEAR(crouched->bounds().min().z(), 0.0, 1e-9);
  // The hips drop by the legs' length times (1 - cos 0.4).
  const HumanoidDimensions& d = standing->dimensions();
  EXPECT_NEAR(standing->Height() - crouched->Height(),
              (d.thigh_length_m + d.tibia_length_m) * (1.0 - std::cos(0.4)), 1e-9);
  const Primitive* foot = Find(*crouched, "left_foot");
  ASSERT_NE(foot, nullptr);
  EXPECT_NEAR(foot->parent_from_local.linear()(2, 2), 1.0, 1e-9);  // sole level.
}

TEST(HumanoidModelTest, StandingIsLeftRightSymmetric) {
  const Result<HumanoidModel> model = HumanoidModel::FromPreset("standing");
  ASSERT_TRUE(model.ok());
  for (const Primitive& p : model->primitives()) {
    if (p.name.rfind("left_", 0) != 0) continue;
    const Primitive* mirror = Find(*model, "right_" + p.name.substr(5));
    ASSERT_NE(mirror, nullptr) << p.name;
    const Eigen::Vector3d a = p.parent_from_local.translation();
    const Eigen::Vector3d b = mirror->parent_from_local.translation();
    EXPECT_NEAR(a.x(), b.x(), 1e-9) << p.name;
    EXPECT_NEAR(a.y(), -b.y(), 1e-9) << p.name;
    EXPECT_NEAR(a.z(), b.z(), 1e-9) << p.name;
  }
  const auto points = model->SampleSurface(0.004);
  ASSERT_TRUE(points.ok());
  const auto cells = Voxelise(*points, 0.016, false);
  const auto mirrored = Voxelise(*points, 0.016, true);
  EXPECT_GT(NearOverlap(mirrored, cells), 0.99);
}

TEST(HumanoidModelTest, RightArmRaisedIsAsymmetric) {
  const Result<HumanoidModel> model = HumanoidModel::FromPreset("right_arm_raised");
  const Result<HumanoidModel> standing = HumanoidModel::FromPreset("standing");
  ASSERT_TRUE(model.ok() && standing.ok());
  const Primitive* right = Find(*model, "right_forearm");
  const Primitive* left = Find(*model, "left_forearm");
  const Primitive* head = Find(*model, "head");
  ASSERT_TRUE(right && left && head);
  // The right hand is up above the shoulders, forward of the torso; the left one hangs.
  EXPECT_GT(right->Bounds().max().z(), head->parent_from_local.translation().z());
  EXPECT_GT(right->Bounds().max().x(), 0.05);
  EXPECT_LT(right->parent_from_local.translation().y(), 0.0);
  EXPECT_LT(left->Bounds().max().z(), head->Bounds().min().z());
  EXPECT_GT(model->Height(), standing->Height());
  const auto points = model->SampleSurface(0.004);
  ASSERT_TRUE(points.ok());
  const auto cells = Voxelise(*points, 0.016, false);
  const auto mirrored = Voxelise(*points, 0.016, true);
  EXPECT_LT(NearOverlap(mirrored, cells), 0.95);
}

TEST(HumanoidModelTest, ArmsSwungSwingOneArmForwardAndTheOtherBack) {
  const Result<HumanoidModel> model = HumanoidModel::FromPreset("arms_swung");
  const Result<HumanoidModel> standing = HumanoidModel::FromPreset("standing");
  ASSERT_TRUE(model.ok() && standing.ok());
  const Primitive* left = Find(*model, "left_forearm");
  const Primitive* right = Find(*model, "right_forearm");
  const Primitive* hanging = Find(*standing, "left_forearm");
  ASSERT_TRUE(left && right && hanging);
  // Hands about 0.4 rad x the arm's 0.2 m reach ahead of and behind where they hang.
  EXPECT_GT(left->Bounds().center().x(), hanging->Bounds().center().x() + 0.05);
  EXPECT_LT(right->Bounds().center().x(), hanging->Bounds().center().x() - 0.05);
  EXPECT_NEAR(model->Height(), standing->Height(), 1e-9);  // the legs are as standing.
}

// The free limbs are the arms, neck and head: points of the surface, none on the legs or feet.
TEST(HumanoidModelTest, FreeLimbSurfaceIsTheArmsNeckAndHead) {
  for (const char* name : {"left_upper_arm", "right_forearm", "neck", "head", "ears"}) {
    EXPECT_TRUE(HumanoidModel::IsFreeLimb(name)) << name;
  }
  for (const char* name : {"torso", "battery_pack", "left_thigh", "right_shank", "left_foot"}) {
    EXPECT_FALSE(HumanoidModel::IsFreeLimb(name)) << name;
  }
  const Result<HumanoidModel> model = HumanoidModel::FromPreset("standing");
  ASSERT_TRUE(model.ok());
  const auto all = model->SampleSurface(0.004);
  const auto limbs = model->SampleFreeLimbSurface(0.004);
  ASSERT_TRUE(all.ok() && limbs.ok());
  ASSERT_GT(limbs->size(), all->size() / 5);
  ASSERT_LT(limbs->size(), all->size() / 2);
  const auto key = [](const Eigen::Vector3f& p) { return std::make_tuple(p.x(), p.y(), p.z()); };
  std::set<std::tuple<float, float, float>> surface;
  for (const Eigen::Vector3f& p : *all) surface.insert(key(p));
  const Primitive* hip = Find(*model, "left_thigh");
  ASSERT_NE(hip, nullptr);
  for (const Eigen::Vector3f& p : *limbs) {
    ASSERT_TRUE(surface.count(key(p))) << p.transpose();
    // The hands hang at mid-thigh; nothing lower than that is a free limb.
    EXPECT_GT(p.z(), hip->Bounds().min().z()) << p.transpose();
  }
  EXPECT_FALSE(model->SampleFreeLimbSurface(0.0).ok());
}

TEST(HumanoidModelTest, SurfaceSamplesAreOnTheOuterSurface) {
  const Result<HumanoidModel> model = HumanoidModel::FromPreset("standing");
  ASSERT_TRUE(model.ok());
  const auto coarse = model->SampleSurface(0.01);
  const auto fine = model->SampleSurface(0.005);
  ASSERT_TRUE(coarse.ok() && fine.ok());
  EXPECT_GT(fine->size(), 3 * coarse->size());  // about 4x for half the spacing.
  Eigen::AlignedBox3d bounds = model->bounds();
  bounds.extend(bounds.min() - Eigen::Vector3d::Constant(1e-6));
  bounds.extend(bounds.max() + Eigen::Vector3d::Constant(1e-6));
  for (const Eigen::Vector3f& p : *fine) {
    ASSERT_TRUE(bounds.contains(p.cast<double>()));
    for (const Primitive& prim : model->primitives()) {
      // Nothing buried more than 1.5 mm inside any part (float rounding aside).
      ASSERT_FALSE(prim.Contains(p.cast<double>(), 0.0015)) << prim.name;
    }
  }
}

TEST(HumanoidModelTest, HeadYawTurnsTheEars) {
  HumanoidJoints turned;
  turned.head_yaw_rad = 0.5;
  const auto a = HumanoidModel::Create({}, {});
  const auto b = HumanoidModel::Create({}, turned);
  ASSERT_TRUE(a.ok() && b.ok());
  const Primitive* ears_a = Find(*a, "ears");
  const Primitive* ears_b = Find(*b, "ears");
  ASSERT_TRUE(ears_a && ears_b);
  EXPECT_NEAR(ears_a->Bounds().sizes().x(), 2 * ears_a->half_size.x(), 1e-9);
  EXPECT_GT(ears_b->Bounds().sizes().x(), ears_a->Bounds().sizes().x() + 0.02);
}

TEST(HumanoidModelTest, BadInputIsRejectedWithAReason) {
  const auto unknown = HumanoidModel::FromPreset("dancing");
  ASSERT_FALSE(unknown.ok());
  EXPECT_EQ(unknown.error().code, ErrorCode::kInvalidArgument);
  EXPECT_NE(unknown.error().message.find("dancing"), std::string::npos);
  EXPECT_NE(unknown.error().message.find("right_arm_raised"), std::string::npos);

  HumanoidDimensions dims;
  dims.thigh_length_m = -0.1;
  const auto bad_dims = HumanoidModel::Create(dims, {});
  ASSERT_FALSE(bad_dims.ok());
  EXPECT_NE(bad_dims.error().message.find("thigh_length_m"), std::string::npos);

  HumanoidJoints joints;
  joints.left_knee_rad = std::nan("");
  const auto bad_joints = HumanoidModel::Create({}, joints);
  ASSERT_FALSE(bad_joints.ok());
  EXPECT_NE(bad_joints.error().message.find("left_knee"), std::string::npos);

  const auto model = HumanoidModel::FromPreset("standing");
  ASSERT_TRUE(model.ok());
  EXPECT_FALSE(model->SampleSurface(0.0).ok());
  EXPECT_FALSE(model->SampleSurface(std::nan("")).ok());
}

}  // namespace
}  // namespace hpose
