#include "core/io/intrinsics_file.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cctype>
#include <exception>
#include <fstream>
#include <vector>

#include "core/io/input_file.h"
#include "core/io/intrinsics_json.h"

namespace hpose {

namespace {

// The first of `keys` that `node` has, or an undefined node.
YAML::Node FirstOf(const YAML::Node& node, std::initializer_list<const char*> keys) {
  for (const char* k : keys) {
    if (node[k]) return node[k];
  }
  return YAML::Node(YAML::NodeType::Undefined);
}

Result<Intrinsics> ReadCameraInfoYaml(const std::string& path) {
  {
    std::ifstream in(path);
    if (!in) return MakeError(ErrorCode::kNotFound, path + ": no such file");
  }
  YAML::Node root;
  try {
    root = YAML::LoadFile(path);
  } catch (const std::exception& e) {
    return FileDataLoss(path, std::string("not valid YAML (") + e.what() + ")");
  }
  if (!root.IsMap()) return FileDataLoss(path, "expected a ROS camera_info mapping");
  const YAML::Node width = FirstOf(root, {"image_width", "width"});
  const YAML::Node height = FirstOf(root, {"image_height", "height"});
  if (!width || !height) {
    return FileDataLoss(path, "missing image_width/image_height (or width/height)");
  }
  YAML::Node matrix = FirstOf(root, {"camera_matrix", "K", "k"});
  if (!matrix) return FileDataLoss(path, "missing camera_matrix (or K)");
  if (matrix.IsMap()) matrix = matrix["data"];
  if (!matrix || !matrix.IsSequence() || matrix.size() != 9) {
    return FileDataLoss(path, "camera_matrix: expected 9 numbers (row-major 3x3)");
  }
  Intrinsics k;
  try {
    k.width = width.as<int>();
    k.height = height.as<int>();
    std::vector<double> m;
    for (const YAML::Node& v : matrix) m.push_back(v.as<double>());
    k.fx = m[0];
    k.cx = m[2];
    k.fy = m[4];
    k.cy = m[5];
  } catch (const std::exception&) {
    return FileDataLoss(path, "image size and camera_matrix must be numbers");
  }
  Status valid = k.Validate();
  if (!valid.ok()) {
    return MakeError(ErrorCode::kInvalidArgument, path + ": " + valid.error().message);
  }
  return k;
}

}  // namespace

Result<Intrinsics> ReadIntrinsicsFile(const std::string& path) {
  std::string lower = path;
  std::transform(lower.begin(), lower.end(), lower.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  auto ends = [&](const std::string& s) {
    return lower.size() >= s.size() && lower.compare(lower.size() - s.size(), s.size(), s) == 0;
  };
  if (ends(".yaml") || ends(".yml")) return ReadCameraInfoYaml(path);
  return ReadIntrinsicsJson(path);
}

}  // namespace hpose
