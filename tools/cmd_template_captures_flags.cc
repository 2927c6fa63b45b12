#include "tools/cmd_template_captures_flags.h"

namespace hpose::tools {

FlagParser TemplateFromCapturesFlags::Parser() {
  FlagParser flags(
      "hpose template from-captures DIR_OR_FILES... --name N --out FILE.bt "
      "(--turntable [--step-deg D | --angles-deg A,B,...] | --headings-deg A,B,...) "
      "[--table-height M] [--origin centroid|axis] [--front-view K] [--report FILE.json]",
      "Makes a 360 degree template from depth captures of the robot standing on a turntable,\n"
      "or turned by hand, all taken by one fixed sensor (the one that will watch it).\n"
      "Captures: 16-bit depth PNGs in mm (with intrinsics.json beside them, or --intrinsics)\n"
      "or .pcd/.ply clouds in the sensor frame; a directory gives its PNGs sorted by name.\n"
      "\n"
      "1. Every capture: the floor is fitted (the captures must agree on it: one fixed sensor),\n"
      "   the objects standing on it are clustered, and the robot is the object at least\n"
      "   15 cm tall nearest the middle of the image (where the others see it); clutter\n"
      "   elsewhere does not matter. Points below --table-height + 25 mm are cut with the table.\n"
      "2. Registration. --turntable: view i is at table angle i * --step-deg (or --angles-deg).\n"
      "   The turntable axis is calibrated from the captures themselves: its direction is the\n"
      "   floor normal and its position on the floor is estimated jointly over all views (grid\n"
      "   search, then point-to-plane least squares). A rotation about a vertical axis cannot\n"
      "   reveal a translation along it (nor the table's zero angle): the report says so; z = 0\n"
      "   is the table top instead. --headings-deg (hand-turned): every view gets its own\n"
      "   x, y, theta on the floor, searched within +-17 deg of its rough heading and refined\n"
      "   jointly with the others.\n"
      "3. Every view's residual against the others (point-to-plane RMS, fraction of its\n"
      "   points with a neighbour within 15 mm) is printed; a view that does not fit (RMS over\n"
      "   --max-rms-mm or fewer than --min-inliers) stops the command, naming it, unless\n"
      "   --drop-bad-views leaves it out.\n"
      "4. Template frame: z = 0 on the table top (floor); origin below the centroid of the\n"
      "   merged body's voxels (--origin centroid, reproducible on any template of the robot)\n"
      "   or on the axis (--origin axis); +x = the direction the robot faced in capture K\n"
      "   (--front-view K, counted from 0 in the order above: it faced the sensor then),\n"
      "   turned by --front-yaw-deg. Voxels with a single merged point are dropped as noise.");
  flags.AllowPositional("DIR_OR_FILES");
  flags.AddString("name", &name, "template name ([A-Za-z0-9_.-])", "N");
  flags.AddString("out", &out, "template file to write (.bt, with its .json sidecar)", "FILE.bt");
  flags.AddString("variant", &variant, "shape label, e.g. standing [default: the name]", "V");
  flags.AddDouble("resolution", &resolution, "voxel edge, metres", "M");
  flags.AddString("intrinsics", &intrinsics,
                  "intrinsics of the depth PNGs [default: intrinsics.json beside each]", "FILE");
  flags.AddBool("turntable", &turntable, "the robot was turned by a turntable");
  flags.AddDouble("step-deg", &step_deg,
                  "turntable: table turn between consecutive captures, degrees (CCW from above)",
                  "D");
  flags.AddString("angles-deg", &angles_text, "turntable: every capture's table angle, degrees",
                  "A,B,...");
  flags.AddString("headings-deg", &headings_text,
                  "hand-turned: every capture's rough robot heading, degrees (CCW from above)",
                  "A,B,...");
  flags.AddDouble("heading-search-deg", &heading_search_deg,
                  "hand-turned: how far each heading may be off, degrees", "D");
  flags.AddDouble("axis-search-m", &axis_search,
                  "turntable: how far the axis may be from the robot's mean position, metres", "M");
  flags.AddDouble("table-height", &table_height,
                  "turntable top above the floor, metres (0: the robot stands on the floor)", "M");
  flags.AddString("origin", &origin_name, "template origin: centroid or axis", "WHERE");
  flags.AddInt("front-view", &front_view, "capture (from 0) in which the robot faced the sensor",
               "K");
  flags.AddDouble("front-yaw-deg", &front_yaw_deg,
                  "turn the template x axis by this from that direction, degrees", "D");
  flags.AddDouble("max-rms-mm", &max_rms_mm, "a view fits when its RMS residual is below", "MM");
  flags.AddDouble("min-inliers", &min_inliers,
                  "... and this fraction of its points meets another view", "F");
  flags.AddBool("drop-bad-views", &drop_bad,
                "leave out captures that do not fit (no floor, no robot, residual too high) "
                "instead of stopping");
  flags.AddString("report", &report_path,
                  "write the calibration, residual table and unobservable directions as JSON",
                  "FILE.json");
  flags.AddString("picture", &picture_path,
                  "draw the registered captures (one colour each) from above and the side, "
                  "with the template origin, +x and the axis",
                  "FILE.png");
  flags.SetEpilog(
      "examples:\n"
      "  hpose simulate turntable --out tt --views 12 --step-deg 30\n"
      "  hpose template from-captures tt --turntable --step-deg 30 --table-height 0.02 \\\n"
      "      --name my_robot --out my_robot.bt --report my_robot_report.json\n"
      "  hpose template from-captures a.png b.png c.png d.png --headings-deg 0,90,180,270 \\\n"
      "      --name my_robot --out my_robot.bt\n"
      "\nexit status: 0 written, 1 bad captures (the message names them) or cannot write,\n"
      "2 bad flags");
  return flags;
}

}  // namespace hpose::tools
