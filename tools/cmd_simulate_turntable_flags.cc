#include "tools/cmd_simulate_turntable_flags.h"

namespace hpose::tools {

FlagParser TurntableFlags::Parser() {
  FlagParser flags(
      "hpose simulate turntable --out DIR [--views N --step-deg D] [--axis-x M --axis-y M] "
      "[--robot-offset X,Y --robot-yaw-deg D] [--table-radius M --table-height M] "
      "[--hand-error-deg D] [--clutter N --seed S --no-noise]",
      "Renders captures of the parametric humanoid standing on a turntable in front of a fixed\n"
      "Kinect v1 (same renderer and noise model as `hpose simulate`): the table turns by\n"
      "--step-deg between views (counter-clockwise seen from above). The robot stands off the\n"
      "axis by --robot-offset (table frame: origin on the axis at the table top, x = the ground\n"
      "x axis in view 0). By default it faces the sensor in view 0 (its x axis points from its\n"
      "origin to the sensor). --hand-error-deg adds a random error of up to +-D to every angle\n"
      "but the first: a robot turned by hand to roughly known headings.\n"
      "Writes DIR/depth_000.png ... (16-bit, mm), DIR/intrinsics.json and DIR/truth.json (axis\n"
      "position in the ground and sensor frames, the robot on the table, every view's true\n"
      "angle and robot pose; metres, radians).");
  flags.AddString("out", &out_dir, "output directory (created if missing)", "DIR");
  flags.AddInt("views", &spec.views, "number of captures", "N");
  flags.AddDouble("step-deg", &step_deg, "table turn between captures, degrees", "D");
  flags.AddDouble("start-deg", &start_deg, "table angle of the first capture, degrees", "D");
  flags.AddDouble("axis-x", &axis_x, "axis position on the floor, ground x (ahead), metres", "M");
  flags.AddDouble("axis-y", &axis_y, "axis position on the floor, ground y (left), metres", "M");
  flags.AddString("robot-offset", &offset, "robot origin on the table, table frame, metres", "X,Y");
  flags.AddDouble("robot-yaw-deg", &yaw_deg,
                  "robot heading in view 0 relative to facing the sensor, degrees", "D");
  flags.AddDouble("table-radius", &spec.table_radius_m, "turntable disc radius, metres", "M");
  flags.AddDouble("table-height", &spec.table_height_m,
                  "turntable top above the floor, metres (0: no disc)", "M");
  flags.AddDouble("hand-error-deg", &error_deg,
                  "random error of every angle but the first, up to +-D degrees", "D");
  flags.AddString("pose", &pose_name, "joint preset: standing, right_arm_raised or arms_swung",
                  "NAME");
  flags.AddDouble("sensor-height", &spec.sensor_height_m, "optical centre above the floor, m", "M");
  flags.AddDouble("pitch-deg", &pitch_deg, "sensor pitch, degrees (+ looks down)", "D");
  flags.AddDouble("roll-deg", &roll_deg, "sensor roll, degrees", "D");
  flags.AddInt("clutter", &spec.clutter, "random still objects on the floor, off the table", "N");
  flags.AddInt("seed", &seed, "seed of the noise, clutter and hand errors", "S");
  flags.AddInt("width", &width, "image width, pixels", "PX");
  flags.AddInt("height", &height, "image height, pixels", "PX");
  flags.AddBool("no-noise", &no_noise, "exact depth: no noise or quantisation");
  flags.SetEpilog(
      "examples:\n"
      "  hpose simulate turntable --out tt --views 12 --step-deg 30 --axis-x 1.3 --axis-y -0.05\n"
      "  hpose simulate turntable --out hand --views 8 --step-deg 45 --table-height 0 "
      "--hand-error-deg 10\n"
      "\nexit status: 0 ok, 1 error writing the files, 2 bad flags or values");
  // As `hpose simulate`'s.
  flags.Within("sensor-height", 0.05, 3.0);
  flags.Within("pitch-deg", -85.0, 85.0);
  flags.Within("roll-deg", -45.0, 45.0);
  flags.Within("start-deg", -3600.0, 3600.0);
  flags.Within("robot-yaw-deg", -3600.0, 3600.0);
  return flags;
}

}  // namespace hpose::tools
