#include "tools/cmd_template_flags.h"

#include <iostream>
#include <string>

#include "core/common/closest_name.h"
#include "tools/exit_codes.h"

namespace hpose::tools {
namespace {

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

FlagParser TemplateGenerateFlags::Parser() {
  FlagParser flags(
      "hpose template generate --pose standing|right_arm_raised|arms_swung --out FILE.bt "
      "[--resolution M] [--name N]",
      "Builds a template from the parametric Nao-sized humanoid: samples the surface of its\n"
      "primitives in the template frame (origin on the floor below the torso centre, x forward,\n"
      "y left, z up) and voxelises it. Its arms, neck and head are marked as free limbs (fitted\n"
      "without them where a robot holds them otherwise). Writes FILE.bt (OctoMap) and its\n"
      "FILE.json sidecar.");
  flags.AddString("pose", &pose, "joint preset: standing, right_arm_raised or arms_swung", "NAME");
  flags.AddString("body", &body, "proportions: nao, long_legs or tall", "NAME");
  flags.AddString("out", &out, "template file to write (.bt)", "FILE.bt");
  flags.AddDouble("resolution", &resolution, "voxel edge, metres", "M");
  flags.AddString("name", &name, "template name [default: the pose]", "N");
  flags.AddDouble("spacing", &spacing,
                  "surface sample spacing, metres (a quarter of the resolution)", "M");
  flags.SetEpilog(
      "example:\n  hpose template generate --pose standing --out templates/standing.bt");
  return flags;
}

FlagParser TemplateFromCloudFlags::Parser() {
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
  return flags;
}

int RunTemplateSubcommand(const TemplateSubcommands& subs, int argc, char** argv) {
  if (argc < 2) {
    PrintHelp();
    return kExitUsage;
  }
  const std::string sub = argv[1];
  if (sub == "--help" || sub == "-h" || sub == "help") {
    PrintHelp();
    return kExitOk;
  }
  if (sub == "generate") return subs.generate(argc, argv);
  if (sub == "from-cloud") return subs.from_cloud(argc, argv);
  if (sub == "from-captures") return subs.from_captures(argc, argv);
  if (sub == "from-urdf") return subs.from_urdf(argc, argv);
  if (sub == "info") return subs.info(argc, argv);
  if (sub == "show") return subs.show(argc, argv);
  std::cerr << "hpose template: unknown subcommand '" << sub << "'"
            << DidYouMean(sub,
                          {"generate", "from-cloud", "from-captures", "from-urdf", "info", "show"})
            << " (see hpose template --help)\n";
  return kExitUsage;
}

}  // namespace hpose::tools
