#include "core/robot/mesh_file.h"

#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/robot/urdf_robot.h"
#include "tests/io/temp_dir.h"

namespace hpose {
namespace {

// A 0.1 x 0.1 x 0.3 m box as COLLADA, with its node moved 0.5 m along x; `count_attribute` false
// leaves the count out of the float_array, which makes Debian's assimp 5.2 crash (a damaged
// file as a mutation test found it).
std::string BoxCollada(bool count_attribute) {
  const std::string count = count_attribute ? " count=\"24\"" : "";
  return R"(<?xml version="1.0" encoding="utf-8"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
  <asset><unit name="meter" meter="1"/><up_axis>Z_UP</up_axis></asset>
  <library_geometries>
    <geometry id="box" name="box">
      <mesh>
        <source id="box-pos">
          <float_array id="box-pos-array")" +
         count +
         R"(>-0.05 -0.05 0 -0.05 -0.05 0.3 -0.05 0.05 0 -0.05 0.05 0.3 0.05 -0.05 0 0.05 -0.05 0.3 0.05 0.05 0 0.05 0.05 0.3</float_array>
          <technique_common><accessor source="#box-pos-array" count="8" stride="3">
            <param name="X" type="float"/><param name="Y" type="float"/><param name="Z" type="float"/>
          </accessor></technique_common>
        </source>
        <vertices id="box-vtx"><input semantic="POSITION" source="#box-pos"/></vertices>
        <triangles count="12"><input semantic="VERTEX" source="#box-vtx" offset="0"/>
          <p>0 1 3 0 3 2 4 6 7 4 7 5 0 4 5 0 5 1 2 3 7 2 7 6 0 2 6 0 6 4 1 5 7 1 7 3</p></triangles>
      </mesh>
    </geometry>
  </library_geometries>
  <library_visual_scenes>
    <visual_scene id="scene">
      <node id="n" name="n"><matrix>1 0 0 0.5 0 1 0 0 0 0 1 0 0 0 0 1</matrix><instance_geometry url="#box"/></node>
    </visual_scene>
  </library_visual_scenes>
  <scene><instance_visual_scene url="#scene"/></scene>
</COLLADA>
)";
}

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
       {dir.Write("box.dae", BoxCollada(true)), dir.Write("tri.obj", kTriangleObj)}) {
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
  const std::string good = dir.Write("box.dae", BoxCollada(true));
  const std::string crashing = dir.Write("crashing.dae", BoxCollada(false));
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
  const std::string crashing = dir.Write("crashing.dae", BoxCollada(false));
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
