// End-to-end tests of `hpose template` and of the shipped templates.
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "core/io/cloud_io.h"
#include "core/sim/humanoid_model.h"
#include "core/sim/humanoid_template.h"
#include "core/templates/template_io.h"
#include "core/templates/voxel_template.h"
#include "tests/tools/cli_test_util.h"

namespace hpose {
namespace {

using testing::CliRun;
using testing::RunHpose;
using testing::TempDir;

TEST(TemplateCliTest, GenerateThenInfo) {
  TempDir dir("template_cli_generate");
  const std::string bt = dir / "arm.bt";
  const CliRun gen =
      RunHpose("template generate --pose right_arm_raised --name arm --out '" + bt + "'", dir);
  ASSERT_EQ(gen.exit_code, 0) << gen.err;
  EXPECT_EQ(gen.err.find("done."), std::string::npos) << "library chatter on stderr: " << gen.err;
  const Result<VoxelTemplate> tpl = LoadTemplate(bt);
  ASSERT_TRUE(tpl.ok()) << tpl.error().ToString();
  EXPECT_EQ(tpl->name, "arm");
  EXPECT_EQ(tpl->variant, "right_arm_raised");
  EXPECT_DOUBLE_EQ(tpl->resolution_m, 0.016);
  const auto model = HumanoidModel::FromPreset("right_arm_raised");
  ASSERT_TRUE(model.ok());
  EXPECT_GE(tpl->Height(), model->Height());
  EXPECT_LE(tpl->Height(), model->Height() + 0.016);
  EXPECT_GT(tpl->voxels.size(), 1000u);
  EXPECT_LT(std::filesystem::file_size(bt), 1000000u);

  const CliRun info = RunHpose("template info '" + bt + "'", dir);
  ASSERT_EQ(info.exit_code, 0) << info.err;
  EXPECT_NE(info.out.find("arm"), std::string::npos);
  EXPECT_NE(info.out.find(std::to_string(tpl->voxels.size())), std::string::npos);
  EXPECT_NE(info.out.find("bbox"), std::string::npos);

  // A surface spacing out of range is refused, naming the flag; nothing is written.
  const CliRun spaced =
      RunHpose("template generate --pose standing --spacing 0 --out '" + (dir / "s.bt") + "'", dir);
  EXPECT_EQ(spaced.exit_code, 2) << spaced.err;
  EXPECT_NE(spaced.err.find("--spacing"), std::string::npos) << spaced.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "s.bt"));

  // Its arms, neck and head are marked as free limbs, the same points as the model's own.
  ASSERT_EQ(tpl->free_limb.size(), tpl->surface.size());
  const Result<VoxelTemplate> direct = MakeHumanoidTemplate(*model, "arm", 0.016);
  ASSERT_TRUE(direct.ok()) << direct.error().ToString();
  EXPECT_EQ(tpl->free_limb, direct->free_limb);
  EXPECT_GT(tpl->FreeLimbPoints().size(), 0u);
  EXPECT_NE(info.out.find(std::to_string(tpl->FreeLimbPoints().size()) + " on free limbs"),
            std::string::npos)
      << info.out;
}

