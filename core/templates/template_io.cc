#include "core/templates/template_io.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <tuple>
#include <vector>

#include <octomap/OcTree.h>
#include <nlohmann/json.hpp>

#include "core/common/file_names.h"
#include "core/io/atomic_file.h"
#include "core/io/input_file.h"

namespace hpose {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

constexpr const char* kFormat = "hpose-template";
// Version 2 adds the surface points, version 3 which of them lie on free limbs ("free_limb");
// files of versions 1 and 2 are still read.
constexpr int kVersion = 3;
constexpr double kSurfaceUnitM = 1e-4;  // surface coordinates are stored in 0.1 mm integers.

// OctoMap's Debian build chatters on std::cout/std::cerr when reading and writing trees
// ("Reading binary octree type OcTree"); templates are loaded at start-up, so the streams are
// muted for the duration of the call. Our own errors are returned, not printed.
class ScopedMuteStreams {
 public:
  ScopedMuteStreams() : out_(std::cout.rdbuf(nullptr)), err_(std::cerr.rdbuf(nullptr)) {}
  ~ScopedMuteStreams() {
    std::cout.rdbuf(out_);
    std::cerr.rdbuf(err_);
  }
  ScopedMuteStreams(const ScopedMuteStreams&) = delete;
  ScopedMuteStreams& operator=(const ScopedMuteStreams&) = delete;

