#ifndef HPOSE_TOOLS_TEMPLATE_PATHS_H_
#define HPOSE_TOOLS_TEMPLATE_PATHS_H_

#include <string>
#include <vector>

#include "core/common/status.h"
#include "core/templates/voxel_template.h"

namespace hpose::tools {

// The directory of the templates shipped with hpose: $HPOSE_TEMPLATE_DIR when set; else, for
// an installed program, the installed templates (<prefix>/share/hpose/templates, found from the
// program's own location, so a relocated installation keeps working); else the source tree's
// templates/ (a program run from the build tree).
std::string DefaultTemplateDir();

// The shipped templates (standing, right_arm_raised) as paths.
std::vector<std::string> DefaultTemplatePaths();

// `entries` with every shipped template's name ("standing", see server::IsTemplateName)
// replaced by its path in DefaultTemplateDir(); paths are kept.
std::vector<std::string> ResolveTemplateNames(const std::vector<std::string>& entries);

// An error naming the first entry that is a name (see server::IsTemplateName) but no shipped
// template, and listing the shipped ones; paths are not checked.
Status CheckTemplateNames(const std::vector<std::string>& entries);

// Loads a template file, or a shipped template by its name ("standing": see
// server::IsTemplateName); an unknown name's error lists the shipped ones.
Result<VoxelTemplate> LoadTemplateEntry(const std::string& entry);

// LoadTemplateEntry() of each entry; an empty list loads the shipped templates. The first
// failure is returned (its message names the file).
Result<std::vector<VoxelTemplate>> LoadTemplates(const std::vector<std::string>& entries);

}  // namespace hpose::tools

#endif  // HPOSE_TOOLS_TEMPLATE_PATHS_H_