// Templates made at another edge than 16 mm are searched at theirs (`hpose estimate` refused
// them before: "the search uses 0.016 m"), and a tall body's 16 mm templates on coarser voxels,
// which a note says; --max-height-voxels 0 keeps their own.
TEST(TemplateCliTest, EstimateSearchesAtTheTemplatesEdgeAndATallBodyCoarser) {
  TempDir dir("template_cli_edge");
  for (const char* pose : {"standing", "right_arm_raised"}) {
    const CliRun gen = RunHpose(std::string("template generate --pose ") + pose +
                                    " --resolution 0.02 --out '" + (dir / pose) + "20.bt'",
                                dir);
    ASSERT_EQ(gen.exit_code, 0) << gen.err;
    const CliRun tall = RunHpose(std::string("template generate --body tall --pose ") + pose +
                                     " --out '" + (dir / pose) + "_tall.bt'",
                                 dir);
    ASSERT_EQ(tall.exit_code, 0) << tall.err;
    // Authoring says which edge a tall body is searched at.
    EXPECT_EQ(gen.out.find("note:"), std::string::npos) << gen.out;
    EXPECT_NE(tall.out.find("note: taller than 48 of its voxels: searched on " +
                            std::string(pose == std::string("standing") ? "26.0" : "28.0") +
                            " mm voxels by default"),
              std::string::npos)
        << tall.out;
  }
  const CliRun sim = RunHpose("simulate --x 1.6 --theta-deg 30 --out '" + (dir / "nao") + "'", dir);
  ASSERT_EQ(sim.exit_code, 0) << sim.err;
  const CliRun twenty =
      RunHpose("estimate '" + (dir / "nao") + "/depth.png' --template '" + (dir / "standing") +
                   "20.bt' --template '" + (dir / "right_arm_raised") + "20.bt'",
               dir);
  ASSERT_EQ(twenty.exit_code, 0) << twenty.err << twenty.out;
  EXPECT_NE(twenty.out.find("humanoid  standing at x 1.6"), std::string::npos) << twenty.out;
  EXPECT_EQ(twenty.err.find("searched on"), std::string::npos) << twenty.err;

  const CliRun tall_sim =
      RunHpose("simulate --body tall --x 2.2 --theta-deg -60 --out '" + (dir / "tall") + "'", dir);
  ASSERT_EQ(tall_sim.exit_code, 0) << tall_sim.err;
  const std::string tall_estimate = "estimate '" + (dir / "tall") + "/depth.png' --template '" +
                                    (dir / "standing") + "_tall.bt' --template '" +
                                    (dir / "right_arm_raised") + "_tall.bt'";
  const CliRun coarse = RunHpose(tall_estimate, dir);
  ASSERT_EQ(coarse.exit_code, 0) << coarse.err << coarse.out;
  EXPECT_NE(coarse.out.find("humanoid  standing at x 2.2"), std::string::npos) << coarse.out;
  EXPECT_NE(coarse.err.find("note: templates 'standing', 'right_arm_raised' searched on 28.0 mm "
                            "voxels, as the body is 1.33 m tall"),
            std::string::npos)
      << coarse.err;
  // On its own 16 mm voxels the body scores under the threshold of 50 at 2.2 m (the depth noise
  // spreads its surface over more small voxels): found from 40.
  const CliRun own = RunHpose(tall_estimate + " --max-height-voxels 0 --threshold 40", dir);
  ASSERT_EQ(own.exit_code, 0) << own.err << own.out;
  EXPECT_NE(own.out.find("humanoid  standing at x 2.2"), std::string::npos) << own.out;
  EXPECT_EQ(own.err.find("searched on"), std::string::npos) << own.err;
  EXPECT_EQ(RunHpose(tall_estimate + " --max-height-voxels 3", dir).exit_code, 2);  // usage.
}

