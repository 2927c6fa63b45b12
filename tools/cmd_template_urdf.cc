// `hpose template from-urdf`: templates of a robot from its URDF description and meshes, one
// per joint set.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include "core/robot/urdf_robot.h"
#include "core/sim/triangle_mesh.h"
#include "core/templates/template_io.h"
#include "core/templates/voxel_template.h"
#include "tools/cmd_template_urdf_flags.h"
#include "tools/command.h"
#include "tools/exit_codes.h"
#include "tools/flag_parser.h"
#include "tools/robot_flags.h"
#include "tools/template_saved.h"

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
  TemplateFromUrdfFlags f;
  FlagParser flags = f.Parser();
  if (const int code = flags.ParseOrExitCode(argc, argv, 2); code >= 0) return code;
  if (flags.positional().size() != 1) return UsageError(kSub, "give exactly one ROBOT.urdf");
  if (!f.list_joints && f.out.empty()) return UsageError(kSub, "--out FILE.bt|DIR is required");
  if (!(f.resolution >= 0.001 && f.resolution <= 0.5)) {
    return UsageError(kSub, "--resolution must be in [0.001, 0.5] m");
  }
  const std::string urdf_path = flags.positional().front();
  Result<UrdfRobot> robot = f.robot_flags.Load(urdf_path, kSub);
  if (!robot.ok()) return ReportError(kSub, robot.error());
  if (f.list_joints) {
    PrintJoints(*robot);
    return kExitOk;
  }
  Result<std::vector<NamedJointSet>> sets = f.robot_flags.JointSets(SanitisedName(robot->name()));
  if (!sets.ok()) return ReportError(kSub, sets.error());

  const bool to_directory = sets->size() > 1 || std::filesystem::path(f.out).extension() != ".bt";
  if (to_directory) {
    std::error_code ec;
    std::filesystem::create_directories(f.out, ec);
    if (ec) {
      return ReportError(kSub, MakeError(ErrorCode::kInternal,
                                         "cannot create directory " + f.out + ": " + ec.message()));
    }
  }
  const std::string urdf_file = std::filesystem::path(urdf_path).filename().string();
  std::cout << "robot '" << robot->name() << "': " << robot->TriangleCount() << " triangles ("
            << f.robot_flags.geometry << " geometry), " << robot->skipped().size()
            << " mesh(es) skipped\n";
  for (const NamedJointSet& set : *sets) {
    Result<PosedRobot> posed = robot->Pose(set.joints, f.robot_flags.reference_link);
    if (!posed.ok()) return ReportError(kSub, posed.error());
    for (const std::string& note : posed->notes) {
      std::cerr << "hpose " << kSub << ": note: joint set '" << set.name << "': " << note << "\n";
    }
    std::string tpl_name = set.name;
    if (!f.name.empty()) tpl_name = sets->size() > 1 ? f.name + "_" + set.name : f.name;
    const std::string source = "hpose template from-urdf " + urdf_file + " (" +
                               f.robot_flags.geometry + " geometry, joint set " + set.name +
                               ", reference link " + posed->reference_link + ", " +
                               std::to_string(robot->skipped().size()) + " mesh(es) skipped)";
    Result<VoxelTemplate> tpl =
        MakeMeshTemplate(posed->mesh, tpl_name, f.resolution, set.name, source, &posed->free_limbs);
    if (!tpl.ok()) return ReportError(kSub, tpl.error());
    const std::string path =
        to_directory ? (std::filesystem::path(f.out) / (set.name + ".bt")).string() : f.out;
    if (Status s = SaveTemplate(*tpl, path); !s.ok()) return ReportError(kSub, s.error());
    std::cout << SavedTemplateLines(*tpl, path);
    if (!posed->free_limb_joints.empty()) {
      const long marked = std::count(tpl->free_limb.begin(), tpl->free_limb.end(), 1);
      std::cout << "  free limbs (fitted without them where they moved): ";
      for (size_t k = 0; k < posed->free_limb_joints.size(); ++k) {
        std::cout << (k > 0 ? ", " : "") << posed->free_limb_joints[k];
      }
      std::cout << "; " << marked << " of " << tpl->surface.size() << " surface points\n";
    }
  }
  return kExitOk;
}

}  // namespace hpose::tools
