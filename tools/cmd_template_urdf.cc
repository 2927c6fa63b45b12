// `hpose template from-urdf`: templates of a robot from its URDF description and meshes, one
// per joint set.
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include "core/robot/urdf_robot.h"
#include "core/sim/triangle_mesh.h"
#include "core/templates/template_io.h"
#include "core/templates/voxel_template.h"
#include "tools/command.h"
#include "tools/exit_codes.h"
#include "tools/fixed_text.h"
#include "tools/flag_parser.h"
#include "tools/robot_flags.h"

namespace hpose::tools {
namespace {

const char kSub[] = "template from-urdf";

// Lists the joints a user may set, with their limits and mimics.
void PrintJoints(const UrdfRobot& robot) {
  std::cout << "robot '" << robot.name() << "': root link " << robot.root_link() << ", "
            << robot.TriangleCount() << " triangles\n";
  for (const UrdfJointInfo& j : robot.joints()) {
    std::cout << "  " << j.name << " (" << j.type << ", " << j.parent_link << " -> " << j.child_link
              << ")";
    if (j.has_limits) std::cout << " limits [" << j.lower << ", " << j.upper << "]";
    if (!j.mimic_of.empty()) {
      std::cout << " mimics " << j.mimic_of << " x " << j.mimic_multiplier << " + "
                << j.mimic_offset;
    }
    std::cout << "\n";
  }
}

std::string SanitisedName(const std::string& text) {
  std::string out;
  for (const char c : text) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                    c == '_' || c == '.' || c == '-';
    out += ok ? c : '_';
  }
  return out.empty() ? "robot" : out;
}

}  // namespace

int TemplateFromUrdf(int argc, char** argv) {
  std::string out, name;
  double resolution = 0.016;
  bool list_joints = false;
  RobotFlags robot_flags;
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
  if (const int code = flags.ParseOrExitCode(argc, argv, 2); code >= 0) return code;
  if (flags.positional().size() != 1) return UsageError(kSub, "give exactly one ROBOT.urdf");
  if (!list_joints && out.empty()) return UsageError(kSub, "--out FILE.bt|DIR is required");
  if (!(resolution >= 0.001 && resolution <= 0.5)) {
    return UsageError(kSub, "--resolution must be in [0.001, 0.5] m");
  }
  const std::string urdf_path = flags.positional().front();
  Result<UrdfRobot> robot = robot_flags.Load(urdf_path, kSub);
  if (!robot.ok()) return ReportError(kSub, robot.error());
  if (list_joints) {
    PrintJoints(*robot);
    return kExitOk;
  }
  Result<std::vector<NamedJointSet>> sets = robot_flags.JointSets(SanitisedName(robot->name()));
  if (!sets.ok()) return ReportError(kSub, sets.error());

  const bool to_directory = sets->size() > 1 || std::filesystem::path(out).extension() != ".bt";
  if (to_directory) {
    std::error_code ec;
    std::filesystem::create_directories(out, ec);
    if (ec) {
      return ReportError(kSub, MakeError(ErrorCode::kInternal,
                                         "cannot create directory " + out + ": " + ec.message()));
    }
  }
  const std::string urdf_file = std::filesystem::path(urdf_path).filename().string();
  std::cout << "robot '" << robot->name() << "': " << robot->TriangleCount() << " triangles ("
            << robot_flags.geometry << " geometry), " << robot->skipped().size()
            << " mesh(es) skipped\n";
  for (const NamedJointSet& set : *sets) {
    Result<PosedRobot> posed = robot->Pose(set.joints, robot_flags.reference_link);
    if (!posed.ok()) return ReportError(kSub, posed.error());
    for (const std::string& note : posed->notes) {
      std::cerr << "hpose " << kSub << ": note: joint set '" << set.name << "': " << note << "\n";
    }
    std::string tpl_name = set.name;
    if (!name.empty()) tpl_name = sets->size() > 1 ? name + "_" + set.name : name;
    const std::string source = "hpose template from-urdf " + urdf_file + " (" +
                               robot_flags.geometry + " geometry, joint set " + set.name +
                               ", reference link " + posed->reference_link + ", " +
                               std::to_string(robot->skipped().size()) + " mesh(es) skipped)";
    Result<VoxelTemplate> tpl =
        MakeMeshTemplate(posed->mesh, tpl_name, resolution, set.name, source);
    if (!tpl.ok()) return ReportError(kSub, tpl.error());
    const std::string path =
        to_directory ? (std::filesystem::path(out) / (set.name + ".bt")).string() : out;
    if (Status s = SaveTemplate(*tpl, path); !s.ok()) return ReportError(kSub, s.error());
    std::cout << "wrote " << path << " and " << TemplateSidecarPath(path) << ": '" << tpl->name
              << "', " << tpl->voxels.size() << " voxels of "
              << Fixed(tpl->resolution_m * 1000.0, 1) << " mm, height "
              << Fixed(tpl->Height() * 1000.0, 0) << " mm\n";
  }
  return kExitOk;
}

}  // namespace hpose::tools
