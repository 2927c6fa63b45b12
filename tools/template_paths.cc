#include "tools/template_paths.h"

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <system_error>

#include "core/common/closest_name.h"
#include "core/templates/template_io.h"
#include "server/daemon_config.h"

// The source tree's templates/ (a build run in place) and the installed templates' directory
// relative to the installed programs' directory (e.g. "../share/hpose/templates").
#ifndef HPOSE_TEMPLATE_DIR
#define HPOSE_TEMPLATE_DIR "templates"
#endif
#ifndef HPOSE_INSTALLED_TEMPLATE_DIR_FROM_BIN
#define HPOSE_INSTALLED_TEMPLATE_DIR_FROM_BIN "../share/hpose/templates"
#endif
// The same from the command programs' directory (<prefix>/libexec/hpose).
#ifndef HPOSE_INSTALLED_TEMPLATE_DIR_FROM_LIBEXEC
#define HPOSE_INSTALLED_TEMPLATE_DIR_FROM_LIBEXEC "../../share/hpose/templates"
#endif

namespace hpose::tools {

namespace {

// The installed templates beside the running program (<prefix>/bin/../share/hpose/templates,
// or from <prefix>/libexec/hpose), or "" when the program does not run from an installation (e.g.
// from the build tree).
std::string InstalledTemplateDir() {
  std::error_code ec;
  const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (ec || exe.empty()) return "";
  for (const char* relative :
       {HPOSE_INSTALLED_TEMPLATE_DIR_FROM_BIN, HPOSE_INSTALLED_TEMPLATE_DIR_FROM_LIBEXEC}) {
    const std::filesystem::path dir = (exe.parent_path() / relative).lexically_normal();
    if (std::filesystem::is_regular_file(dir / "standing.bt", ec)) return dir.string();
  }
  return "";
}

}  // namespace

std::string DefaultTemplateDir() {
  const char* env = std::getenv("HPOSE_TEMPLATE_DIR");
  if (env != nullptr && *env != '\0') return env;
  static const std::string installed = InstalledTemplateDir();
  return installed.empty() ? HPOSE_TEMPLATE_DIR : installed;
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

Status CheckTemplateNames(const std::vector<std::string>& entries) {
  const std::string dir = DefaultTemplateDir();
  for (const std::string& entry : entries) {
    std::error_code ec;
    if (!server::IsTemplateName(entry) || std::filesystem::exists(dir + "/" + entry + ".bt", ec)) {
      continue;
    }
    std::vector<std::string> names;
    for (std::filesystem::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
      if (it->path().extension() == ".bt") names.push_back(it->path().stem().string());
    }
    std::sort(names.begin(), names.end());
    std::string shipped;
    for (const std::string& name : names) shipped += (shipped.empty() ? "" : ", ") + name;
    const std::string meant = ClosestName(entry, names);
    return MakeError(ErrorCode::kNotFound,
                     "'" + entry + "' is no shipped template (" +
                         (shipped.empty() ? "none found" : "those are " + shipped) + ", in " + dir +
                         "); " +
                         (meant.empty() ? "give" : "did you mean '" + meant + "'? Or give") +
                         " a template file by its path, FILE.bt");
  }
  return Status::Ok();
}

Result<VoxelTemplate> LoadTemplateEntry(const std::string& entry) {
  if (!server::IsTemplateName(entry)) return LoadTemplate(entry);
  const Status shipped = CheckTemplateNames({entry});
  if (!shipped.ok()) return shipped.error();
  return LoadTemplate(DefaultTemplateDir() + "/" + entry + ".bt");
}

Result<std::vector<VoxelTemplate>> LoadTemplates(const std::vector<std::string>& entries) {
  const std::vector<std::string> use = entries.empty() ? DefaultTemplatePaths() : entries;
  std::vector<VoxelTemplate> out;
  for (const std::string& e : use) {
    Result<VoxelTemplate> t = LoadTemplateEntry(e);
    if (!t.ok()) {
      Error error = t.error();
      if (entries.empty() && error.code == ErrorCode::kNotFound) {
        error.message += " (the shipped templates are looked up in " + DefaultTemplateDir() +
                         "; set HPOSE_TEMPLATE_DIR or pass --template)";
      }
      return error;
    }
    out.push_back(std::move(t).value());
  }
  return out;
}

}  // namespace hpose::tools