TEST(TemplateCliTest, FromCloudVoxelisesTheCloud) {
  TempDir dir("template_cli_cloud");
  const auto model = HumanoidModel::FromPreset("standing");
  ASSERT_TRUE(model.ok());
  const auto points = model->SampleSurface(0.005);
  ASSERT_TRUE(points.ok());
  PointCloud cloud;
  cloud.points = *points;
  ASSERT_TRUE(WritePcd(cloud, dir / "robot.pcd").ok());
  const CliRun run = RunHpose("template from-cloud '" + (dir / "robot.pcd") +
                                  "' --name robot --resolution 0.02 --out '" + (dir / "r.bt") + "'",
                              dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const Result<VoxelTemplate> tpl = LoadTemplate(dir / "r.bt");
  const Result<VoxelTemplate> direct = MakeTemplateFromPoints(*points, "robot", 0.02);
  ASSERT_TRUE(tpl.ok() && direct.ok());
  EXPECT_EQ(tpl->name, "robot");
  EXPECT_DOUBLE_EQ(tpl->resolution_m, 0.02);
  EXPECT_EQ(tpl->voxels.size(), direct->voxels.size());
  EXPECT_EQ(run.out.find("note:"), std::string::npos) << run.out;

  // The same body lifted half a metre, or moved aside: made, with a note asking about the frame.
  const auto moved = [&](const std::string& name, const Eigen::Vector3f& by) {
    PointCloud c = cloud;
    for (Eigen::Vector3f& p : c.points) p += by;
    EXPECT_TRUE(WritePcd(c, dir / (name + ".pcd")).ok());
    const CliRun r =
        RunHpose("template from-cloud '" + (dir / (name + ".pcd")) + "' --name " + name +
                     " --resolution 0.02 --out '" + (dir / (name + ".bt")) + "'",
                 dir);
    EXPECT_EQ(r.exit_code, 0) << r.err;
    return r.out;
  };
  const std::string up = moved("up", Eigen::Vector3f(0.0f, 0.0f, 0.5f));
  EXPECT_NE(up.find("lowest voxel is 500 mm above the floor"), std::string::npos) << up;
  EXPECT_EQ(up.find("footprint"), std::string::npos) << up;
  const std::string side = moved("side", Eigen::Vector3f(0.6f, 0.0f, 0.0f));
  EXPECT_NE(side.find("centre of its footprint is"), std::string::npos) << side;
  EXPECT_EQ(side.find("lowest voxel"), std::string::npos) << side;
}

TEST(TemplateCliTest, BadInputGivesClearErrors) {
  TempDir dir("template_cli_bad");
  const CliRun missing = RunHpose(
      "template from-cloud '" + (dir / "nope.pcd") + "' --name x --out '" + (dir / "x.bt") + "'",
      dir);
  EXPECT_EQ(missing.exit_code, 1);
  EXPECT_NE(missing.err.find("nope.pcd"), std::string::npos);
  EXPECT_EQ(RunHpose("template from-cloud a.pcd --out x.bt", dir).exit_code, 2);  // no --name
  EXPECT_EQ(RunHpose("template generate --pose dancing --out x.bt", dir).exit_code, 2);
  EXPECT_EQ(RunHpose("template generate --pose standing", dir).exit_code, 2);  // no --out
  EXPECT_EQ(RunHpose("template frobnicate", dir).exit_code, 2);
  EXPECT_EQ(RunHpose("template", dir).exit_code, 2);
  {
    std::ofstream corrupt(dir / "bad.bt");
    corrupt << "not an octree";
  }
  const CliRun info = RunHpose("template info '" + (dir / "bad.bt") + "'", dir);
  EXPECT_EQ(info.exit_code, 1);
  EXPECT_NE(info.err.find("bad.bt"), std::string::npos);
  for (const char* sub : {"generate", "from-cloud", "info"}) {
    const CliRun help = RunHpose(std::string("template ") + sub + " --help", dir);
    EXPECT_EQ(help.exit_code, 0) << sub;
    EXPECT_NE(help.out.find("usage"), std::string::npos) << sub;
  }
}

// The shipped templates must be what `make templates` produces from the current model.
TEST(TemplateCliTest, ShippedTemplatesMatchTheModel) {
  TempDir dir("template_cli_shipped");
  for (const std::string pose : {"standing", "right_arm_raised", "arms_swung"}) {
    const std::string shipped = std::string(HPOSE_SOURCE_DIR) + "/templates/" + pose + ".bt";
    const Result<VoxelTemplate> a = LoadTemplate(shipped);
    ASSERT_TRUE(a.ok()) << a.error().ToString();
    const CliRun run =
        RunHpose("template generate --pose " + pose + " --out '" + (dir / pose) + ".bt'", dir);
    ASSERT_EQ(run.exit_code, 0) << run.err;
    const Result<VoxelTemplate> b = LoadTemplate(dir / (pose + ".bt"));
    ASSERT_TRUE(b.ok());
    EXPECT_EQ(a->name, pose);
    EXPECT_EQ(a->voxels, b->voxels) << pose << ": run `make templates` after changing the model";
    EXPECT_LT(std::filesystem::file_size(shipped), 1000000u);
  }
}

}  // namespace
}  // namespace hpose
