#include "tools/cmd_template_view_flags.h"

namespace hpose::tools {
namespace {

const char kAsymmetryHelp[] =
    "Asymmetry: orthographic depth images of the voxels are compared cell by cell (a cell\n"
    "matches when both images have a surface there within one voxel of depth); the number is\n"
    "the share of occupied cells that do not match. front/back: the robot facing the sensor vs\n"
    "facing away (small: 180-degree flips are likely); left/right sides: its left side vs its\n"
    "right side (small: +-90-degree flips); mirror: the front view vs its mirror image (0 for a\n"
    "left/right symmetric robot, whose left and right arms cannot be told apart).";

}  // namespace

FlagParser TemplateInfoFlags::Parser() {
  FlagParser flags(
      "hpose template info FILE.bt [--json]",
      std::string("Prints a template's name, variant, source, resolution, voxel count,\n"
                  "height, widths, bounding box (template frame) and asymmetry. FILE.bt may be\n"
                  "a shipped template's name (standing, right_arm_raised).\n\n") +
          kAsymmetryHelp);
  flags.AllowPositional("FILE.bt");
  flags.AddBool("json", &json, "print one JSON object (SI units) instead of text");
  return flags;
}

FlagParser TemplateShowFlags::Parser() {
  FlagParser flags(
      "hpose template show FILE.bt --picture OUT.png [--distance M --sensor-height M "
      "--heading-deg D]",
      "Draws a template: its voxels from the front, from the side (its left) and from above,\n"
      "shaded by depth (nearer is brighter), and as a level Kinect v1 sees them; the template\n"
      "frame's origin and axes (x red, y green, z blue) drawn in each view, and the figures of\n"
      "`hpose template info` underneath. FILE.bt may be a shipped template's name (standing,\n"
      "right_arm_raised).");
  flags.AllowPositional("FILE.bt");
  flags.AddString("picture", &picture, "PNG file to write", "OUT.png");
  flags.AddDouble("distance", &options.sensor_distance_m,
                  "Kinect view: horizontal distance to the template origin, metres", "M");
  flags.AddDouble("sensor-height", &options.sensor_height_m,
                  "Kinect view: optical centre above the floor, metres", "M");
  flags.AddDouble("heading-deg", &options.heading_deg,
                  "Kinect view: robot heading, degrees (0 = facing away, 180 = facing the "
                  "sensor)",
                  "D");
  flags.Within("heading-deg", -3600.0, 3600.0);
  return flags;
}

}  // namespace hpose::tools
