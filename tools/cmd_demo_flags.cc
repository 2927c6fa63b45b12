#include "tools/cmd_demo_flags.h"

namespace hpose::tools {

DemoFlags::DemoFlags() {
  spec.preset = "right_arm_raised";
  spec.humanoid_pose = Pose2D{1.3, 0.15, DegToRad(-120.0)};
  spec.clutter = 4;
  spec.seed = 7;
  theta_deg = RadToDeg(spec.humanoid_pose.theta);
  seed = static_cast<int>(spec.seed);
}

FlagParser DemoFlags::Parser() {
  FlagParser flags(
      "hpose demo [--x M --y M --theta-deg D --pose NAME --clutter N --seed S]",
      "Simulates one 640x480 Kinect v1 frame of a humanoid among clutter (sensor 0.34 m\n"
      "above the floor, level), estimates the humanoid's pose with the shipped\n"
      "templates and prints the estimate beside the truth. No input needed. With --robot,\n"
      "the humanoid is that URDF robot and its template is made on the fly from the URDF.");
  flags.AddDouble("x", &spec.humanoid_pose.x,
                  "humanoid x in the ground frame, metres (within +-20; the Kinect reads 0.8-4 m)",
                  "M");
  flags.AddDouble("y", &spec.humanoid_pose.y,
                  "humanoid y in the ground frame, metres (within +-20)", "M");
  flags.AddDouble("theta-deg", &theta_deg, "humanoid heading, degrees (0 = facing away)", "DEG");
  flags.AddString("pose", &spec.preset,
                  "humanoid joint preset: standing, right_arm_raised or arms_swung", "NAME");
  flags.AddString("body", &spec.body, "humanoid proportions: nao, long_legs or tall", "NAME");
  flags.AddString("robot", &robot_urdf,
                  "simulate and look for this URDF robot (template made from it, 16 mm voxels)",
                  "ROBOT.urdf");
  robot_flags.Register(&flags, /*one_set=*/true);
  flags.AddInt("clutter", &spec.clutter, "random objects on the floor (0-50)");
  flags.AddInt("seed", &seed, "clutter and noise seed (0 or more)");
  flags.AddString("picture", &picture, "where to draw the match", "OUT.png");
  flags.Within("x", -20.0, 20.0);  // as `hpose simulate`'s.
  flags.Within("y", -20.0, 20.0);
  flags.Within("clutter", 0, 50);
  flags.Within("seed", 0, 2147483647.0);
  return flags;
}

}  // namespace hpose::tools
