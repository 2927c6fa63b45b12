#include "tools/cmd_stereo_flags.h"

namespace hpose::tools {

FlagParser EstimateStereoFlags::Parser() {
  FlagParser flags(
      "hpose estimate-stereo --calibration CAL.yaml (--left L.png --right R.png | --sequence DIR)",
      "Locates the robot (its stereo head projected on the floor, or the point set by the "
      "options' head_to_reference_m) and the ball in the field frame of three same-coloured "
      "landmarks, from one stereo pair or a sequence directory "
      "(layout: DIR/frames.csv or DIR/left/*.png + DIR/right/*.png, optional "
      "DIR/calibration.yaml). Over a sequence it also averages the robot pose over 8 frames, "
      "detects when the ball starts moving and predicts its straight path. The landmarks are "
      "chosen among all blobs of their colour by geometry (epipolar match, size for the "
      "distance, spacing of the known layout), the ball as the most ball-like blob pair; a "
      "partly hidden landmark is down-weighted, and every rejected frame names its reason.");
  flags.AddStrings("calibration", &calibration_paths,
                   "OpenCV stereo calibration (YAML/XML: M1 D1 M2 D2 R T); give two files for "
                   "separate intrinsics and extrinsics",
                   "FILE");
  flags.AddString("calib-unit", &calib_unit, "unit of T in the calibration: m or mm", "UNIT");
  flags.AddString("left", &left, "left image of a single pair", "IMAGE");
  flags.AddString("right", &right, "right image of a single pair", "IMAGE");
  flags.AddString("sequence", &sequence, "directory of frame pairs", "DIR");
  flags.AddDouble("fps", &fps, "frame rate when the sequence has no frames.csv", "HZ");
  flags.AddString("options", &options_path,
                  "estimator options (YAML: colours, landmark positions, thresholds)", "FILE");
  flags.AddString("method", &method,
                  "camera->world fit: svd, closed_form or covariance (default: the options file's)",
                  "NAME");
  flags.AddBool("json", &json, "print one JSON object per frame (SI units) instead of text");
  flags.SetEpilog(
      "exit status: 0 ok; 1 bad input; 2 usage; 3 a single pair gave no robot pose.\n"
      "example:\n  hpose simulate stereo --out /tmp/seq && hpose estimate-stereo --sequence "
      "/tmp/seq --json\n");
  flags.Within("fps", 0.01, 10000.0);  // as hposed's.
  return flags;
}

FlagParser SimulateStereoFlags::Parser() {
  FlagParser flags(
      "hpose simulate-stereo --out DIR [--scenario rolling|walking|grid]",
      "Renders stereo pairs (PNG) of the field seen from the robot's head: floor with a grid "
      "sheet, three blue landmark discs at the paper's positions, an orange ball, optional "
      "distractor colours, with lens distortion, image noise, lighting variation and head sway "
      "while walking. Writes DIR/calibration.yaml (OpenCV), DIR/left/, DIR/right/, "
      "DIR/frames.csv and DIR/ground_truth.csv (SI units). --hard adds what real rigs see: "
      "carpet texture, vignetting, Bayer sensor noise with demosaicing, JPEG, speckles, "
      "distractors of the landmark and ball colours (40 % of placements) and occluders over "
      "part of a landmark (15 %); ground_truth.csv then records the occluded fraction of each "
      "landmark and the number of same-coloured distractors.");
  flags.AddString("out", &out, "output directory (created)", "DIR");
  flags.AddString("rig", &rig,
                  "stereo head: paper (512x240, 70 mm baseline) or vga (640x480, strong "
                  "k1 k2 p1 p2 k3 distortion, 76 mm baseline); camera flags override it",
                  "NAME");
  flags.AddBool("hard", &hard, "realistic sensor and cluttered scenes (see above)");
  flags.AddString("scenario", &scenario,
                  "rolling: ball kicked towards a standing robot; walking: robot walks, ball at "
                  "rest; grid: the paper's grid of robot positions",
                  "NAME");
  flags.AddInt("frames", &spec.frames, "frames (rolling, walking)");
  flags.AddDouble("fps", &spec.fps, "frame rate", "HZ");
  flags.AddInt("width", &spec.camera.width, "image width", "PX");
  flags.AddInt("height", &spec.camera.height, "image height", "PX");
  flags.AddDouble("hfov", &spec.camera.hfov_deg, "horizontal field of view", "DEG");
  flags.AddDouble("baseline", &spec.camera.baseline_m, "stereo baseline", "M");
  flags.AddDouble("head-height", &spec.camera.head_height_m, "head height above the floor", "M");
  flags.AddDouble("tilt", &spec.camera.head_tilt_deg, "head tilt below horizontal", "DEG");
  flags.AddDouble("noise", &noise, "image noise sigma, grey levels", "LEVELS");
  flags.AddDouble("robot-x", &spec.robot_start.x, "robot start x (world)", "M");
  flags.AddDouble("robot-y", &spec.robot_start.y, "robot start y (world)", "M");
  flags.AddDouble("robot-theta", &spec.robot_start.theta, "robot start heading (world)", "RAD");
  flags.AddDouble("kick-time", &spec.kick_time_s, "when the ball is kicked (rolling)", "S");
  flags.AddDouble("ball-vx", &spec.ball_velocity_mps.x(), "ball velocity after the kick, x", "M/S");
  flags.AddDouble("ball-vy", &spec.ball_velocity_mps.y(), "ball velocity after the kick, y", "M/S");
  flags.AddInt("frames-per-position", &spec.frames_per_position, "frames per grid position");
  flags.AddBool("no-distractors", &no_distractors, "no distractor colours on the floor");
  flags.AddBool("no-sway", &no_sway, "no head sway");
  flags.AddInt("seed", &seed, "random seed");
  flags.AddDouble("speed", &spec.robot_speed_mps, "robot walking speed (walking)", "M/S");
  flags.AddString("depth-sensor", &depth_sensor,
                  "also render a depth sensor (Kinect v1 model) watching the robot, its ground "
                  "frame at X,Y (world, metres) facing YAW degrees from world +x: writes "
                  "DIR/stereo/ and DIR/depth/ (see below)",
                  "X,Y,YAW");
  flags.AddDouble("depth-mount-height", &depth.height_m,
                  "depth sensor's optical centre above the floor", "M");
  flags.AddDouble("depth-pitch", &depth_pitch_deg, "depth sensor pitch (+ looks down)", "DEG");
  flags.AddString("depth-size", &depth_size, "depth image size", "WxH");
  flags.AddInt("depth-every", &depth.every, "one depth frame per N stereo frames", "N");
  flags.SetEpilog(
      "With --depth-sensor the output is a recording both estimators see: DIR/stereo/ (the "
      "layout above) and DIR/depth/ (16-bit depth PNGs named by their time in seconds on the "
      "stereo clock, intrinsics.json, truth.csv with the humanoid's ground and world poses). "
      "The humanoid stands where the robot's stereo head is (head_to_reference_m = 0). Use it "
      "with `hpose calibrate world-from-ground --recording DIR`, and as hposed's source.path "
      "(DIR/depth) and stereo.source (DIR/stereo).\n"
      "example:\n  hpose simulate stereo --out rec --scenario walking --frames 90 --fps 10 "
      "--speed 0.08 --robot-y -1.35 --depth-sensor -1.1,-2.1,45\n");
  // Ranges a simulated rig and field can take (the simulator checks the camera's again).
  flags.Within("frames", 1, 100000);
  flags.Within("fps", 0.01, 10000.0);
  flags.Within("width", 16, 4096);
  flags.Within("height", 16, 4096);
  flags.Within("hfov", 10.0, 150.0);
  flags.Within("baseline", 0.005, 2.0);
  flags.Within("head-height", 0.05, 10.0);
  flags.Within("tilt", -89.0, 89.0);
  flags.Within("noise", 0.0, 255.0);
  flags.Within("robot-x", -20.0, 20.0);
  flags.Within("robot-y", -20.0, 20.0);
  flags.Within("robot-theta", -100.0, 100.0);
  flags.Within("kick-time", 0.0, 100000.0);
  flags.Within("ball-vx", -50.0, 50.0);
  flags.Within("ball-vy", -50.0, 50.0);
  flags.Within("frames-per-position", 1, 10000);
  flags.Within("seed", 0, 2147483647.0);
  flags.Within("speed", -2.0, 2.0);
  flags.Within("depth-mount-height", 0.05, 3.0);
  flags.Within("depth-pitch", -85.0, 85.0);
  flags.Within("depth-every", 1, 10000);
  return flags;
}

}  // namespace hpose::tools