 private:
  std::streambuf* out_;
  std::streambuf* err_;
};

// OcTree::writeBinary's file, written without the progress text ("Writing ... done.") that the
// installed liboctomap prints on stderr: the maximum-likelihood, pruned tree after OctoMap's
// binary header.
bool WriteOctreeBinary(octomap::OcTree* tree, std::ostream& out) {
  tree->toMaxLikelihood();
  tree->prune();
  out << "# Octomap OcTree binary file\n"
      << "# (feel free to add / change comments, but leave the first line as it is!)\n#\n"
      << "id " << tree->getTreeType() << "\nsize " << tree->size() << "\nres "
      << tree->getResolution() << "\ndata\n";
  if (tree->getRoot() != nullptr) tree->writeBinaryNode(out, tree->getRoot());
  return static_cast<bool>(out);
}

// OctoMap's binary reader recurses once per inner node and checks neither the depth nor the end
// of the data: a crafted or damaged file recurses until the stack overflows. This walks the
// same node stream (pre-order, two bytes a node: two bits per child, "11" = a child with
// children of its own) without recursion and refuses data that runs past the end or nests
// deeper than the tree's 16 levels, before OctoMap sees it.
Status CheckOctreeNodes(const std::string& bytes, const std::string& path) {
  const auto corrupt = [&](const std::string& why) {
    return Status(MakeError(ErrorCode::kDataLoss, path + ": corrupt OctoMap tree (" + why + ")"));
  };
  // The header, parsed token by token the way OctoMap's own reader does (a "key value" pair may
  // share a line with "data", a value may sit on the next line), so that the node stream walked
  // below starts exactly where OctoMap will start reading it.
  std::istringstream s(bytes);
  std::string token;
  std::getline(s, token);  // The first line, checked by the caller.
  const auto skip_line = [&s] {
    char c = 0;
    do {
      c = static_cast<char>(s.get());
    } while (s.good() && c != '\n');
  };
  unsigned size = 0;
  bool header_read = false;
  while (s.good() && !header_read) {
    s >> token;
    if (token == "data") {
      header_read = true;
      skip_line();
    } else if (token.compare(0, 1, "#") == 0) {
      skip_line();
    } else if (token == "id") {
      std::string id;
      s >> id;
    } else if (token == "res") {
      double res = 0;
      s >> res;
    } else if (token == "size") {
      s >> size;
    } else {
      skip_line();
    }
  }
  if (!header_read) return corrupt("no data section");
  const std::streampos data_start = s.tellg();
  size_t pos = data_start < 0 ? bytes.size() : static_cast<size_t>(data_start);
  if (size == 0) return Status::Ok();
  constexpr size_t kTreeDepth = 16;
  std::vector<int> todo{1};  // nodes still to read at each depth of the current path.
  while (!todo.empty()) {
    if (todo.back() == 0) {
      todo.pop_back();
      continue;
    }
    --todo.back();
    if (pos + 2 > bytes.size()) return corrupt("the node data ends early");
    int inner = 0;
    for (int b = 0; b < 2; ++b) {
      const unsigned char c = static_cast<unsigned char>(bytes[pos + b]);
      for (int i = 0; i < 4; ++i) inner += ((c >> (2 * i)) & 3) == 3 ? 1 : 0;
    }
    pos += 2;
    if (inner == 0) continue;
    if (todo.size() >= kTreeDepth) return corrupt("nodes nested deeper than 16 levels");
    todo.push_back(inner);
  }
  return Status::Ok();
}

// Templates are a few thousand voxels (a 58 cm humanoid at 16 mm: ~3000); the limits leave
// room for a large robot at fine resolution: a million surface voxels of 4 mm cover 16 m^2, a
// 2 m robot's surface several times over. (The former four million took a minute to load
// under the sanitizers, and no estimator can search such a template in real time.)
constexpr std::uint64_t kMaxTemplateFileBytes = std::uint64_t{256} << 20;
constexpr std::uint64_t kMaxTemplateVoxels = 1'000'000;

// Occupied voxels at full depth once the tree is expanded: a pruned occupied leaf at depth d
// stands for 8^(max_depth - d) of them. Saturates instead of overflowing.
std::uint64_t ExpandedOccupiedVoxels(const octomap::OcTree& tree) {
  const unsigned max_depth = tree.getTreeDepth();
  std::uint64_t total = 0;
  for (auto it = tree.begin_leafs(), end = tree.end_leafs(); it != end; ++it) {
    if (!tree.isNodeOccupied(*it)) continue;
    const unsigned levels = max_depth - it.getDepth();
    if (levels >= 21) return ~std::uint64_t{0};
    total += std::uint64_t{1} << (3 * levels);
    if (total > kMaxTemplateVoxels) return total;
  }
  return total;
}

std::string SidecarText(const VoxelTemplate& tpl) {
  json j;
  j["format"] = kFormat;
  j["version"] = kVersion;
  j["name"] = tpl.name;
  j["variant"] = tpl.variant;
  j["resolution_m"] = tpl.resolution_m;
  j["source"] = tpl.source;
  j["voxels"] = tpl.voxels.size();
  j["height_m"] = tpl.Height();
  j["surface_points"] = tpl.surface.size();
  // One character a surface point, '1' on a free limb (only when some point is).
  if (tpl.free_limb.size() == tpl.surface.size() &&
      std::find(tpl.free_limb.begin(), tpl.free_limb.end(), 1) != tpl.free_limb.end()) {
    std::string marks(tpl.free_limb.size(), '0');
    for (size_t i = 0; i < marks.size(); ++i) marks[i] = tpl.free_limb[i] ? '1' : '0';
    j["free_limb"] = marks;
  }
  // The surface as one flat line [x0, y0, z0, x1, ...] of 0.1 mm integers (compact, and exact
  // far below the sensor's noise) after the readable keys.
  std::string text = j.dump(2);
  text.resize(text.size() - 2);  // the closing "\n}".
  text += ",\n  \"surface_0.1mm\": [";
  for (size_t i = 0; i < tpl.surface.size(); ++i) {
    for (int k = 0; k < 3; ++k) {
      if (i + k > 0) text += ',';
      text += std::to_string(std::lround(tpl.surface[i][k] / kSurfaceUnitM));
    }
  }
  text += "]\n}\n";
  return text;
}

// Parsed sidecar contents; fields absent in the file keep their defaults.
struct Sidecar {
  std::string name;
  std::string variant;
  std::string source;
  double resolution_m = 0.0;
  long long voxels = -1;
  std::vector<Eigen::Vector3f> surface;
  std::vector<std::uint8_t> free_limb;
};

// Reads a sidecar's text as events: its keys' values into a JSON object, except the surface
// array (tens of thousands of integers), whose entries go straight into a vector; a document
// value per entry would cost several times the parse. A nested array or object under another
// key is kept as an empty one of its kind (only its kind is checked).
class SidecarReader : public json::json_sax_t {
 public:
  static constexpr const char* kSurfaceKey = "surface_0.1mm";

