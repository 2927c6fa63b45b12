#include "core/robot/urdf_robot.h"

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/robot/package_resolver.h"
#include "core/sim/triangle_mesh.h"
#include "tests/io/temp_dir.h"

namespace hpose {
namespace {

const std::string kDarwinUrdf =
    std::string(HPOSE_SHARED_DATA_DIR) + "/darwin_op/robots/robotis_op.urdf";

bool HaveDarwin() { return std::filesystem::exists(kDarwinUrdf); }

// A base box (0.2 x 0.1 x 0.3 m) on a revolute joint chain: an arm (cylinder) on a shoulder
// joint about y, a head sphere on a fixed joint and a mimic joint following the shoulder.
const char kPrimitiveRobot[] = R"(<?xml version="1.0"?>
<robot name="blocky">
  <link name="base">
    <visual><origin xyz="0 0 0.15"/><geometry><box size="0.2 0.1 0.3"/></geometry></visual>
  </link>
  <link name="arm">
    <visual><origin xyz="0 0 -0.1"/><geometry><cylinder radius="0.02" length="0.2"/></geometry></visual>
  </link>
  <link name="head">
    <visual><geometry><sphere radius="0.05"/></geometry></visual>
  </link>
  <link name="twin"/>
  <joint name="shoulder" type="revolute">
    <parent link="base"/><child link="arm"/>
    <origin xyz="0 0.08 0.28"/><axis xyz="0 1 0"/>
    <limit lower="-3.0" upper="3.0" effort="1" velocity="1"/>
  </joint>
  <joint name="neck" type="fixed">
    <parent link="base"/><child link="head"/><origin xyz="0 0 0.35"/>
  </joint>
  <joint name="twin_joint" type="revolute">
    <parent link="base"/><child link="twin"/><axis xyz="0 0 1"/>
    <limit lower="-1.0" upper="1.0" effort="1" velocity="1"/>
    <mimic joint="shoulder" multiplier="0.5" offset="0.1"/>
  </joint>
</robot>
)";

// A tetrahedron as an ASCII STL, unit size.
const char kTetraStl[] = R"(solid tet
facet normal 0 0 -1
outer loop
vertex 0 0 0
vertex 0 1 0
vertex 1 0 0
endloop
endfacet
facet normal 0 -1 0
outer loop
vertex 0 0 0
vertex 1 0 0
vertex 0 0 1
endloop
endfacet
facet normal -1 0 0
outer loop
vertex 0 0 0
vertex 0 0 1
vertex 0 1 0
endloop
endfacet
facet normal 1 1 1
outer loop
vertex 1 0 0
vertex 0 1 0
vertex 0 0 1
endloop
endfacet
endsolid tet
)";

std::string MeshRobot(const std::string& filename, const std::string& scale) {
  return "<?xml version=\"1.0\"?>\n<robot name=\"meshy\">\n  <link name=\"base\">\n"
         "    <visual><geometry><mesh filename=\"" +
         filename + "\" scale=\"" + scale + "\"/></geometry></visual>\n  </link>\n</robot>\n";
}

