#ifndef HPOSE_CORE_IO_INTRINSICS_JSON_H_
#define HPOSE_CORE_IO_INTRINSICS_JSON_H_

#include <string>

#include "core/common/status.h"
#include "core/depth/intrinsics.h"

namespace hpose {

// Parses {"width","height","fx","fy","cx","cy"} (unknown keys are errors) and validates it.
Result<Intrinsics> ParseIntrinsicsJson(const std::string& text, const std::string& origin);
Result<Intrinsics> ReadIntrinsicsJson(const std::string& path);
std::string IntrinsicsToJson(const Intrinsics& intrinsics);
Status WriteIntrinsicsJson(const Intrinsics& intrinsics, const std::string& path);

// The intrinsics.json in the directory of `frame_path` ("." for a bare file name), where hpose
// simulate and record write them and where frames are read with them. Not checked to exist.
std::string IntrinsicsJsonBeside(const std::string& frame_path);

}  // namespace hpose

#endif  // HPOSE_CORE_IO_INTRINSICS_JSON_H_