  json top;                        // the object's keys; the surface's is an empty array.
  bool object = false;             // the document is an object.
  bool surface_array = false;      // the surface key holds an array.
  std::vector<long long> surface;  // its integer entries within the range, in order.
  long long surface_entries = 0;   // its entries of any kind.
  long long first_bad_entry = -1;  // the first entry that is not such an integer.

  bool null() override { return Scalar(json(nullptr)); }
  bool boolean(bool v) override { return Scalar(json(v)); }
  bool number_integer(number_integer_t v) override {
    if (InSurface()) return Entry(v >= -kMaxEntry && v <= kMaxEntry, v);
    return Scalar(json(v));
  }
  bool number_unsigned(number_unsigned_t v) override {
    if (InSurface()) {
      const bool ok = v <= static_cast<number_unsigned_t>(kMaxEntry);
      return Entry(ok, ok ? static_cast<long long>(v) : 0);
    }
    return Scalar(json(v));
  }
  bool number_float(number_float_t v, const string_t&) override {
    if (InSurface()) return Entry(false, 0);
    return Scalar(json(v));
  }
  bool string(string_t& v) override { return Scalar(json(v)); }
  bool binary(binary_t&) override { return Scalar(json::binary({})); }
  bool start_object(std::size_t) override { return Open(false); }
  bool end_object() override { return Close(); }
  bool start_array(std::size_t) override { return Open(true); }
  bool end_array() override { return Close(); }
  bool key(string_t& k) override {
    if (depth_ == 1) key_ = k;
    return true;
  }
  bool parse_error(std::size_t, const std::string&, const nlohmann::detail::exception&) override {
    return false;
  }

 private:
  static constexpr long long kMaxEntry = 100000000LL;  // 10 km in 0.1 mm.

  bool InSurface() const { return depth_ == 2 && in_surface_; }
  bool Entry(bool ok, long long v) {
    if (ok) {
      surface.push_back(v);
    } else if (first_bad_entry < 0) {
      first_bad_entry = surface_entries;
    }
    ++surface_entries;
    return true;
  }
  // A value that is no container: the document itself (not an object), a key's, or nested.
  bool Scalar(json v) {
    if (InSurface()) return Entry(false, 0);
    if (depth_ == 1) {
      if (key_ == kSurfaceKey) Restart(false);
      top[key_] = std::move(v);
    }
    return true;
  }
  // The surface key's value begins (again: as in a document, the last one counts).
  void Restart(bool array) {
    surface_array = array;
    surface.clear();
    surface_entries = 0;
    first_bad_entry = -1;
  }
  bool Open(bool array) {
    if (depth_ == 0) {
      object = !array;
    } else if (depth_ == 1) {
      in_surface_ = array && key_ == kSurfaceKey;
      if (key_ == kSurfaceKey) Restart(array);
      top[key_] = array ? json::array() : json::object();
    } else if (InSurface()) {
      Entry(false, 0);
    }
    ++depth_;
    return true;
  }
  bool Close() {
    --depth_;
    if (depth_ == 1) in_surface_ = false;
    return true;
  }