TEST(UrdfRobotTest, PrimitivesArePosedInTheTemplateFrame) {
  TempDir dir;
  const std::string urdf = dir.Write("blocky.urdf", kPrimitiveRobot);
  Result<UrdfRobot> robot = UrdfRobot::Load(urdf);
  ASSERT_TRUE(robot.ok()) << robot.error().message;
  EXPECT_EQ(robot->name(), "blocky");
  EXPECT_EQ(robot->root_link(), "base");
  ASSERT_EQ(robot->joints().size(), 3u);

  Result<PosedRobot> posed = robot->Pose({});
  ASSERT_TRUE(posed.ok()) << posed.error().message;
  const Eigen::AlignedBox3d b = posed->mesh.Bounds();
  // The arm hangs down to z = 0.08 and the box reaches the floor: box bottom on z = 0.
  EXPECT_NEAR(b.min().z(), 0.0, 1e-6);
  EXPECT_NEAR(b.min().x(), -0.1, 1e-6);
  EXPECT_NEAR(b.max().x(), 0.1, 1e-6);
  EXPECT_NEAR(b.min().y(), -0.05, 1e-6);
  EXPECT_NEAR(b.max().y(), 0.08 + 0.02, 1e-3);
  EXPECT_NEAR(b.max().z(), 0.35 + 0.05, 1e-3);  // the head sphere's top
  EXPECT_NEAR(posed->Height(), 0.40, 1e-3);

  // Raising the arm about y by -pi/2 points it forward (+x): x reaches 0.28 - ... the arm's tip
  // at 0.2 m ahead of the shoulder.
  Result<PosedRobot> raised = robot->Pose({{"shoulder", -M_PI / 2}});
  ASSERT_TRUE(raised.ok()) << raised.error().message;
  EXPECT_NEAR(raised->mesh.Bounds().max().x(), 0.2, 2e-3);
  // The mimic joint follows: 0.5 * (-pi/2) + 0.1.
  const Eigen::Matrix3d twin = raised->template_from_link.at("twin").linear();
  EXPECT_NEAR(std::atan2(twin(1, 0), twin(0, 0)), 0.5 * (-M_PI / 2) + 0.1, 1e-9);
  // ... and is outside its own limits [-1, 1] at shoulder = -3: noted, not an error.
  Result<PosedRobot> far = robot->Pose({{"shoulder", -3.0}});
  ASSERT_TRUE(far.ok());
  ASSERT_EQ(far->notes.size(), 1u);
  EXPECT_NE(far->notes[0].find("twin_joint"), std::string::npos);
}

TEST(UrdfRobotTest, FreeLimbsAreTheMovingLimbsClearOfTheFloor) {
  TempDir dir;
  Result<UrdfRobot> robot = UrdfRobot::Load(dir.Write("blocky.urdf", kPrimitiveRobot));
  ASSERT_TRUE(robot.ok()) << robot.error().message;
  // The arm (on a revolute joint, its lowest point 0.08 m up a 0.40 m robot) is a free limb; the
  // head is fixed to the base (part of the trunk) and the mimic joint's link has no shape.
  Result<PosedRobot> posed = robot->Pose({});
  ASSERT_TRUE(posed.ok()) << posed.error().message;
  EXPECT_EQ(posed->free_limb_joints, std::vector<std::string>{"shoulder"});
  ASSERT_FALSE(posed->free_limbs.empty());
  const Eigen::AlignedBox3d arm = posed->free_limbs.Bounds();
  EXPECT_NEAR(arm.min().z(), 0.08, 1e-3);
  EXPECT_NEAR(arm.max().z(), 0.28, 1e-3);
  EXPECT_NEAR(arm.min().y(), 0.06, 1e-3);
  EXPECT_NEAR(arm.max().y(), 0.10, 1e-3);
  // The template marks the surface on the arm, and only there.
  Result<VoxelTemplate> tpl =
      MakeMeshTemplate(posed->mesh, "blocky", 0.016, "standing", "test", &posed->free_limbs);
  ASSERT_TRUE(tpl.ok()) << tpl.error().message;
  ASSERT_EQ(tpl->free_limb.size(), tpl->surface.size());
  int marked = 0;
  for (size_t i = 0; i < tpl->surface.size(); ++i) {
    const Eigen::Vector3f& p = tpl->surface[i];
    if (!tpl->free_limb[i]) continue;
    ++marked;
    EXPECT_GT(p.y(), 0.05f - 0.008f) << "marked point off the arm at " << p.transpose();
    EXPECT_GT(p.z(), 0.08f - 0.008f);
  }
  EXPECT_GT(marked, 20);
  EXPECT_LT(marked, static_cast<int>(tpl->surface.size()) / 2);
}

