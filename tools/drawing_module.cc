#include "tools/drawing_module.h"

#include <dlfcn.h>

#include <cstdlib>
#include <filesystem>

#include "tools/drawing/drawing_api.h"

namespace hpose::tools {
namespace {

constexpr char kModuleName[] = "hpose-drawing.so";

std::string RunningProgramDir() {
  std::error_code ec;
  const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", ec);
  return ec ? std::string() : self.parent_path().string();
}

Result<const HposeDrawingApi*> Load() {
  const std::vector<std::string> candidates = DrawingModuleCandidates();
  std::string looked;
  for (const std::string& path : candidates) {
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec)) {
      looked += (looked.empty() ? "" : ", ") + path;
      continue;
    }
    void* handle = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (handle == nullptr) {
      const char* why = dlerror();
      return MakeError(ErrorCode::kInternal, "cannot load the drawing module " + path + ": " +
                                                 (why != nullptr ? why : "unknown error"));
    }
    auto entry = reinterpret_cast<HposeDrawingApiFunction>(dlsym(handle, "hpose_drawing_api_v1"));
    const HposeDrawingApi* api = entry != nullptr ? entry() : nullptr;
    if (api == nullptr || api->version != kHposeDrawingApiVersion ||
        api->size != sizeof(HposeDrawingApi)) {
      dlclose(handle);
      return MakeError(ErrorCode::kInternal,
                       path + " is not a drawing module of this hpose (version " +
                           std::to_string(kHposeDrawingApiVersion) + ")");
    }
    return api;  // kept loaded for the rest of the run.
  }
  return MakeError(ErrorCode::kNotFound, std::string("cannot draw pictures: the drawing module ") +
                                             kModuleName + " is missing (looked for " + looked +
                                             ")");
}

}  // namespace

std::vector<std::string> DrawingModuleCandidates() {
  if (const char* set = std::getenv("HPOSE_DRAWING_MODULE"); set != nullptr && *set != '\0') {
    return {set};
  }
  std::vector<std::string> out;
  if (const std::string dir = RunningProgramDir(); !dir.empty()) {
    out.push_back(dir + "/" + kModuleName);
  }
#ifdef HPOSE_BUILD_DRAWING_MODULE
  if (out.empty() || out.front() != HPOSE_BUILD_DRAWING_MODULE) {
    out.push_back(HPOSE_BUILD_DRAWING_MODULE);
  }
#endif
  return out;
}

Result<const HposeDrawingApi*> LoadDrawingModule() {
  static const Result<const HposeDrawingApi*> loaded = Load();
  return loaded;
}

}  // namespace hpose::tools