  int depth_ = 0;
  bool in_surface_ = false;
  std::string key_;
};

Result<Sidecar> ParseSidecar(const std::string& text, const std::string& path) {
  SidecarReader reader;
  if (!json::sax_parse(text, &reader) || !reader.object) {
    return MakeError(ErrorCode::kDataLoss, path + ": not a JSON object");
  }
  const json& j = reader.top;
  static const char* const kKnown[] = {"format",         "version",       "name",     "variant",
                                       "resolution_m",   "source",        "voxels",   "height_m",
                                       "surface_points", "surface_0.1mm", "free_limb"};
  for (auto it = j.begin(); it != j.end(); ++it) {
    bool known = false;
    for (const char* k : kKnown) known = known || it.key() == k;
    if (!known) {
      return MakeError(ErrorCode::kDataLoss, path + ": unknown key '" + it.key() + "'");
    }
  }
  if (!j.contains("format") || j["format"] != kFormat) {
    return MakeError(ErrorCode::kDataLoss,
                     path + ": 'format' must be \"" + std::string(kFormat) + "\"");
  }
  if (!j.contains("version") || !j["version"].is_number_integer() || j["version"] < 1 ||
      j["version"] > kVersion) {
    return MakeError(ErrorCode::kDataLoss,
                     path + ": unsupported 'version' (this hpose reads versions 1 to " +
                         std::to_string(kVersion) + ")");
  }
  Sidecar s;
  auto get_string = [&](const char* key, std::string* out) -> Status {
    if (!j.contains(key)) return Status::Ok();
    if (!j[key].is_string()) {
      return MakeError(ErrorCode::kDataLoss, path + ": '" + key + "' must be a string");
    }
    *out = j[key].get<std::string>();
    return Status::Ok();
  };
  for (auto [key, out] : {std::pair<const char*, std::string*>{"name", &s.name},
                          {"variant", &s.variant},
                          {"source", &s.source}}) {
    Status st = get_string(key, out);
    if (!st.ok()) return st.error();
  }
  if (!j.contains("resolution_m") || !j["resolution_m"].is_number()) {
    return MakeError(ErrorCode::kDataLoss, path + ": 'resolution_m' (a number) is missing");
  }
  s.resolution_m = j["resolution_m"].get<double>();
  if (j.contains("voxels")) {
    if (!j["voxels"].is_number_integer()) {
      return MakeError(ErrorCode::kDataLoss, path + ": 'voxels' must be an integer");
    }
    s.voxels = j["voxels"].get<long long>();
  }
  if (j.contains(SidecarReader::kSurfaceKey)) {
    if (!reader.surface_array || reader.surface_entries % 3 != 0) {
      return MakeError(ErrorCode::kDataLoss,
                       path + ": 'surface_0.1mm' must be an array of x, y, z integer triples");
    }
    if (reader.first_bad_entry >= 0) {
      return MakeError(ErrorCode::kDataLoss, path + ": 'surface_0.1mm' entry " +
                                                 std::to_string(reader.first_bad_entry) +
                                                 " is not an integer within 10 km");
    }
    const std::vector<long long>& a = reader.surface;
    s.surface.reserve(a.size() / 3);
    for (size_t i = 0; i < a.size(); i += 3) {
      s.surface.emplace_back(static_cast<float>(a[i] * kSurfaceUnitM),
                             static_cast<float>(a[i + 1] * kSurfaceUnitM),
                             static_cast<float>(a[i + 2] * kSurfaceUnitM));
    }
    if (j.contains("surface_points") &&
        (!j["surface_points"].is_number_integer() ||
         j["surface_points"].get<long long>() != static_cast<long long>(s.surface.size()))) {
      return MakeError(ErrorCode::kDataLoss,
                       path + ": 'surface_points' disagrees with the length of 'surface_0.1mm'");
    }
  }
  if (j.contains("free_limb")) {
    const json& marks = j["free_limb"];
    if (!marks.is_string() || marks.get_ref<const std::string&>().size() != s.surface.size() ||
        marks.get_ref<const std::string&>().find_first_not_of("01") != std::string::npos) {
      return MakeError(ErrorCode::kDataLoss,
                       path +
                           ": 'free_limb' must be a string of one '0' or '1' per surface point (" +
                           std::to_string(s.surface.size()) + ")");
    }
    for (char m : marks.get_ref<const std::string&>()) s.free_limb.push_back(m == '1');
  }
  return s;
}

}  // namespace