TEST(UrdfRobotTest, JointErrorsNameTheJoints) {
  TempDir dir;
  Result<UrdfRobot> robot = UrdfRobot::Load(dir.Write("blocky.urdf", kPrimitiveRobot));
  ASSERT_TRUE(robot.ok());
  Result<PosedRobot> unknown = robot->Pose({{"elbow", 0.1}, {"knee", 0.2}, {"shoulder", 0.0}});
  ASSERT_FALSE(unknown.ok());
  EXPECT_EQ(unknown.error().code, ErrorCode::kInvalidArgument);
  EXPECT_NE(unknown.error().message.find("'elbow'"), std::string::npos);
  EXPECT_NE(unknown.error().message.find("'knee'"), std::string::npos);
  Result<PosedRobot> limits = robot->Pose({{"shoulder", 3.5}});
  ASSERT_FALSE(limits.ok());
  EXPECT_NE(limits.error().message.find("limits"), std::string::npos);
  Result<PosedRobot> fixed = robot->Pose({{"neck", 0.1}});
  ASSERT_FALSE(fixed.ok());
  EXPECT_NE(fixed.error().message.find("fixed"), std::string::npos);
  Result<PosedRobot> mimic = robot->Pose({{"twin_joint", 0.1}});
  ASSERT_FALSE(mimic.ok());
  EXPECT_NE(mimic.error().message.find("mimic"), std::string::npos);
  Result<PosedRobot> link = robot->Pose({}, "no_such_link");
  ASSERT_FALSE(link.ok());
  EXPECT_NE(link.error().message.find("no_such_link"), std::string::npos);
}

TEST(UrdfRobotTest, ReferenceLinkDefinesOriginAndHeading) {
  TempDir dir;
  Result<UrdfRobot> robot = UrdfRobot::Load(dir.Write("blocky.urdf", kPrimitiveRobot));
  ASSERT_TRUE(robot.ok());
  // The arm link turned about y keeps its x axis on the floor but moves its origin: the template
  // origin is below the shoulder (0, 0.08) of the root frame.
  Result<PosedRobot> posed = robot->Pose({{"shoulder", 0.3}}, "arm");
  ASSERT_TRUE(posed.ok()) << posed.error().message;
  const Eigen::Vector3d arm = posed->template_from_link.at("arm").translation();
  EXPECT_NEAR(arm.x(), 0.0, 1e-9);
  EXPECT_NEAR(arm.y(), 0.0, 1e-9);
  EXPECT_NEAR(arm.z(), 0.28, 1e-6);
  const Eigen::Vector3d base = posed->template_from_link.at("base").translation();
  EXPECT_NEAR(base.y(), -0.08, 1e-9);
  // The arm's x axis projected on the floor is the template's x.
  const Eigen::Vector3d arm_x = posed->template_from_link.at("arm").linear().col(0);
  EXPECT_NEAR(arm_x.y(), 0.0, 1e-9);
  EXPECT_GT(arm_x.x(), 0.0);
}

TEST(UrdfRobotTest, MeshScaleAndRelativePaths) {
  TempDir dir;
  std::filesystem::create_directories(dir.File("meshes"));
  dir.Write("meshes/tet.stl", kTetraStl);
  Result<UrdfRobot> robot =
      UrdfRobot::Load(dir.Write("meshy.urdf", MeshRobot("meshes/tet.stl", "0.1 0.2 0.3")));
  ASSERT_TRUE(robot.ok()) << robot.error().message;
  EXPECT_EQ(robot->TriangleCount(), 4u);
  Result<PosedRobot> posed = robot->Pose({});
  ASSERT_TRUE(posed.ok());
  // The root link's origin is the tetrahedron's corner: the template origin.
  const Eigen::AlignedBox3d b = posed->mesh.Bounds();
  EXPECT_NEAR(b.min().x(), 0.0, 1e-6);
  EXPECT_NEAR(b.max().x(), 0.1, 1e-6);
  EXPECT_NEAR(b.max().y(), 0.2, 1e-6);
  EXPECT_NEAR(b.max().z(), 0.3, 1e-6);
}

