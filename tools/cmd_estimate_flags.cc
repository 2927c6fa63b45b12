#include "tools/cmd_estimate_flags.h"

namespace hpose::tools {

EstimateFlags::EstimateFlags() {
  options.threads = 0;  // every usable core: one frame, as soon as possible.
}

FlagParser EstimateFlags::Parser() {
  FlagParser flags(
      "hpose estimate (FRAME | --depth FRAME [--intrinsics CAM.json] | --cloud FRAME.pcd) "
      "[--template FILE.bt ...] [--json]",
      "Finds the humanoid in one depth frame: builds the point cloud, fits the floor, clusters\n"
      "what stands on it and matches every template against every cluster by a search over\n"
      "(x, y, theta). Poses are in the ground frame: origin on the floor below the sensor, x the\n"
      "optical axis projected on the floor, y left, theta counter-clockwise (0 = facing away).\n"
      "FRAME alone is read by its extension: .png, .tif, .tiff or .pclzf as --depth, .pcd or\n"
      ".ply as --cloud.");
  flags.AllowPositional("FRAME");
  flags.AddString("depth", &depth_path,
                  "depth frame in millimetres (0 = no reading): 16-bit PNG or TIFF, or PCL's "
                  ".pclzf (with its .xml camera parameters beside it)",
                  "FRAME");
  flags.AddString("intrinsics", &intrinsics_path,
                  "the depth camera's intrinsics: hpose's JSON {\"width\",\"height\",\"fx\","
                  "\"fy\",\"cx\",\"cy\"} or a ROS camera_info YAML; default: intrinsics.json "
                  "beside the frame (as `hpose replay` and hposed read it), a .pclzf's own, else "
                  "Kinect v1 for the frame's size (a note says which)",
                  "CAM.json|CAM.yaml");
  flags.AddString("cloud", &cloud_path,
                  "point cloud (.pcd or .ply) in the sensor frame (x right, y down, z forward), "
                  "metres",
                  "FRAME.pcd");
  flags.AddStrings("template", &template_paths,
                   "humanoid template (.bt with its .json sidecar) or a shipped template's "
                   "name; default: the shipped standing and right_arm_raised",
                   "FILE.bt");
  flags.AddString("search", &search,
                  "pose search: 'exact' (global optimum on a lattice of 1 deg and a quarter "
                  "voxel: 4 mm at 16 mm) or 'paper' (the paper's two coarse-to-fine passes)",
                  "KIND");
  flags.AddString("score", &score,
                  "pose value: 'free-space' (the paper's voxel overlap minus template voxels where "
                  "the sensor saw through) or 'paper' (the overlap alone)",
                  "KIND");
  flags.AddInt("max-height-voxels", &options.max_height_voxels,
               "the search runs on the templates' voxels, or on coarser ones for a body taller "
               "than N of them (its height / N, to the mm; a note says so): a 1.23 m robot made "
               "at 16 mm is searched at 28 mm in about half the time, as accurately; 8-1024, or "
               "0: always the templates' own",
               "N");
  flags.AddDouble("threshold", &options.score_threshold,
                  "score (0-100) a cluster needs to count as the humanoid");
  flags.AddDouble("min-fit", &options.min_humanoid_fit,
                  "refined fit (0-100) a cluster's pose also needs to count as the humanoid: the "
                  "share of its points on the template times the share of the template not seen "
                  "through (0: the score alone)");
  flags.AddDouble("min-evidence", &options.min_humanoid_evidence,
                  "share (0-1) of the template's voxels a cluster's refined pose must also "
                  "cover, weighed by (fit/100)^8, to count as the humanoid: clutter that passes "
                  "the score and the fit covers little of the template (0: off)",
                  "E");
  flags.AddDouble("far-ratio", &options.far_score_ratio,
                  "when nothing passes --threshold, a cluster 2.5 m or more from the sensor "
                  "(where depth noise lowers a humanoid's score) passes from this share of it, "
                  "if its pose covers enough of the template, fitting well (0-1; 1: one "
                  "threshold at every range)",
                  "R");
  flags.AddInt("height-offset-voxels", &options.height_offset_voxels,
               "when nothing passes, search again with the templates standing 1, 2, ... up to "
               "N (0-8) voxels lower and higher than the floor (a robot with bent knees stands "
               "lower than a template made with straight legs; 0: only on the floor)",
               "N");
  flags.AddInt("stride", &stride,
               "use every N-th (1-16) depth pixel in each direction (2: 640x480 -> 320x240 like "
               "the paper; about 0.73x the time of a tracked frame, at the cost of less certain "
               "headings and robots missed at 3.5 m)");
  flags.AddDouble("floor-height", &floor_height,
                  "fixed floor calibration: sensor height above the floor in metres (skips the "
                  "per-frame floor fit)",
                  "M");
  flags.AddDouble("floor-pitch-deg", &floor_pitch_deg,
                  "with --floor-height: optical axis below the horizon, degrees", "DEG");
  flags.AddDouble("floor-roll-deg", &floor_roll_deg, "with --floor-height: roll, degrees", "DEG");
  flags.AddDouble("floor-max-tilt-deg", &floor_max_tilt_deg,
                  "a fitted floor's normal lies at most this far from the sensor's up direction, "
                  "degrees (walls lie further; 70 fits pitches to 60 with some roll; a sensor "
                  "looking down more steeply, from near the ceiling, needs up to 85.9)",
                  "DEG");
  flags.AddDouble("floor-min-width", &options.floor_fit.min_width_m,
                  "a fitted floor's inliers must spread at least this wide, metres (narrower "
                  "planes are strips through objects when no floor is in view; 0: no check)",
                  "M");
  flags.AddString("picture", &picture,
                  "also draw the match (top and front views) to a PNG; without a humanoid, the "
                  "nearest miss and why it was refused",
                  "OUT.png");
  flags.AddInt("threads", &options.threads,
               "threads (0-256) for the frame's (cluster, template) searches, 0 = one per core "
               "this process may use; the result does not depend on it",
               "N");
  flags.AddBool("json", &json, "print one JSON object instead of text");
  flags.Within("threshold", 0.0, 100.0);
  flags.Within("min-fit", 0.0, 100.0);
  flags.Within("min-evidence", 0.0, 1.0);
  flags.Within("far-ratio", 0.0, 1.0);
  flags.Within("height-offset-voxels", 0, 8);
  flags.Within("stride", 1, 16);
  flags.Within("threads", 0, 256);
  flags.Within("floor-min-width", 0.0, 100.0);
  flags.SetEpilog(
      "exit status: 0 humanoid found, 3 no humanoid passed the threshold, 4 no floor found,\n"
      "             1 bad input (the message names it), 2 usage\n\n"
      "examples:\n"
      "  hpose simulate --out /tmp/frame && hpose estimate /tmp/frame/depth.png\n"
      "  hpose estimate --depth frame.tif --intrinsics camera_info.yaml\n"
      "  hpose estimate --cloud scan.pcd --template my_robot.bt --json");
  return flags;
}

}  // namespace hpose::tools
