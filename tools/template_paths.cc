#include "tools/template_paths.h"

#include <cstdlib>

#include "core/templates/template_io.h"
#include "server/daemon_config.h"

#ifndef HPOSE_TEMPLATE_DIR
#define HPOSE_TEMPLATE_DIR "templates"
#endif

namespace hpose::tools {

std::string DefaultTemplateDir() {
  const char* env = std::getenv("HPOSE_TEMPLATE_DIR");
  return (env != nullptr && *env != '\0') ? env : HPOSE_TEMPLATE_DIR;
}

std::vector<std::string> DefaultTemplatePaths() {
  const std::string dir = DefaultTemplateDir();
  return {dir + "/standing.bt", dir + "/right_arm_raised.bt"};
}

std::vector<std::string> ResolveTemplateNames(const std::vector<std::string>& entries) {
  std::vector<std::string> out;
  for (const std::string& e : entries) {
    out.push_back(server::IsTemplateName(e) ? DefaultTemplateDir() + "/" + e + ".bt" : e);
  }
  return out;
}

Result<std::vector<VoxelTemplate>> LoadTemplates(const std::vector<std::string>& paths) {
  const std::vector<std::string> use = paths.empty() ? DefaultTemplatePaths() : paths;
  std::vector<VoxelTemplate> out;
  for (const std::string& p : use) {
    Result<VoxelTemplate> t = LoadTemplate(p);
    if (!t.ok()) {
      Error e = t.error();
      if (paths.empty() && e.code == ErrorCode::kNotFound) {
        e.message += " (the shipped templates are looked up in " + DefaultTemplateDir() +
                     "; set HPOSE_TEMPLATE_DIR or pass --template)";
      }
      return e;
    }
    out.push_back(std::move(t).value());
  }
  return out;
}

}  // namespace hpose::tools