TEST(UrdfRobotTest, ObjMeshesLoadToo) {
  TempDir dir;
  // A unit square (two triangles given as one quad face, triangulated on load) and a triangle.
  dir.Write("m.obj",
            "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 2\n"
            "f 1 2 3 4\nf 1 2 5\n");
  Result<UrdfRobot> robot = UrdfRobot::Load(dir.Write("o.urdf", MeshRobot("m.obj", "0.1 0.1 0.1")));
  ASSERT_TRUE(robot.ok()) << robot.error().message;
  EXPECT_EQ(robot->TriangleCount(), 3u);
  Result<PosedRobot> posed = robot->Pose({});
  ASSERT_TRUE(posed.ok());
  EXPECT_NEAR(posed->Height(), 0.2, 1e-6);
}

TEST(UrdfRobotTest, PackageUrisAreResolvedThroughPackagePaths) {
  TempDir dir;
  const std::string pkg = dir.File("ws/src/description");
  std::filesystem::create_directories(pkg + "/meshes");
  dir.Write("ws/src/description/package.xml",
            "<package><name>my_robot_description</name></package>");
  dir.Write("ws/src/description/meshes/tet.stl", kTetraStl);
  std::filesystem::create_directories(dir.File("elsewhere"));
  const std::string urdf = dir.Write(
      "elsewhere/r.urdf", MeshRobot("package://my_robot_description/meshes/tet.stl", "1 1 1"));

  Result<UrdfRobot> missing = UrdfRobot::Load(urdf);
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.error().message.find("my_robot_description"), std::string::npos);
  EXPECT_NE(missing.error().message.find("'base'"), std::string::npos);

  UrdfLoadOptions options;
  options.package_paths = {dir.File("ws")};
  Result<UrdfRobot> robot = UrdfRobot::Load(urdf, options);
  ASSERT_TRUE(robot.ok()) << robot.error().message;
  EXPECT_EQ(robot->TriangleCount(), 4u);

  // A package directory given directly, found by its directory name (no package.xml).
  std::filesystem::create_directories(dir.File("plain/meshes"));
  Result<std::string> by_dir =
      ResolveUrdfResource("package://plain/meshes/a.stl", "/x", {dir.File("plain")});
  ASSERT_TRUE(by_dir.ok()) << by_dir.error().message;
  EXPECT_EQ(*by_dir, dir.File("plain/meshes/a.stl"));
  EXPECT_EQ(*ResolveUrdfResource("file:///abs/m.dae", "/x", {}), "/abs/m.dae");
  EXPECT_EQ(*ResolveUrdfResource("m/a.obj", "/robots", {}), "/robots/m/a.obj");
  EXPECT_FALSE(ResolveUrdfResource("package://nopath", "/x", {}).ok());
}

