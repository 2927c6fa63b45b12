#include "tools/cmd_template_urdf_flags.h"

namespace hpose::tools {

FlagParser TemplateFromUrdfFlags::Parser() {
  FlagParser flags(
      "hpose template from-urdf ROBOT.urdf --out FILE.bt|DIR [--geometry visual|collision] "
      "[--package-path DIR]... [--joint NAME=RAD]... [--joints FILE.yaml [--joint-set NAME]...] "
      "[--reference-link LINK] [--resolution M] [--allow-missing]",
      "Makes templates of a robot from its URDF: poses the links by forward kinematics, loads\n"
      "their visual (default) or collision shapes (meshes in any format assimp reads - STL,\n"
      "COLLADA, OBJ... - with their URDF scale, and boxes, cylinders and spheres) and marks\n"
      "every voxel the surface passes through, so no voxel is missed however small the\n"
      "triangles. The template frame: origin on the floor below the reference link's origin,\n"
      "x along that link's x axis projected on the floor, z up; the floor touches the posed\n"
      "robot's lowest point (its feet). With --joints FILE.yaml every joint set gives one\n"
      "template (several sets: --out is a directory and each set is written as SET.bt).\n"
      "Mimic joints follow their leader; a position outside a joint's limits is an error.");
  flags.AllowPositional("ROBOT.urdf");
  flags.AddString("out", &out,
                  "template file to write (.bt), or a directory for one file per joint set",
                  "FILE.bt|DIR");
  flags.AddDouble("resolution", &resolution, "voxel edge, metres", "M");
  flags.AddString("name", &name,
                  "template name [default: the joint set's name, or the robot's without "
                  "--joints]; with several sets, NAME_SET",
                  "N");
  robot_flags.Register(&flags, /*one_set=*/false);
  flags.AddBool("list-joints", &list_joints, "print the robot's joints and limits, and exit");
  flags.SetEpilog(
      "examples:\n"
      "  hpose template from-urdf ../shared/data/darwin_op/robots/robotis_op.urdf \\\n"
      "      --geometry collision --out darwin.bt\n"
      "  hpose template from-urdf robot.urdf --package-path ~/ws/src --joints poses.yaml \\\n"
      "      --out templates/robot/\n"
      "joint-set file (radians; joints not named stay at 0):\n"
      "  standing: {}\n"
      "  right_arm_raised: {j_shoulder_r: 1.3}\n"
      "\nexit status: 0 ok, 1 bad robot, mesh or joints, 2 bad flags");
  return flags;
}

}  // namespace hpose::tools
