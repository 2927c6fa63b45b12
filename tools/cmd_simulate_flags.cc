#include "tools/cmd_simulate_flags.h"

#include <string>

namespace hpose::tools {

FlagParser SimulateFlags::Parser() {
  FlagParser flags(
      "hpose simulate --out DIR [--x M --y M --theta-deg D] [--pose NAME --body NAME | --robot "
      "ROBOT.urdf [--joints FILE.yaml --joint-set NAME | --joint N=RAD]] [--sensor-height M "
      "--pitch-deg D --roll-deg D] [--clutter N --seed S] [--frames N --turn-deg D --step-m M]",
      "Renders simulated Kinect v1 depth frames of the parametric humanoid (or, with --robot, a\n"
      "robot described by a URDF and its meshes) standing on a floor,\n"
      "optionally among clutter (a ball, boxes, cylinders) and a second humanoid, with\n"
      "a Kinect v1 sensor model: axial noise 1.425e-3 z^2 m, 0.8 px lateral jitter, 11-bit\n"
      "disparity quantisation, no reading outside 0.8-4.0 m or beyond 80 degrees incidence.\n"
      "Writes DIR/depth.png (16-bit, mm), DIR/intrinsics.json, DIR/cloud.pcd (sensor frame, m)\n"
      "and DIR/truth.json (poses in the ground frame, metres and radians); with --frames N > 1\n"
      "the frames are depth_000.png, cloud_000.pcd, ... Poses: ground frame origin on the floor\n"
      "below the sensor, x along the optical axis projected on the floor, y left; theta = 0\n"
      "means the humanoid faces away from the sensor.");
  flags.AddString("out", &out_dir, "output directory (created if missing)", "DIR");
  flags.AddDouble("x", &x, "humanoid x in the ground frame, metres (distance ahead)", "M");
  flags.AddDouble("y", &y, "humanoid y in the ground frame, metres (left)", "M");
  flags.AddDouble("theta-deg", &theta_deg, "humanoid heading, degrees (0 = facing away)", "D");
  flags.AddString("pose", &pose_name, "joint preset: standing, right_arm_raised or arms_swung",
                  "NAME");
  flags.AddString("body", &body, "humanoid proportions: nao, long_legs or tall", "NAME");
  flags.AddString("robot", &robot_urdf,
                  "render this URDF robot instead of the parametric humanoid (see the joint "
                  "and package flags below)",
                  "ROBOT.urdf");
  robot_flags.Register(&flags, /*one_set=*/true);
  flags.AddDouble("sensor-height", &sensor_height, "optical centre above the floor, metres", "M");
  flags.AddDouble("pitch-deg", &pitch_deg,
                  "sensor pitch, degrees (+ looks down; within +-85: a floor tilted more than 70 "
                  "from the image's up direction needs `hpose estimate --floor-max-tilt-deg`)",
                  "D");
  flags.AddDouble("roll-deg", &roll_deg, "sensor roll, degrees (+ image right side down)", "D");
  flags.AddInt("clutter", &clutter,
               "random clutter objects: the first a ball, then boxes and cylinders", "N");
  flags.AddInt("seed", &seed, "seed of the clutter layout and the sensor noise", "S");
  flags.AddInt("width", &width, "image width, pixels (Kinect v1 intrinsics scaled)", "PX");
  flags.AddInt("height", &height, "image height, pixels", "PX");
  flags.AddBool("no-noise", &no_noise,
                "exact depth: no random noise or quantisation (range and incidence limits "
                "still apply)");
  flags.AddDouble("noise-correlation", &noise_correlation,
                  "share (0-1) of the depth noise (axial error and ray jitter) that neighbouring "
                  "pixels share, as a real Kinect's window-matched disparities do (0.9 resembles "
                  "one; 0: every pixel independent)",
                  "SHARE");
  flags.AddInt("noise-correlation-px", &noise_correlation_px,
               "with --noise-correlation: the shared part is the mean over the pixels within "
               "this many of each pixel (a square), so errors stay alike over about twice that",
               "R");
  flags.AddInt("frames", &frames, "number of frames; the humanoid moves between them", "N");
  flags.AddDouble("turn-deg", &turn_deg, "humanoid turn per frame, degrees (counter-clockwise)",
                  "D");
  flags.AddDouble("step-m", &step_m, "humanoid walk per frame along its heading, metres", "M");
  flags.AddString("second-at", &second_at,
                  "add a second (still) humanoid at X,Y,THETA_DEG (metres, degrees)", "X,Y,DEG");
  flags.AddString("second-pose", &second_pose, "joint preset of the second humanoid", "NAME");
  flags.AddBool("no-cloud", &no_cloud, "do not write the point clouds");
  flags.SetEpilog(
      "examples:\n"
      "  hpose simulate --out sim1                      # the paper's setup: 1 m ahead, theta 0\n"
      "  hpose simulate --out sim2 --x 2 --theta-deg 90 --pose right_arm_raised --clutter 6\n"
      "  hpose simulate --out turn --frames 12 --turn-deg 30   # a full turn in 30 deg steps\n"
      "  hpose simulate --out darwin --robot ../shared/data/darwin_op/robots/robotis_op.urdf \\\n"
      "      --allow-missing --theta-deg 60 --clutter 4\n"
      "  hpose simulate turntable --help   # captures on a turntable for template from-captures\n"
      "\nexit status: 0 ok, 1 error writing the files, 2 bad flags or values");
  return flags;
}

int RunSimulateSubcommand(const SimulateSubcommands& subs, int argc, char** argv) {
  // `hpose simulate stereo ...` renders stereo pairs: the same as `hpose simulate-stereo ...`.
  if (argc >= 2 && std::string(argv[1]) == "stereo") {
    std::string prog = "hpose simulate stereo";
    argv[1] = prog.data();
    return subs.stereo(argc - 1, argv + 1);
  }
  if (argc >= 2 && std::string(argv[1]) == "turntable") {
    std::string prog = "hpose simulate turntable";
    argv[1] = prog.data();
    return subs.turntable(argc - 1, argv + 1);
  }
  return subs.scene(argc, argv);
}

}  // namespace hpose::tools
