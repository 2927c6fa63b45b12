#ifndef HPOSE_TOOLS_CMD_TEMPLATE_FLAGS_H_
#define HPOSE_TOOLS_CMD_TEMPLATE_FLAGS_H_

#include <string>

#include "tools/command.h"
#include "tools/flag_parser.h"

namespace hpose::tools {

// The flags of `hpose template generate`, holding their defaults until parsed.
struct TemplateGenerateFlags {
  std::string pose = "standing", body = "nao", out, name;
  double resolution = 0.016, spacing = 0.004;

  // The command's parser, writing into these fields (which must outlive it).
  FlagParser Parser();
};

// The flags of `hpose template from-cloud`, holding their defaults until parsed.
struct TemplateFromCloudFlags {
  std::string out, name, variant;
  double resolution = 0.016;

  // The command's parser, writing into these fields (which must outlive it).
  FlagParser Parser();
};

// What `hpose template SUBCOMMAND` runs for each subcommand: its work in the command's program,
// the check of its flags in the `hpose` front end.
struct TemplateSubcommands {
  CommandFn generate, from_cloud, from_captures, from_urdf, info, show;
};

// `hpose template`: runs the subcommand argv[1] names (its flags from argv[2] on), or lists the
// subcommands.
int RunTemplateSubcommand(const TemplateSubcommands& subs, int argc, char** argv);

}  // namespace hpose::tools

#endif  // HPOSE_TOOLS_CMD_TEMPLATE_FLAGS_H_
