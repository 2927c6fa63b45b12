#include "core/robot/mesh_file.h"

#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/robot/urdf_robot.h"
#include "tests/io/temp_dir.h"
#include "tests/robot/collada_box.h"

namespace hpose {
namespace {

const char kTriangleObj[] = "v 0 0 0\nv 1 0 0\nv 0 2 0\nf 1 2 3\n";

void ExpectSameMesh(const TriangleMesh& a, const TriangleMesh& b) {
  ASSERT_EQ(a.vertices.size(), b.vertices.size());
  ASSERT_EQ(a.triangles.size(), b.triangles.size());
  for (size_t i = 0; i < a.vertices.size(); ++i) EXPECT_EQ(a.vertices[i], b.vertices[i]) << i;
  for (size_t i = 0; i < a.triangles.size(); ++i) EXPECT_EQ(a.triangles[i], b.triangles[i]) << i;
}

TEST(MeshFileTest, ReadInAChildAsInThisProcess) {
  TempDir dir;
  for (const std::string& path :
       {dir.Write("box.dae", testing::BoxCollada(true)), dir.Write("tri.obj", kTriangleObj)}) {
    const Result<TriangleMesh> here = ReadMeshFileInProcess(path);
    ASSERT_TRUE(here.ok()) << here.error().ToString();
    const Result<TriangleMesh> child = ReadMeshFile(path);
    ASSERT_TRUE(child.ok()) << child.error().ToString();
    ExpectSameMesh(*child, *here);
  }
  const Result<TriangleMesh> box = ReadMeshFile(dir.File("box.dae"));
  ASSERT_TRUE(box.ok());
  EXPECT_EQ(box->triangles.size(), 12u);
  EXPECT_NEAR(box->Bounds().min().x(), 0.45, 1e-6);  // the node's transform applied
  EXPECT_NEAR(box->Bounds().max().z(), 0.3, 1e-6);
}

TEST(MeshFileTest, AFileThatCrashesAssimpIsAnErrorAndTheOthersAreStillRead) {
  TempDir dir;
  const std::string good = dir.Write("box.dae", testing::BoxCollada(true));
  const std::string crashing = dir.Write("crashing.dae", testing::BoxCollada(false));
  const std::string garbage = dir.Write("garbage.stl", "this is not a mesh at all");
  const std::string obj = dir.Write("tri.obj", kTriangleObj);

  const Result<TriangleMesh> one = ReadMeshFile(crashing);
  ASSERT_FALSE(one.ok());
  EXPECT_EQ(one.error().code, ErrorCode::kDataLoss);
  // A signal in a plain build; AddressSanitizer's own exit status where it catches the fault.
  EXPECT_NE(one.error().message.find("assimp "), std::string::npos) << one.error().message;
  EXPECT_NE(one.error().message.find("(read in a separate process)"), std::string::npos);

  const std::vector<Result<TriangleMesh>> all = ReadMeshFiles({good, crashing, garbage, obj, good});
  ASSERT_EQ(all.size(), 5u);
  ASSERT_TRUE(all[0].ok()) << all[0].error().ToString();
  EXPECT_EQ(all[0]->triangles.size(), 12u);
  ASSERT_FALSE(all[1].ok());
  EXPECT_EQ(all[1].error().message, one.error().message);
  ASSERT_FALSE(all[2].ok());  // assimp's own error, from the next child
  EXPECT_EQ(all[2].error().code, ErrorCode::kDataLoss);
  EXPECT_EQ(all[2].error().message.find("separate process"), std::string::npos);
  ASSERT_TRUE(all[3].ok()) << all[3].error().ToString();
  EXPECT_EQ(all[3]->triangles.size(), 1u);
  ASSERT_TRUE(all[4].ok());
  ExpectSameMesh(*all[4], *all[0]);
  EXPECT_TRUE(ReadMeshFiles({}).empty());
}

TEST(MeshFileTest, ARobotWhoseMeshCrashesAssimpIsAnErrorNamingLinkAndFile) {
  TempDir dir;
  dir.Write("tri.obj", kTriangleObj);
  const std::string crashing = dir.Write("crashing.dae", testing::BoxCollada(false));
  const std::string urdf = dir.Write("r.urdf", R"(<?xml version="1.0"?>
<robot name="r">
  <link name="base"><visual><geometry><mesh filename="tri.obj"/></geometry></visual></link>
  <link name="arm"><visual><geometry><mesh filename="crashing.dae"/></geometry></visual></link>
  <joint name="shoulder" type="fixed"><parent link="base"/><child link="arm"/></joint>
</robot>
)");
  const Result<UrdfRobot> refused = UrdfRobot::Load(urdf);
  ASSERT_FALSE(refused.ok());
  EXPECT_EQ(refused.error().code, ErrorCode::kDataLoss);
  EXPECT_NE(refused.error().message.find("link 'arm'"), std::string::npos)
      << refused.error().message;
  EXPECT_NE(refused.error().message.find(crashing), std::string::npos);
  EXPECT_NE(refused.error().message.find("assimp "), std::string::npos);

  UrdfLoadOptions options;
  options.allow_missing = true;
  const Result<UrdfRobot> robot = UrdfRobot::Load(urdf, options);
  ASSERT_TRUE(robot.ok()) << robot.error().ToString();
  ASSERT_EQ(robot->skipped().size(), 1u);
  EXPECT_EQ(robot->skipped()[0].link, "arm");
  EXPECT_EQ(robot->TriangleCount(), 1u);  // the base's triangle
}

}  // namespace
}  // namespace hpose
