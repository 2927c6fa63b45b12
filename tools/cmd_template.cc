// `hpose template`: makes humanoid templates (from the parametric model or from a cloud) and
// describes template files.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include "core/io/cloud_io.h"
#include "core/sim/humanoid_model.h"
#include "core/templates/template_io.h"
#include "core/templates/voxel_template.h"
#include "tools/command.h"
#include "tools/exit_codes.h"
#include "tools/fixed_text.h"
#include "tools/flag_parser.h"

namespace hpose::tools {
namespace {

const char kTemplateCmd[] = "template";

void PrintSaved(const VoxelTemplate& tpl, const std::string& path) {
  std::cout << "wrote " << path << " and " << TemplateSidecarPath(path) << ": '" << tpl.name
            << "', " << tpl.voxels.size() << " voxels of " << Fixed(tpl.resolution_m * 1000.0, 1)
            << " mm, height " << Fixed(tpl.Height() * 1000.0, 0) << " mm\n";
}

int Generate(int argc, char** argv) {
  std::string pose = "standing", body = "nao", out, name;
  double resolution = 0.016, spacing = 0.004;
  FlagParser flags(
      "hpose template generate --pose standing|right_arm_raised --out FILE.bt "
      "[--resolution M] [--name N]",
      "Builds a template from the parametric Nao-sized humanoid: samples the surface of its\n"
      "primitives in the template frame (origin on the floor below the torso centre, x forward,\n"
      "y left, z up) and voxelises it. Writes FILE.bt (OctoMap) and its FILE.json sidecar.");
  flags.AddString("pose", &pose, "joint preset: standing or right_arm_raised", "NAME");
  flags.AddString("body", &body, "proportions: nao, long_legs or tall", "NAME");
  flags.AddString("out", &out, "template file to write (.bt)", "FILE.bt");
  flags.AddDouble("resolution", &resolution, "voxel edge, metres", "M");
  flags.AddString("name", &name, "template name [default: the pose]", "N");
  flags.AddDouble("spacing", &spacing,
                  "surface sample spacing, metres (a quarter of the resolution)", "M");
  flags.SetEpilog(
      "example:\n  hpose template generate --pose standing --out templates/standing.bt");
  if (const int code = flags.ParseOrExitCode(argc, argv, 2); code >= 0) return code;
  if (out.empty()) return UsageError("template generate", "--out FILE.bt is required");
  if (!(resolution >= 0.001 && resolution <= 0.5)) {
    return UsageError("template generate", "--resolution must be in [0.001, 0.5] m");
  }
  if (!flags.Seen("spacing")) spacing = 0.25 * resolution;
  if (name.empty()) name = pose;

  Result<HumanoidDimensions> dimensions = HumanoidDimensions::Variant(body);
  if (!dimensions.ok())
    return UsageError("template generate", "--body: " + dimensions.error().message);
  Result<HumanoidModel> model = HumanoidModel::FromPreset(pose, *dimensions);
  if (!model.ok()) return UsageError("template generate", "--pose: " + model.error().message);
  Result<std::vector<Eigen::Vector3f>> points = model->SampleSurface(spacing);
  if (!points.ok()) return UsageError("template generate", "--spacing: " + points.error().message);
  const std::string source = "hpose template generate --pose " + pose +
                             (body == "nao" ? "" : " --body " + body) + " --resolution " +
                             Fixed(resolution, 4) + " (parametric humanoid, " +
                             Fixed(model->Height(), 3) + " m tall)";
  Result<VoxelTemplate> tpl = MakeTemplateFromPoints(*points, name, resolution, pose, source);
  if (!tpl.ok()) return UsageError("template generate", tpl.error().message);
  if (Status s = SaveTemplate(*tpl, out); !s.ok()) return ReportError(kTemplateCmd, s.error());
  PrintSaved(*tpl, out);
  return kExitOk;
}

int FromCloud(int argc, char** argv) {
  std::string out, name, variant;
  double resolution = 0.016;
  FlagParser flags(
      "hpose template from-cloud ROBOT.pcd|ROBOT.ply --name N --out FILE.bt [--resolution M]",
      "Makes a template from a point cloud of a robot that is already expressed in the\n"
      "template frame (metres; origin on the floor below the torso centre, x forward, y left,\n"
      "z up). Non-finite points are skipped. Writes FILE.bt and its FILE.json sidecar.");
  flags.AllowPositional("ROBOT.pcd|ROBOT.ply");
  flags.AddString("name", &name, "template name ([A-Za-z0-9_.-])", "N");
  flags.AddString("out", &out, "template file to write (.bt)", "FILE.bt");
  flags.AddDouble("resolution", &resolution, "voxel edge, metres", "M");
  flags.AddString("variant", &variant, "shape label, e.g. standing [default: the name]", "V");
  if (const int code = flags.ParseOrExitCode(argc, argv, 2); code >= 0) return code;
  if (flags.positional().size() != 1) {
    return UsageError("template from-cloud", "give exactly one cloud file (.pcd or .ply)");
  }
  if (name.empty()) return UsageError("template from-cloud", "--name N is required");
  if (out.empty()) return UsageError("template from-cloud", "--out FILE.bt is required");
  if (!(resolution >= 0.001 && resolution <= 0.5)) {
    return UsageError("template from-cloud", "--resolution must be in [0.001, 0.5] m");
  }
  const std::string cloud_path = flags.positional().front();
  Result<PointCloud> cloud = ReadCloud(cloud_path);
  if (!cloud.ok()) return ReportError(kTemplateCmd, cloud.error());
  const std::string source =
      "hpose template from-cloud " + std::filesystem::path(cloud_path).filename().string();
  Result<VoxelTemplate> tpl = MakeTemplateFromPoints(cloud->points, name, resolution,
                                                     variant.empty() ? name : variant, source);
  if (!tpl.ok()) return ReportError(kTemplateCmd, tpl.error());
  if (Status s = SaveTemplate(*tpl, out); !s.ok()) return ReportError(kTemplateCmd, s.error());
  PrintSaved(*tpl, out);
  return kExitOk;
}

void PrintHelp() {
  std::cout << "usage: hpose template SUBCOMMAND [--help] [options]\n\n"
               "Makes and inspects humanoid templates (OctoMap .bt + .json sidecar).\n\n"
               "subcommands:\n"
               "  generate      template of the parametric humanoid (poses, --body proportions)\n"
               "  from-cloud    template from a robot's point cloud in the template frame\n"
               "  from-captures 360 degree template from turntable / hand-turned captures\n"
               "  from-urdf     templates from a robot's URDF and meshes, one per joint set\n"
               "  info          print what a template file holds: size, widths, asymmetry\n"
               "  show          draw a template: front, side, top and Kinect views\n\n"
               "Run `hpose template SUBCOMMAND --help` for its options.\n";
}

}  // namespace

int RunTemplate(int argc, char** argv) {
  if (argc < 2) {
    PrintHelp();
    return kExitUsage;
  }
  const std::string sub = argv[1];
  if (sub == "--help" || sub == "-h" || sub == "help") {
    PrintHelp();
    return kExitOk;
  }
  if (sub == "generate") return Generate(argc, argv);
  if (sub == "from-cloud") return FromCloud(argc, argv);
  if (sub == "from-captures") return RunTemplateFromCaptures(argc, argv);
  if (sub == "from-urdf") return TemplateFromUrdf(argc, argv);
  if (sub == "info") return TemplateInfo(argc, argv);
  if (sub == "show") return TemplateShow(argc, argv);
  std::cerr << "hpose template: unknown subcommand '" << sub << "' (see hpose template --help)\n";
  return kExitUsage;
}

}  // namespace hpose::tools