std::string TemplateSidecarPath(const std::string& bt_path) {
  fs::path p(bt_path);
  p.replace_extension(".json");
  return p.string();
}

Status SaveTemplate(const VoxelTemplate& tpl, const std::string& bt_path) {
  if (!EndsWith(bt_path, ".bt")) {
    return MakeError(ErrorCode::kInvalidArgument,
                     bt_path + ": template files must end in .bt (OctoMap binary tree)");
  }
  if (tpl.voxels.empty()) {
    return MakeError(ErrorCode::kInvalidArgument, "template '" + tpl.name + "' has no voxels");
  }
  octomap::OcTree tree(tpl.resolution_m);
  for (const Eigen::Vector3f& v : tpl.voxels) {
    octomap::OcTreeKey key;
    if (!tree.coordToKeyChecked(v.x(), v.y(), v.z(), key)) {
      return MakeError(ErrorCode::kInvalidArgument,
                       "template '" + tpl.name + "' has a voxel outside OctoMap's range");
    }
    tree.updateNode(key, true);
  }
  // The tree first, then the sidecar: each is renamed into place only when complete.
  Status st = WriteAtomically(bt_path, [&tree](const std::string& temp) -> Status {
    std::ofstream out(temp, std::ios::binary);
    if (!out || !WriteOctreeBinary(&tree, out) || !out.flush()) {
      return MakeError(ErrorCode::kInternal, temp + ": cannot write the OctoMap tree");
    }
    return Status::Ok();
  });
  if (!st.ok()) return st;
  return WriteFileAtomically(TemplateSidecarPath(bt_path), SidecarText(tpl));
}

