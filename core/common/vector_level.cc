#include "core/common/vector_level.h"

#include <cstdlib>
#include <string>

namespace hpose {
namespace {

const char* VariableValue() {
  const char* value = std::getenv(kVectorLevelVariable);
  return value != nullptr ? value : "";
}

}  // namespace

Result<VectorLevel> ParseVectorLevel(std::string_view text) {
  for (VectorLevel level : {VectorLevel::kScalar, VectorLevel::kAvx2, VectorLevel::kAvx512}) {
    if (text == VectorLevelName(level)) return level;
  }
  return MakeError(ErrorCode::kInvalidArgument, "unknown vector level \"" + std::string(text) +
                                                    "\" (expected scalar, avx2 or avx512)");
}

const char* VectorLevelName(VectorLevel level) {
  switch (level) {
    case VectorLevel::kScalar:
      return "scalar";
    case VectorLevel::kAvx2:
      return "avx2";
    case VectorLevel::kAvx512:
      return "avx512";
  }
  return "avx512";
}

VectorLevel VectorLevelCap() {
  static const VectorLevel cap = [] {
    const std::string_view value = VariableValue();
    if (value.empty()) return VectorLevel::kAvx512;
    const Result<VectorLevel> level = ParseVectorLevel(value);
    return level.ok() ? *level : VectorLevel::kAvx512;
  }();
  return cap;
}

Status CheckVectorLevelVariable() {
  const std::string_view value = VariableValue();
  if (value.empty()) return Status::Ok();
  const Result<VectorLevel> level = ParseVectorLevel(value);
  if (level.ok()) return Status::Ok();
  return MakeError(ErrorCode::kInvalidArgument,
                   std::string(kVectorLevelVariable) + ": " + level.error().message);
}

}  // namespace hpose
