// `hpose template show` and `hpose template info`: look at a template before trusting it.
#include <algorithm>
#include <cstdio>
#include <iostream>
#include <string>

#include <nlohmann/json.hpp>

#include "core/templates/template_io.h"
#include "core/templates/template_shape.h"
#include "core/templates/voxel_template.h"
#include "tools/cmd_template_view_flags.h"
#include "tools/command.h"
#include "tools/exit_codes.h"
#include "tools/fixed_text.h"
#include "tools/flag_parser.h"
#include "tools/template_paths.h"
#include "tools/template_picture.h"

namespace hpose::tools {

int TemplateInfo(int argc, char** argv) {
  TemplateInfoFlags f;
  FlagParser flags = f.Parser();
  if (const int code = flags.ParseOrExitCode(argc, argv, 2); code >= 0) return code;
  if (flags.positional().size() != 1)
    return UsageError("template info", "give exactly one FILE.bt");
  Result<VoxelTemplate> tpl = LoadTemplateEntry(flags.positional().front());
  if (!tpl.ok()) return ReportError("template info", tpl.error());
  const TemplateShape s = DescribeTemplate(*tpl);
  if (f.json) {
    nlohmann::ordered_json j;
    j["file"] = flags.positional().front();
    j["name"] = tpl->name;
    j["variant"] = tpl->variant;
    j["source"] = tpl->source;
    j["resolution_m"] = tpl->resolution_m;
    j["voxels"] = s.voxels;
    j["height_m"] = s.height_m;
    j["width_x_m"] = s.width_x_m;
    j["width_y_m"] = s.width_y_m;
    j["min_m"] = {s.min.x(), s.min.y(), s.min.z()};
    j["max_m"] = {s.max.x(), s.max.y(), s.max.z()};
    j["front_back_difference"] = s.front_back_difference;
    j["left_right_difference"] = s.left_right_difference;
    j["mirror_difference"] = s.mirror_difference;
    j["surface_points"] = tpl->surface.size();
    j["free_limb_points"] = std::count(tpl->free_limb.begin(), tpl->free_limb.end(), 1);
    std::cout << j.dump(2) << "\n";
    return kExitOk;
  }
  auto mm = [](double v) { return Fixed(v * 1000.0, 0); };
  std::cout << "name:        " << tpl->name << "\n"
            << "variant:     " << tpl->variant << "\n"
            << "source:      " << tpl->source << "\n"
            << "resolution:  " << Fixed(tpl->resolution_m * 1000.0, 1) << " mm\n"
            << "voxels:      " << s.voxels << "\n"
            << "height:      " << mm(s.height_m) << " mm\n"
            << "widths:      x (front-back) " << mm(s.width_x_m) << " mm, y (left-right) "
            << mm(s.width_y_m) << " mm\n"
            << "surface:     " << tpl->surface.size() << " points";
  if (const long limbs = std::count(tpl->free_limb.begin(), tpl->free_limb.end(), 1); limbs > 0) {
    std::cout << ", " << limbs << " on free limbs (arms, head: fitted without them where the robot "
              << "holds them otherwise)";
  } else if (tpl->surface.empty()) {
    std::cout << " (voxel centres stand in for them)";
  }
  std::cout << "\n";
  if (s.voxels > 0) {
    std::cout << "bbox (mm):   x " << mm(s.min.x()) << " .. " << mm(s.max.x()) << ", y "
              << mm(s.min.y()) << " .. " << mm(s.max.y()) << ", z " << mm(s.min.z()) << " .. "
              << mm(s.max.z()) << "\n"
              << "asymmetry:   front/back " << Fixed(100 * s.front_back_difference, 1)
              << "%, left/right sides " << Fixed(100 * s.left_right_difference, 1) << "%, mirror "
              << Fixed(100 * s.mirror_difference, 1) << "% of the views' cells differ\n";
  }
  return kExitOk;
}

int TemplateShow(int argc, char** argv) {
  TemplateShowFlags f;
  FlagParser flags = f.Parser();
  if (const int code = flags.ParseOrExitCode(argc, argv, 2); code >= 0) return code;
  if (flags.positional().size() != 1)
    return UsageError("template show", "give exactly one FILE.bt");
  if (f.picture.empty()) return UsageError("template show", "--picture OUT.png is required");
  if (!(f.options.sensor_distance_m >= 0.3 && f.options.sensor_distance_m <= 10.0)) {
    return UsageError("template show", "--distance must be in [0.3, 10] m");
  }
  if (!(f.options.sensor_height_m > 0.0 && f.options.sensor_height_m <= 3.0)) {
    return UsageError("template show", "--sensor-height must be in (0, 3] m");
  }
  Result<VoxelTemplate> tpl = LoadTemplateEntry(flags.positional().front());
  if (!tpl.ok()) return ReportError("template show", tpl.error());
  if (Status s = WriteTemplatePicture(*tpl, f.picture, f.options); !s.ok()) {
    return ReportError("template show", s.error());
  }
  std::cout << "picture " << f.picture << "\n";
  return kExitOk;
}

}  // namespace hpose::tools