TEST(UrdfRobotTest, BadFilesAreClearErrors) {
  TempDir dir;
  Result<UrdfRobot> absent = UrdfRobot::Load(dir.File("absent.urdf"));
  ASSERT_FALSE(absent.ok());
  EXPECT_EQ(absent.error().code, ErrorCode::kNotFound);
  EXPECT_NE(absent.error().message.find("absent.urdf"), std::string::npos);

  Result<UrdfRobot> garbage = UrdfRobot::Load(dir.Write("garbage.urdf", "<robot name=\"x\"><link"));
  ASSERT_FALSE(garbage.ok());
  EXPECT_EQ(garbage.error().code, ErrorCode::kInvalidArgument);
  EXPECT_NE(garbage.error().message.find("garbage.urdf"), std::string::npos);

  // A description still in xacro: the message says to expand it first.
  Result<UrdfRobot> xacro = UrdfRobot::Load(dir.Write(
      "r.urdf.xacro",
      "<robot name=\"x\" xmlns:xacro=\"http://www.ros.org/wiki/xacro\">\n"
      "  <xacro:include filename=\"leg.xacro\"/>\n  <xacro:leg side=\"l\"/>\n</robot>\n"));
  ASSERT_FALSE(xacro.ok());
  EXPECT_EQ(xacro.error().code, ErrorCode::kInvalidArgument);
  EXPECT_NE(xacro.error().message.find("xacro r.urdf.xacro > r.urdf"), std::string::npos)
      << xacro.error().message;
  EXPECT_EQ(garbage.error().message.find("xacro"), std::string::npos) << garbage.error().message;

  dir.Write("bad.stl", "this is not a mesh at all");
  Result<UrdfRobot> bad_mesh = UrdfRobot::Load(dir.Write("r.urdf", MeshRobot("bad.stl", "1 1 1")));
  ASSERT_FALSE(bad_mesh.ok());
  EXPECT_NE(bad_mesh.error().message.find("'base'"), std::string::npos);
  EXPECT_NE(bad_mesh.error().message.find("bad.stl"), std::string::npos);
}

// Numbers urdfdom cannot read make it leave the element out and still return a model; numbers
// it reads but no shape can have (negative sizes) pass through it. Both are errors naming the
// link, not a template silently missing a part.
TEST(UrdfRobotTest, UnreadableOrImpossibleShapeNumbersAreErrors) {
  TempDir dir;
  const auto robot = [](const std::string& head_geometry) {
    return std::string(
               "<robot name=\"r\"><link name=\"base\"><visual><origin xyz=\"0 0 0.3\"/>"
               "<geometry><box size=\"0.2 0.2 0.6\"/></geometry></visual></link>"
               "<link name=\"head\"><visual><geometry>") +
           head_geometry +
           "</geometry></visual></link><joint name=\"neck\" type=\"fixed\"><parent "
           "link=\"base\"/><child link=\"head\"/><origin xyz=\"0 0 0.7\"/></joint></robot>";
  };
  ASSERT_TRUE(UrdfRobot::Load(dir.Write("ok.urdf", robot("<sphere radius=\"0.1\"/>"))).ok());

  const Result<UrdfRobot> nan =
      UrdfRobot::Load(dir.Write("nan.urdf", robot("<sphere radius=\"nan\"/>")));
  ASSERT_FALSE(nan.ok());
  EXPECT_EQ(nan.error().code, ErrorCode::kInvalidArgument);
  EXPECT_NE(nan.error().message.find("nan.urdf"), std::string::npos) << nan.error().message;
  EXPECT_NE(nan.error().message.find("[head]"), std::string::npos) << nan.error().message;

  const Result<UrdfRobot> negative =
      UrdfRobot::Load(dir.Write("neg.urdf", robot("<sphere radius=\"-0.1\"/>")));
  ASSERT_FALSE(negative.ok());
  EXPECT_NE(negative.error().message.find("link 'head': sphere radius (-0.1)"), std::string::npos)
      << negative.error().message;

  const Result<UrdfRobot> box =
      UrdfRobot::Load(dir.Write("box.urdf", robot("<box size=\"0.1 -0.1 0.1\"/>")));
  ASSERT_FALSE(box.ok());
  EXPECT_NE(box.error().message.find("link 'head': box size"), std::string::npos)
      << box.error().message;

  const Result<UrdfRobot> cylinder =
      UrdfRobot::Load(dir.Write("cyl.urdf", robot("<cylinder radius=\"0.1\" length=\"-1\"/>")));
  ASSERT_FALSE(cylinder.ok());
  EXPECT_NE(cylinder.error().message.find("link 'head': cylinder"), std::string::npos)
      << cylinder.error().message;

  // Shapes wider than any template (lengths in millimetres, a mutated file's 100 km sphere, which
  // took all memory to tessellate) are refused before they are tessellated; one just within the
  // limit loads.
  for (const std::string& huge :
       {std::string("<sphere radius=\"100000\"/>"), std::string("<box size=\"200 300 1500\"/>"),
        std::string("<cylinder radius=\"2.6\" length=\"0.1\"/>")}) {
    const Result<UrdfRobot> refused = UrdfRobot::Load(dir.Write("huge.urdf", robot(huge)));
    ASSERT_FALSE(refused.ok()) << huge;
    EXPECT_EQ(refused.error().code, ErrorCode::kInvalidArgument);
    EXPECT_NE(refused.error().message.find("link 'head': "), std::string::npos)
        << refused.error().message;
    EXPECT_NE(refused.error().message.find("more than the 5 m a template may span"),
              std::string::npos)
        << refused.error().message;
  }
  EXPECT_TRUE(UrdfRobot::Load(dir.Write("wide.urdf", robot("<box size=\"5 0.1 0.1\"/>"))).ok());
}

