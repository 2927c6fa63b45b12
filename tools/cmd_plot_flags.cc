#include "tools/cmd_plot_flags.h"

namespace hpose::tools {

FlagParser PlotFlags::Parser() {
  FlagParser flags(
      "hpose plot POSES.jsonl --out TRACK.png [--title TEXT] [--truth truth.json]",
      "Draws a track of depth estimates for people: the floor from above with the humanoid's "
      "path (blue at the first estimate, red at the last) and its heading every few frames, and "
      "x, y, heading and score against time, with gaps where no humanoid was found. POSES.jsonl "
      "holds one hpose.v1.PoseEstimate per line, as `hpose replay` and `hpose query stream "
      "--json` write them ('-': standard input); the stereo estimator's lines are left out.");
  flags.AddString("out", &out, "PNG file to write", "TRACK.png");
  flags.AddString("title", &title, "heading of the picture (default: the input's file name)",
                  "TEXT");
  flags.AddString("truth", &truth_path,
                  "truth.json that `hpose simulate` wrote beside the frames: the true path, x, y "
                  "and heading are drawn beneath the estimates (frames matched by the file name "
                  "in each line's source), and the errors are printed",
                  "FILE");
  flags.AllowPositional("POSES.jsonl");
  flags.SetEpilog(
      "examples:\n  hpose replay walk.oni --out walk.jsonl && hpose plot walk.jsonl --out "
      "walk.png\n"
      "  hpose query stream --json --count 300 | hpose plot - --out live.png\n"
      "  hpose replay sim/ --out sim.jsonl && hpose plot sim.jsonl --truth sim/truth.json "
      "--out sim.png\n");
  return flags;
}

}  // namespace hpose::tools
