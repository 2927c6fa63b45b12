#include "tools/template_saved.h"

#include <cmath>

#include "core/search/estimator.h"
#include "core/templates/template_io.h"
#include "core/templates/template_shape.h"
#include "tools/fixed_text.h"

namespace hpose::tools {
namespace {

// How far a template's lowest voxel may lie from the floor, and its footprint's centre from
// the origin, before the printout asks whether the cloud was in the template frame.
constexpr double kMaxFloorGapM = 0.05;
constexpr double kMaxFootprintOffsetM = 0.25;

}  // namespace

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
  // The search keeps a template standing on the floor with its origin at the pose: a body
  // whose lowest voxel floats or sinks, or whose footprint lies far from the origin, was most
  // likely given in another frame (a sensor's: y down, z forward).
  if (!tpl.voxels.empty()) {
    const TemplateShape shape = DescribeTemplate(tpl);
    const double bottom = shape.min.z();
    if (bottom > kMaxFloorGapM || bottom < -kMaxFloorGapM) {
      out += "  note: its lowest voxel is " + Fixed(std::abs(bottom) * 1000.0, 0) + " mm " +
             (bottom > 0.0 ? "above" : "below") +
             " the floor (z = 0 of the template frame); poses are searched with the template "
             "standing on the floor, so a robot standing there will not match it. Is the "
             "cloud in the template frame (z up, origin on the floor)?\n";
    }
    const double off =
        0.5 * std::hypot(shape.min.x() + shape.max.x(), shape.min.y() + shape.max.y());
    if (off > kMaxFootprintOffsetM) {
      out += "  note: the centre of its footprint is " + Fixed(off * 1000.0, 0) +
             " mm from the origin; poses are of the origin, which should lie below the torso's "
             "centre\n";
    }
  }
  return out;
}

}  // namespace hpose::tools