// A joint origin a million kilometres out (a unit slip): the head's single-precision vertices
// there would collapse to a point, so posing refuses it by the link's name; a robot within
// reach of its root poses.
TEST(UrdfRobotTest, ShapesTooFarFromTheRootAreErrorsNamingTheLink) {
  TempDir dir;
  const auto robot = [](const std::string& neck_origin) {
    return "<robot name=\"r\"><link name=\"base\"><visual><origin xyz=\"0 0 0.3\"/>"
           "<geometry><box size=\"0.2 0.2 0.6\"/></geometry></visual></link>"
           "<link name=\"head\"><visual><geometry><sphere radius=\"0.1\"/></geometry></visual>"
           "</link><joint name=\"neck\" type=\"fixed\"><parent link=\"base\"/><child "
           "link=\"head\"/><origin xyz=\"" +
           neck_origin + "\"/></joint></robot>";
  };
  const Result<UrdfRobot> near = UrdfRobot::Load(dir.Write("near.urdf", robot("0 0 0.7")));
  ASSERT_TRUE(near.ok()) << near.error().message;
  EXPECT_TRUE(near->Pose({}).ok());

  const Result<UrdfRobot> far = UrdfRobot::Load(dir.Write("far.urdf", robot("0 0 1e9")));
  ASSERT_TRUE(far.ok()) << far.error().message;  // a valid URDF; the template cannot be made.
  const Result<PosedRobot> posed = far->Pose({});
  ASSERT_FALSE(posed.ok());
  EXPECT_EQ(posed.error().code, ErrorCode::kInvalidArgument);
  EXPECT_NE(posed.error().message.find("link 'head': its shapes lie 1e+09 m"), std::string::npos)
      << posed.error().message;
}

TEST(UrdfRobotTest, DarwinVisualMissingHeadIsAnErrorNamingLinkAndPath) {
  if (!HaveDarwin()) GTEST_SKIP() << "shared Darwin-OP data not found at " << kDarwinUrdf;
  Result<UrdfRobot> robot = UrdfRobot::Load(kDarwinUrdf);
  ASSERT_FALSE(robot.ok());
  EXPECT_EQ(robot.error().code, ErrorCode::kNotFound);
  EXPECT_NE(robot.error().message.find("'MP_HEAD'"), std::string::npos) << robot.error().message;
  EXPECT_NE(robot.error().message.find("meshes/head.STL"), std::string::npos);
}

