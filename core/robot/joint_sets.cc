#include "core/robot/joint_sets.h"

#include <cmath>
#include <fstream>
#include <set>
#include <sstream>

#include <yaml-cpp/yaml.h>

namespace hpose {
namespace {

bool ValidSetName(const std::string& name) {
  if (name.empty()) return false;
  for (const char c : name) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                    c == '_' || c == '.' || c == '-';
    if (!ok) return false;
  }
  return true;
}

// Parses a whole string as a finite double.
bool ParseFinite(const std::string& text, double* value) {
  std::istringstream in(text);
  double v = 0.0;
  char extra = 0;
  if (!(in >> v) || (in >> extra) || !std::isfinite(v)) return false;
  *value = v;
  return true;
}

}  // namespace

Result<std::vector<NamedJointSet>> ParseJointSetsYaml(const std::string& text,
                                                      const std::string& origin) {
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    return MakeError(ErrorCode::kInvalidArgument, origin + ": not valid YAML: " + e.what());
  }
  if (!root.IsMap() || root.size() == 0) {
    return MakeError(ErrorCode::kInvalidArgument,
                     origin + ": expected a map of joint-set names to {joint: position} maps");
  }
  std::vector<NamedJointSet> sets;
  std::set<std::string> names;
  for (const auto& entry : root) {
    const std::string name = entry.first.Scalar();
    if (!ValidSetName(name)) {
      return MakeError(ErrorCode::kInvalidArgument,
                       origin + ": joint-set name '" + name + "' must be [A-Za-z0-9_.-]");
    }
    if (!names.insert(name).second) {
      return MakeError(ErrorCode::kInvalidArgument,
                       origin + ": joint set '" + name + "' is given twice");
    }
    NamedJointSet set{name, {}};
    const YAML::Node& joints = entry.second;
    if (!joints.IsNull() && !joints.IsMap()) {
      return MakeError(ErrorCode::kInvalidArgument,
                       origin + ": joint set '" + name + "' must be a map of joint: position");
    }
    if (joints.IsMap()) {
      for (const auto& j : joints) {
        const std::string joint = j.first.Scalar();
        double v = 0.0;
        if (!j.second.IsScalar() || !ParseFinite(j.second.Scalar(), &v)) {
          return MakeError(ErrorCode::kInvalidArgument,
                           origin + ": joint set '" + name + "', joint '" + joint +
                               "': position must be a finite number (radians or metres)");
        }
        set.joints[joint] = v;
      }
    }
    sets.push_back(std::move(set));
  }
  return sets;
}

Result<std::vector<NamedJointSet>> LoadJointSetsFile(const std::string& path) {
  std::ifstream in(path);
  if (!in) return MakeError(ErrorCode::kNotFound, "cannot read joint-set file " + path);
  std::ostringstream text;
  text << in.rdbuf();
  return ParseJointSetsYaml(text.str(), path);
}

Status ParseJointAssignment(const std::string& text, JointValues* values) {
  const size_t eq = text.find('=');
  if (eq == std::string::npos || eq == 0) {
    return MakeError(ErrorCode::kInvalidArgument,
                     "joint position '" + text + "' must be NAME=VALUE (radians or metres)");
  }
  double v = 0.0;
  if (!ParseFinite(text.substr(eq + 1), &v)) {
    return MakeError(ErrorCode::kInvalidArgument,
                     "joint position '" + text + "': the value must be a finite number");
  }
  (*values)[text.substr(0, eq)] = v;
  return Status::Ok();
}

}  // namespace hpose
