#include "core/robot/mesh_file.h"

#include <unistd.h>

#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <assimp/Importer.hpp>
#include <cstdint>
#include <cstring>
#include <functional>
#include <utility>

#include "core/common/self_child.h"

namespace hpose {
namespace {

constexpr char kChildVariable[] = "HPOSE_MESH_FILE_CHILD";
// The files a child reads, one a line in its variable.
constexpr char kPathSeparator = '\n';
// The child's answer for each file, in order: a tag, the payload's length (8 bytes), then the
// payload: the mesh (vertex and triangle counts, then their numbers) or the error's message.
constexpr char kMeshTag = 'M';
constexpr char kErrorTag = 'E';

template <typename T>
void Put(std::string* out, const T& value) {
  out->append(reinterpret_cast<const char*>(&value), sizeof(T));
}

template <typename T>
bool Take(const std::string& in, size_t* at, T* value) {
  if (in.size() - *at < sizeof(T)) return false;
  std::memcpy(value, in.data() + *at, sizeof(T));
  *at += sizeof(T);
  return true;
}

std::string Answer(const Result<TriangleMesh>& mesh) {
  std::string payload;
  if (mesh.ok()) {
    Put(&payload, static_cast<uint64_t>(mesh->vertices.size()));
    Put(&payload, static_cast<uint64_t>(mesh->triangles.size()));
    for (const Eigen::Vector3f& v : mesh->vertices) {
      for (int k = 0; k < 3; ++k) Put(&payload, v[k]);
    }
    for (const Eigen::Vector3i& t : mesh->triangles) {
      for (int k = 0; k < 3; ++k) Put(&payload, static_cast<int32_t>(t[k]));
    }
  } else {
    payload = mesh.error().message;
  }
  std::string answer(1, mesh.ok() ? kMeshTag : kErrorTag);
  Put(&answer, static_cast<uint64_t>(payload.size()));
  return answer + payload;
}

// The child: reads each file, writes its answer as soon as it has it, ends before main.
[[noreturn]] void RunChild(const char* paths) {
  // A damaged count can make assimp allocate without end (a COLLADA offset of "inf" took 15 GB
  // within 20 s): past half the machine's memory its allocations fail in the child instead.
  LimitSelfChildMemory(HalfThePhysicalMemory());
  std::string list = paths;
  for (size_t start = 0; start <= list.size();) {
    size_t end = list.find(kPathSeparator, start);
    if (end == std::string::npos) end = list.size();
    const std::string answer = Answer(ReadMeshFileInProcess(list.substr(start, end - start)));
    if (!WriteSelfChildOutput(answer.data(), answer.size())) _exit(1);
    start = end + 1;
  }
  _exit(0);
}

const bool kRanAsChild = [] {
  if (const char* paths = RunningAsSelfChild(kChildVariable)) RunChild(paths);
  return false;
}();

// A mesh payload as a mesh, or why it is not one.
Result<TriangleMesh> ParseMesh(const std::string& payload) {
  size_t at = 0;
  uint64_t vertices = 0, triangles = 0;
  if (!Take(payload, &at, &vertices) || !Take(payload, &at, &triangles) ||
      vertices > payload.size() / 12 || triangles > payload.size() / 12 ||
      payload.size() - at != 12 * (vertices + triangles)) {
    return MakeError(ErrorCode::kDataLoss, "the mesh reader's answer is malformed");
  }
  TriangleMesh mesh;
  mesh.vertices.resize(vertices);
  mesh.triangles.resize(triangles);
  for (Eigen::Vector3f& v : mesh.vertices) {
    for (int k = 0; k < 3; ++k) Take(payload, &at, &v[k]);
  }
  for (Eigen::Vector3i& t : mesh.triangles) {
    for (int k = 0; k < 3; ++k) {
      int32_t index = 0;
      Take(payload, &at, &index);
      t[k] = index;
    }
  }
  if (!mesh.IsValid()) {
    return MakeError(ErrorCode::kDataLoss, "the mesh reader's answer is malformed");
  }
  return mesh;
}

// The whole answers at the start of `output`, in order.
std::vector<Result<TriangleMesh>> ParseAnswers(const std::string& output) {
  std::vector<Result<TriangleMesh>> results;
  size_t at = 0;
  while (output.size() - at >= 9) {
    const char tag = output[at];
    size_t after_tag = at + 1;
    uint64_t bytes = 0;
    Take(output, &after_tag, &bytes);
    if (output.size() - after_tag < bytes || (tag != kMeshTag && tag != kErrorTag)) break;
    const std::string payload = output.substr(after_tag, bytes);
    results.push_back(tag == kMeshTag
                          ? ParseMesh(payload)
                          : Result<TriangleMesh>(MakeError(ErrorCode::kDataLoss, payload)));
    at = after_tag + bytes;
  }
  return results;
}

}  // namespace

Result<TriangleMesh> ReadMeshFileInProcess(const std::string& path) {
  Assimp::Importer importer;
  // URDF meshes are authored in the link frame: keep COLLADA coordinates as they are.
  importer.SetPropertyBool(AI_CONFIG_IMPORT_COLLADA_IGNORE_UP_DIRECTION, true);
  const aiScene* scene = importer.ReadFile(
      path, aiProcess_Triangulate | aiProcess_JoinIdenticalVertices | aiProcess_SortByPType);
  if (scene == nullptr || scene->mRootNode == nullptr) {
    const std::string why = importer.GetErrorString();
    if (why.find("bad_alloc") != std::string::npos) {
      return MakeError(ErrorCode::kDataLoss,
                       "assimp ran out of memory on it (is a count or index in it damaged?)");
    }
    return MakeError(ErrorCode::kDataLoss, why);
  }
  TriangleMesh mesh;
  std::function<void(const aiNode*, const aiMatrix4x4&)> walk = [&](const aiNode* node,
                                                                    const aiMatrix4x4& parent) {
    const aiMatrix4x4 world = parent * node->mTransformation;
    for (unsigned m = 0; m < node->mNumMeshes; ++m) {
      const aiMesh* am = scene->mMeshes[node->mMeshes[m]];
      const int offset = static_cast<int>(mesh.vertices.size());
      for (unsigned v = 0; v < am->mNumVertices; ++v) {
        const aiVector3D p = world * am->mVertices[v];
        mesh.vertices.emplace_back(p.x, p.y, p.z);
      }
      for (unsigned f = 0; f < am->mNumFaces; ++f) {
        const aiFace& face = am->mFaces[f];
        if (face.mNumIndices != 3) continue;  // points and lines
        mesh.triangles.emplace_back(offset + static_cast<int>(face.mIndices[0]),
                                    offset + static_cast<int>(face.mIndices[1]),
                                    offset + static_cast<int>(face.mIndices[2]));
      }
    }
    for (unsigned c = 0; c < node->mNumChildren; ++c) walk(node->mChildren[c], world);
  };
  walk(scene->mRootNode, aiMatrix4x4());
  if (mesh.empty()) return MakeError(ErrorCode::kDataLoss, "the file holds no triangles");
  if (!mesh.IsValid()) return MakeError(ErrorCode::kDataLoss, "non-finite vertices");
  return mesh;
}

Result<TriangleMesh> ReadMeshFile(const std::string& path, double timeout_s) {
  return std::move(ReadMeshFiles({path}, timeout_s)[0]);
}

std::vector<Result<TriangleMesh>> ReadMeshFiles(const std::vector<std::string>& paths,
                                                double timeout_s) {
  (void)kRanAsChild;
  std::vector<Result<TriangleMesh>> results;
  while (results.size() < paths.size()) {
    // The files still to read, up to one whose name cannot be passed with the others.
    std::string list;
    size_t count = 0;
    for (size_t i = results.size(); i < paths.size(); ++i) {
      if (paths[i].find(kPathSeparator) != std::string::npos) break;
      list += (count++ == 0 ? "" : std::string(1, kPathSeparator)) + paths[i];
    }
    if (count == 0) {  // a name with a line break in it: read here.
      results.push_back(ReadMeshFileInProcess(paths[results.size()]));
      continue;
    }
    const SelfChildRun run = RunSelfAsChild(kChildVariable, list, timeout_s);
    if (!run.started) {
      for (size_t i = 0; i < count; ++i) {
        results.push_back(ReadMeshFileInProcess(paths[results.size()]));
      }
      continue;
    }
    std::vector<Result<TriangleMesh>> answered = ParseAnswers(run.output);
    if (answered.size() > count) {
      answered.erase(answered.begin() + static_cast<long>(count), answered.end());
    }
    for (Result<TriangleMesh>& r : answered) results.push_back(std::move(r));
    if (answered.size() < count) {
      // The file being read when the child ended (or fell silent) is the one to blame.
      const bool ended_badly = run.timed_out || run.signal != 0 || run.exit_status != 0;
      results.push_back(MakeError(ErrorCode::kDataLoss,
                                  ended_badly
                                      ? "assimp " + DescribeSelfChildEnd(run, timeout_s) +
                                            " on it (read in a separate process)"
                                      : std::string("the mesh reader's answer is cut short")));
    }
  }
  return results;
}

}  // namespace hpose
