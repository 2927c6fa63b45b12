#ifndef HPOSE_TOOLS_DRAWING_MODULE_H_
#define HPOSE_TOOLS_DRAWING_MODULE_H_

#include <string>
#include <vector>

#include "core/common/status.h"

struct HposeDrawingApi;

namespace hpose::tools {

// Where the drawing module (hpose-drawing.so) is looked for, in order: the file named by the
// environment variable HPOSE_DRAWING_MODULE when it is set (then nowhere else); beside the
// running program (the build tree's tools/ and an installed libexec/hpose/ hold both); the
// build tree's copy, for tests built beside it.
std::vector<std::string> DrawingModuleCandidates();

// The drawing module's functions, loaded on the first call (thread-safe) and kept. Fails with
// kNotFound naming every place looked in, or kInternal with the loader's message when a file
// is there but is not a drawing module of this version.
Result<const HposeDrawingApi*> LoadDrawingModule();

}  // namespace hpose::tools

#endif  // HPOSE_TOOLS_DRAWING_MODULE_H_
