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
#include "core/sim/humanoid_template.h"
#include "core/templates/template_io.h"
#include "core/templates/voxel_template.h"
#include "tools/cmd_template_flags.h"
#include "tools/command.h"
#include "tools/exit_codes.h"
#include "tools/fixed_text.h"
#include "tools/flag_parser.h"
#include "tools/template_saved.h"

namespace hpose::tools {
namespace {

const char kTemplateCmd[] = "template";

void PrintSaved(const VoxelTemplate& tpl, const std::string& path) {
  std::cout << SavedTemplateLines(tpl, path);
}

int Generate(int argc, char** argv) {
  TemplateGenerateFlags f;
  FlagParser flags = f.Parser();
  if (const int code = flags.ParseOrExitCode(argc, argv, 2); code >= 0) return code;
  if (f.out.empty()) return UsageError("template generate", "--out FILE.bt is required");
  if (!(f.resolution >= 0.001 && f.resolution <= 0.5)) {
    return UsageError("template generate", "--resolution must be in [0.001, 0.5] m");
  }
  if (!flags.Seen("spacing")) f.spacing = 0.25 * f.resolution;
  if (!(f.spacing >= 0.0005 && f.spacing <= 0.1)) {
    return UsageError(
        "template generate",
        "--spacing (by default a quarter of --resolution) must be in [0.0005, 0.1] m");
  }
  if (f.name.empty()) f.name = f.pose;

  Result<HumanoidDimensions> dimensions = HumanoidDimensions::Variant(f.body);
  if (!dimensions.ok())
    return UsageError("template generate", "--body: " + dimensions.error().message);
  Result<HumanoidModel> model = HumanoidModel::FromPreset(f.pose, *dimensions);
  if (!model.ok()) return UsageError("template generate", "--pose: " + model.error().message);
  const std::string source = "hpose template generate --pose " + f.pose +
                             (f.body == "nao" ? "" : " --body " + f.body) + " --resolution " +
                             Fixed(f.resolution, 4) + " (parametric humanoid, " +
                             Fixed(model->Height(), 3) + " m tall)";
  Result<VoxelTemplate> tpl =
      MakeHumanoidTemplate(*model, f.name, f.resolution, f.pose, source, f.spacing);
  if (!tpl.ok()) return UsageError("template generate", tpl.error().message);
  if (Status s = SaveTemplate(*tpl, f.out); !s.ok()) return ReportError(kTemplateCmd, s.error());
  PrintSaved(*tpl, f.out);
  return kExitOk;
}

int FromCloud(int argc, char** argv) {
  TemplateFromCloudFlags f;
  FlagParser flags = f.Parser();
  if (const int code = flags.ParseOrExitCode(argc, argv, 2); code >= 0) return code;
  if (flags.positional().size() != 1) {
    return UsageError("template from-cloud", "give exactly one cloud file (.pcd or .ply)");
  }
  if (f.name.empty()) return UsageError("template from-cloud", "--name N is required");
  if (f.out.empty()) return UsageError("template from-cloud", "--out FILE.bt is required");
  if (!(f.resolution >= 0.001 && f.resolution <= 0.5)) {
    return UsageError("template from-cloud", "--resolution must be in [0.001, 0.5] m");
  }
  const std::string cloud_path = flags.positional().front();
  Result<PointCloud> cloud = ReadCloud(cloud_path);
  if (!cloud.ok()) return ReportError(kTemplateCmd, cloud.error());
  const std::string source =
      "hpose template from-cloud " + std::filesystem::path(cloud_path).filename().string();
  Result<VoxelTemplate> tpl = MakeTemplateFromPoints(
      cloud->points, f.name, f.resolution, f.variant.empty() ? f.name : f.variant, source);
  if (!tpl.ok()) return ReportError(kTemplateCmd, tpl.error());
  if (Status s = SaveTemplate(*tpl, f.out); !s.ok()) return ReportError(kTemplateCmd, s.error());
  PrintSaved(*tpl, f.out);
  return kExitOk;
}

}  // namespace

int RunTemplate(int argc, char** argv) {
  return RunTemplateSubcommand(
      {Generate, FromCloud, RunTemplateFromCaptures, TemplateFromUrdf, TemplateInfo, TemplateShow},
      argc, argv);
}

}  // namespace hpose::tools
