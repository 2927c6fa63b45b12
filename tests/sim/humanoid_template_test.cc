#include "core/sim/humanoid_template.h"

#include <gtest/gtest.h>

#include "core/sim/humanoid_model.h"

namespace hpose {
namespace {

TEST(HumanoidTemplateTest, TheModelsTemplateWithItsFreeLimbsMarked) {
  const Result<HumanoidModel> model = HumanoidModel::FromPreset("standing");
  ASSERT_TRUE(model.ok());
  const Result<VoxelTemplate> tpl = MakeHumanoidTemplate(*model, "standing", 0.016, "", "test");
  const Result<VoxelTemplate> plain =
      MakeTemplateFromPoints(*model->SampleSurface(0.004), "standing", 0.016, "", "test");
  ASSERT_TRUE(tpl.ok() && plain.ok()) << tpl.error().ToString();
  // The same voxels and surface as the unmarked template: only the marks are added.
  EXPECT_EQ(tpl->voxels, plain->voxels);
  EXPECT_EQ(tpl->surface, plain->surface);
  EXPECT_TRUE(plain->free_limb.empty());
  ASSERT_EQ(tpl->free_limb.size(), tpl->surface.size());
  size_t marked = 0, feet = 0, crown = 0;
  for (size_t i = 0; i < tpl->surface.size(); ++i) {
    const float z = tpl->surface[i].z();
    marked += tpl->free_limb[i];
    if (z < 0.1f) {  // feet and shanks: legs carry the robot, never free.
      ++feet;
      EXPECT_EQ(tpl->free_limb[i], 0) << tpl->surface[i].transpose();
    }
    if (z > model->Height() - 0.03) {  // the top of the head.
      ++crown;
      EXPECT_EQ(tpl->free_limb[i], 1) << tpl->surface[i].transpose();
    }
  }
  EXPECT_GT(feet, 100u);
  EXPECT_GT(crown, 10u);
  // Arms and head are a quarter to a half of a Nao-like body's surface.
  EXPECT_GT(marked, tpl->surface.size() / 4);
  EXPECT_LT(marked, tpl->surface.size() / 2);
  EXPECT_EQ(tpl->FreeLimbPoints().size(), marked);
}

TEST(HumanoidTemplateTest, FailsAsTheSamplingAndVoxelisingDo) {
  const Result<HumanoidModel> model = HumanoidModel::FromPreset("standing");
  ASSERT_TRUE(model.ok());
  const Result<VoxelTemplate> bad_spacing = MakeHumanoidTemplate(*model, "s", 0.016, "", "", 0.0);
  ASSERT_FALSE(bad_spacing.ok());
  EXPECT_NE(bad_spacing.error().message.find("spacing"), std::string::npos);
  const Result<VoxelTemplate> bad_name = MakeHumanoidTemplate(*model, "no spaces", 0.016);
  ASSERT_FALSE(bad_name.ok());
  EXPECT_NE(bad_name.error().message.find("no spaces"), std::string::npos);
}

}  // namespace
}  // namespace hpose
