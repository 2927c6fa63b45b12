#include "core/robot/package_resolver.h"

#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>

namespace hpose {
namespace {

namespace fs = std::filesystem;

constexpr int kMaxSearchDepth = 4;

// The <name> of a package.xml in `dir`, or "" when there is none.
std::string PackageXmlName(const fs::path& dir) {
  std::ifstream in(dir / "package.xml");
  if (!in) return "";
  std::ostringstream text;
  text << in.rdbuf();
  static const std::regex kName("<name>\\s*([^<\\s]+)\\s*</name>");
  std::smatch m;
  const std::string s = text.str();
  return std::regex_search(s, m, kName) ? m[1].str() : "";
}

bool IsPackage(const fs::path& dir, const std::string& name) {
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) return false;
  const std::string xml_name = PackageXmlName(dir);
  if (!xml_name.empty()) return xml_name == name;
  return dir.filename() == name;
}

bool Search(const fs::path& dir, const std::string& name, int depth, fs::path* found) {
  if (IsPackage(dir, name)) {
    *found = dir;
    return true;
  }
  if (depth >= kMaxSearchDepth) return false;
  std::error_code ec;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    if (it->is_directory(ec) && Search(it->path(), name, depth + 1, found)) return true;
  }
  return false;
}

}  // namespace

Result<std::string> ResolveUrdfResource(const std::string& uri, const std::string& urdf_dir,
                                        const std::vector<std::string>& package_paths) {
  if (uri.empty()) return MakeError(ErrorCode::kInvalidArgument, "empty mesh file name");
  const std::string kPackage = "package://";
  const std::string kFile = "file://";
  if (uri.rfind(kFile, 0) == 0) return uri.substr(kFile.size());
  if (uri.rfind(kPackage, 0) != 0) {
    const fs::path p(uri);
    return p.is_absolute() ? p.string() : (fs::path(urdf_dir) / p).lexically_normal().string();
  }
  const std::string rest = uri.substr(kPackage.size());
  const size_t slash = rest.find('/');
  if (slash == std::string::npos || slash == 0 || slash + 1 == rest.size()) {
    return MakeError(ErrorCode::kInvalidArgument,
                     "'" + uri + "' must be package://PACKAGE/PATH/IN/PACKAGE");
  }
  const std::string name = rest.substr(0, slash);
  const std::string inside = rest.substr(slash + 1);
  fs::path found;
  std::string searched;
  for (const std::string& dir : package_paths) {
    searched += (searched.empty() ? "" : ", ") + dir;
    if (Search(fs::path(dir), name, 0, &found)) return (found / inside).lexically_normal().string();
  }
  // Like a ROS workspace: the URDF usually lives inside its own package. Walk up the path as
  // given first (so messages keep relative paths relative), then the absolute one.
  std::error_code ec;
  for (fs::path start : {fs::path(urdf_dir).lexically_normal(), fs::absolute(urdf_dir, ec)}) {
    fs::path dir = start.empty() ? fs::path(".") : start;
    for (int up = 0; up <= kMaxSearchDepth && !dir.empty(); ++up) {
      if (PackageXmlName(dir) == name) return (dir / inside).lexically_normal().string();
      if (dir == dir.parent_path() || dir.filename() == "..") break;
      dir = dir.parent_path();
    }
  }
  searched += std::string(searched.empty() ? "" : ", ") + "the URDF's parent directories";
  return MakeError(ErrorCode::kNotFound, "package '" + name + "' of '" + uri +
                                             "' not found (searched " + searched +
                                             "; add its directory with --package-path)");
}

}  // namespace hpose