Result<VoxelTemplate> LoadTemplate(const std::string& bt_path) {
  std::error_code ec;
  if (!fs::exists(bt_path, ec)) {
    return MakeError(ErrorCode::kNotFound, bt_path + ": no such template file");
  }
  Result<std::uint64_t> size = CheckInputFile(bt_path, kMaxTemplateFileBytes);
  if (!size.ok()) return size.error();
  std::ifstream in(bt_path, std::ios::binary);
  if (!in) return MakeError(ErrorCode::kNotFound, bt_path + ": cannot open");
  // OctoMap's reader wants a tree of the right resolution first; readBinary(istream) replaces
  // it with the file's.
  octomap::OcTree tree(0.1);
  std::string header;
  std::getline(in, header);
  if (header.rfind("# Octomap OcTree binary file", 0) != 0) {
    return MakeError(ErrorCode::kDataLoss,
                     bt_path + ": not an OctoMap binary tree (.bt) file (bad header)");
  }
  {
    std::ostringstream all;
    in.seekg(0);
    all << in.rdbuf();
    const Status nodes = CheckOctreeNodes(all.str(), bt_path);
    if (!nodes.ok()) return nodes.error();
  }
  in.clear();
  in.seekg(0);
  bool read_ok = false;
  {
    ScopedMuteStreams mute;
    read_ok = tree.readBinary(in);
  }
  if (!read_ok) {
    return MakeError(ErrorCode::kDataLoss, bt_path + ": corrupt or truncated OctoMap tree");
  }
  // A pruned leaf high in the tree stands for up to 8^15 voxels: count before expanding.
  const std::uint64_t voxels = ExpandedOccupiedVoxels(tree);
  if (voxels > kMaxTemplateVoxels) {
    return MakeError(ErrorCode::kOutOfRange,
                     bt_path + ": the tree expands to " + std::to_string(voxels) +
                         " occupied voxels, more than the " + std::to_string(kMaxTemplateVoxels) +
                         " a template may hold");
  }
  if (!(tree.getResolution() >= 1e-4 && tree.getResolution() <= 10.0)) {
    return MakeError(ErrorCode::kDataLoss, bt_path + ": resolution " +
                                               std::to_string(tree.getResolution()) +
                                               " m is outside [0.0001, 10]");
  }
  // The occupied voxels at full depth. Not tree.expand(): that also expands pruned *free*
  // leaves, up to 8^15 nodes for one leaf near the root (a fuzzed file ran out of memory there);
  // the occupied ones were counted above.
  // Listed by key, sorted as integers (the order of x, then y, then z: a key's coordinate grows
  // with it), then placed: sorting the coordinates themselves took a minute for four million
  // voxels under the sanitizers (a fuzzed file).
  std::vector<std::uint64_t> keys;
  keys.reserve(static_cast<std::size_t>(voxels));
  const unsigned max_depth = tree.getTreeDepth();
  for (auto it = tree.begin_leafs(), end = tree.end_leafs(); it != end; ++it) {
    if (!tree.isNodeOccupied(*it)) continue;
    const unsigned n = 1u << (max_depth - it.getDepth());
    const octomap::OcTreeKey corner = it.getIndexKey();
    for (unsigned i = 0; i < n; ++i) {
      for (unsigned j = 0; j < n; ++j) {
        for (unsigned l = 0; l < n; ++l) {
          keys.push_back(std::uint64_t{static_cast<octomap::key_type>(corner[0] + i)} << 32 |
                         std::uint64_t{static_cast<octomap::key_type>(corner[1] + j)} << 16 |
                         std::uint64_t{static_cast<octomap::key_type>(corner[2] + l)});
        }
      }
    }
  }
  if (keys.empty()) {
    return MakeError(ErrorCode::kInvalidArgument, bt_path + ": the tree has no occupied voxels");
  }
  std::sort(keys.begin(), keys.end());
  VoxelTemplate tpl;
  tpl.resolution_m = tree.getResolution();
  tpl.voxels.reserve(keys.size());
  for (const std::uint64_t k : keys) {
    const octomap::OcTreeKey key(static_cast<octomap::key_type>(k >> 32),
                                 static_cast<octomap::key_type>(k >> 16),
                                 static_cast<octomap::key_type>(k));
    const octomap::point3d c = tree.keyToCoord(key);
    tpl.voxels.emplace_back(c.x(), c.y(), c.z());
  }

  const std::string sidecar_path = TemplateSidecarPath(bt_path);
  tpl.name = fs::path(bt_path).stem().string();
  tpl.variant = tpl.name;
  if (fs::exists(sidecar_path, ec)) {
    Result<std::string> text = ReadFile(sidecar_path);
    if (!text.ok()) return text.error();
    Result<Sidecar> side = ParseSidecar(*text, sidecar_path);
    if (!side.ok()) return side.error();
    if (std::abs(side->resolution_m - tpl.resolution_m) > 1e-9) {
      return MakeError(ErrorCode::kInvalidArgument,
                       sidecar_path + ": resolution_m " + std::to_string(side->resolution_m) +
                           " disagrees with the tree's " + std::to_string(tpl.resolution_m));
    }
    if (side->voxels >= 0 && side->voxels != static_cast<long long>(tpl.voxels.size())) {
      return MakeError(ErrorCode::kDataLoss,
                       sidecar_path + ": says " + std::to_string(side->voxels) +
                           " voxels but the tree holds " + std::to_string(tpl.voxels.size()));
    }
    if (!side->name.empty()) tpl.name = side->name;
    tpl.variant = side->variant.empty() ? tpl.name : side->variant;
    tpl.source = side->source;
    tpl.surface = std::move(side->surface);
    tpl.free_limb = std::move(side->free_limb);
  }
  return tpl;
}

}  // namespace hpose
