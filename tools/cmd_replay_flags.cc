#include "tools/cmd_replay_flags.h"

namespace hpose::tools {

FlagParser ReplayFlags::Parser() {
  FlagParser flags(
      "hpose replay RECORDING [--template FILE.bt ...] [--out FILE] [--format jsonl|csv]",
      "Estimates the humanoid's pose in every frame of a recording and writes one record per "
      "frame: JSON Lines (hpose.v1.PoseEstimate in the schema of docs/API.md, every field "
      "present, SI units) or CSV. A recording is an .oni file; a directory of 16-bit depth "
      "frames (PNG with intrinsics.json, TIFF, or PCL's *_depth.pclzf with their .xml) or of PCD "
      "clouds; or a single frame file of one of these formats. Frame times come from the file "
      "names when they record one (frame_20121214T142255.814212.pcd, 1355495775.81.png), else "
      "from --fps. Prints a progress bar and a summary on stderr.");
  flags.AddStrings(
      "template", &templates,
      "humanoid template: a .bt file or a shipped template's name (default: the shipped templates)",
      "FILE.bt");
  flags.AddString("out", &out_path, "output file (default: standard output)", "FILE");
  flags.AddString("format", &format,
                  "jsonl (every field of each estimate) or csv (a row a frame: the best "
                  "detection's template, pose, score, template_margin over the next template in "
                  "the points template_margin_kind names (fit, score, score_at_least) and, when it "
                  "is no humanoid, refused_by: the rule that refused it); default: from --out's "
                  "extension, else jsonl",
                  "FMT");
  flags.AddString("config", &config_path, "hposed YAML config for search and floor settings",
                  "FILE");
  flags.AddString("rate", &rate, "fast (as fast as possible) or recorded", "RATE");
  flags.AddDouble("fps", &fps, "frame rate of files whose names record no time (source_time)",
                  "HZ");
  flags.AddString("intrinsics", &intrinsics_path,
                  "depth camera intrinsics for every frame: hpose's intrinsics.json or a ROS "
                  "camera_info YAML (default: intrinsics.json beside the frames, a pclzf's .xml, "
                  "else Kinect v1 for TIFF)",
                  "FILE");
  flags.AddInt("max-frames", &max_frames, "stop after N frames (0 = all)", "N");
  flags.Within("max-frames", 0, 2147483647.0);
  flags.AddString("initial-pose", &initial_pose,
                  "where the robot stands at the start, ground frame (metres, degrees): until "
                  "it is first found, frames are searched as if the one before had seen it there, "
                  "so a robot too far to pass the score threshold cold is found "
                  "(search.tracked_score_threshold); default: source.initial_pose of --config",
                  "X,Y,DEG");
  flags.AddString("truth", &truth_path,
                  "truth.json that `hpose simulate` wrote beside the frames: each frame's "
                  "humanoid is compared with where it stood (frames matched by file name) and the "
                  "errors are summed up after the summary",
                  "FILE");
  flags.AddBool("no-progress", &no_progress, "no progress bar");
  flags.AllowPositional("RECORDING");
  flags.SetEpilog(
      "examples:\n  hpose replay walk.oni --template templates/standing.bt --out walk.jsonl\n"
      "  hpose replay grabber_sequences/tiff/ --out poses.jsonl\n"
      "  hpose replay frame_20121214T142255.814212.pcd\n"
      "  hpose replay frames/ --template templates/standing.bt --format csv > poses.csv\n"
      "  hpose replay sim/ --truth sim/truth.json --out sim.jsonl   # errors against the truth\n");
  return flags;
}

}  // namespace hpose::tools
