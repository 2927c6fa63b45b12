#include "tools/template_saved.h"

#include "core/search/estimator.h"
#include "core/templates/template_io.h"
#include "tools/fixed_text.h"

namespace hpose::tools {

std::string SavedTemplateLines(const VoxelTemplate& tpl, const std::string& path) {
  std::string out = "wrote " + path + " and " + TemplateSidecarPath(path) + ": '" + tpl.name +
                    "', " + std::to_string(tpl.voxels.size()) + " voxels of " +
                    Fixed(tpl.resolution_m * 1000.0, 1) + " mm, height " +
                    Fixed(tpl.Height() * 1000.0, 0) + " mm\n";
  const int most = DefaultEstimatorOptions().max_height_voxels;
  const double edge = TallBodySearchEdge(tpl.Height(), tpl.resolution_m, most);
  if (edge > tpl.resolution_m + 1e-9) {
    out += "  note: taller than " + std::to_string(most) + " of its voxels: searched on " +
           Fixed(edge * 1000.0, 1) +
           " mm voxels by default, its own surface still fitted (docs/TEMPLATES.md)\n";
  }
  return out;
}

}  // namespace hpose::tools
