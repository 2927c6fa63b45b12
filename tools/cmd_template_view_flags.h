#ifndef HPOSE_TOOLS_CMD_TEMPLATE_VIEW_FLAGS_H_
#define HPOSE_TOOLS_CMD_TEMPLATE_VIEW_FLAGS_H_

#include <string>

#include "tools/flag_parser.h"
#include "tools/template_picture.h"

namespace hpose::tools {

// The flags of `hpose template info`, holding their defaults until parsed.
struct TemplateInfoFlags {
  bool json = false;

  // The command's parser, writing into these fields (which must outlive it).
  FlagParser Parser();
};

// The flags of `hpose template show`, holding their defaults until parsed.
struct TemplateShowFlags {
  std::string picture;
  TemplatePictureOptions options;

  // The command's parser, writing into these fields (which must outlive it).
  FlagParser Parser();
};

}  // namespace hpose::tools

#endif  // HPOSE_TOOLS_CMD_TEMPLATE_VIEW_FLAGS_H_