TEST(UrdfRobotTest, DarwinVisualWithAllowMissingSkipsOnlyTheHead) {
  if (!HaveDarwin()) GTEST_SKIP() << "shared Darwin-OP data not found at " << kDarwinUrdf;
  UrdfLoadOptions options;
  options.allow_missing = true;
  Result<UrdfRobot> robot = UrdfRobot::Load(kDarwinUrdf, options);
  ASSERT_TRUE(robot.ok()) << robot.error().message;
  ASSERT_EQ(robot->skipped().size(), 1u);
  EXPECT_EQ(robot->skipped()[0].link, "MP_HEAD");
  EXPECT_NE(robot->skipped()[0].path.find("head.STL"), std::string::npos);
  Result<PosedRobot> posed = robot->Pose({});
  ASSERT_TRUE(posed.ok()) << posed.error().message;
  // Feet on the floor, the root link (the default reference) straight above or below the
  // template origin (Darwin-OP's base_link is a ground point, 8 mm under its soles).
  EXPECT_NEAR(posed->mesh.Bounds().min().z(), 0.0, 1e-6);
  const Eigen::Vector3d root = posed->template_from_link.at("base_link").translation();
  EXPECT_NEAR(root.head<2>().norm(), 0.0, 1e-9);
  // With the torso as reference, its origin is straight above the template origin.
  Result<PosedRobot> by_body = robot->Pose({}, "MP_BODY");
  ASSERT_TRUE(by_body.ok());
  const Eigen::Vector3d body = by_body->template_from_link.at("MP_BODY").translation();
  EXPECT_NEAR(body.head<2>().norm(), 0.0, 1e-9);
  EXPECT_GT(body.z(), 0.25);
  EXPECT_NEAR(by_body->mesh.Bounds().min().z(), 0.0, 1e-6);
  // Darwin-OP stands about 0.45 m tall; without its head about 0.40 m.
  EXPECT_GT(posed->Height(), 0.35);
  EXPECT_LT(posed->Height(), 0.45);
}

TEST(UrdfRobotTest, DarwinFreeLimbsAreTheArmsAndTheHeadNotTheLegs) {
  if (!HaveDarwin()) GTEST_SKIP() << "shared Darwin-OP data not found at " << kDarwinUrdf;
  UrdfLoadOptions options;
  options.allow_missing = true;
  Result<UrdfRobot> robot = UrdfRobot::Load(kDarwinUrdf, options);
  ASSERT_TRUE(robot.ok()) << robot.error().message;
  // Standing with the arms down, and with the left knee bent and its foot lifted: that leg's
  // lowest point stays low, it is no free limb.
  for (const JointValues& joints :
       {JointValues{{"j_shoulder_l", 1.3}, {"j_shoulder_r", -1.3}},
        JointValues{{"j_thigh2_l", 0.5}, {"j_tibia_l", -1.0}, {"j_ankle1_l", -0.5}}}) {
    Result<PosedRobot> posed = robot->Pose(joints);
    ASSERT_TRUE(posed.ok()) << posed.error().message;
    EXPECT_EQ(posed->free_limb_joints,
              (std::vector<std::string>{"j_pan", "j_shoulder_l", "j_shoulder_r"}));
    EXPECT_GT(posed->free_limbs.Bounds().min().z(), 0.15 * posed->Height());
  }
}

TEST(UrdfRobotTest, DarwinCollisionGeometryHasTheHead) {
  if (!HaveDarwin()) GTEST_SKIP() << "shared Darwin-OP data not found at " << kDarwinUrdf;
  UrdfLoadOptions options;
  options.geometry = UrdfGeometryKind::kCollision;
  Result<UrdfRobot> robot = UrdfRobot::Load(kDarwinUrdf, options);
  ASSERT_TRUE(robot.ok()) << robot.error().message;
  EXPECT_TRUE(robot->skipped().empty());
  Result<PosedRobot> posed = robot->Pose({});
  ASSERT_TRUE(posed.ok());
  // The head is the top of the robot: some triangles lie above the head link's origin.
  const double head_z = posed->template_from_link.at("MP_HEAD").translation().z();
  EXPECT_GT(posed->Height(), head_z + 0.02);
  EXPECT_GT(posed->Height(), 0.42);
}

}  // namespace
}  // namespace hpose
