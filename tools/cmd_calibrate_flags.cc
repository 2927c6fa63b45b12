#include "tools/cmd_calibrate_flags.h"

#include <iostream>
#include <string>

#include "tools/exit_codes.h"

namespace hpose::tools {

FlagParser CalibrateStereoFlags::Parser() {
  FlagParser flags(
      "hpose calibrate stereo --out CAL.yaml (--dir DIR | --left L1 --right R1 ...)",
      "Calibrates a stereo pair from views of a chessboard held still in front of both cameras "
      "(OpenCV: findChessboardCorners, cornerSubPix, calibrateCamera per camera, "
      "stereoCalibrate, stereoRectify). Writes the calibration that `hpose estimate-stereo "
      "--calibration` and hposed read (M1 D1 M2 D2 R T in metres, the image size, R1 R2 P1 P2 "
      "Q and the RMS error), and prints the RMS reprojection error with a per-pair table. "
      "Use 10 or more pairs with the board tilted and spread over the whole image.");
  flags.AddString(
      "dir", &dir,
      "directory of pairs named left<N>.<ext> / right<N>.<ext> (N: digits, e.g. left01.jpg)",
      "DIR");
  flags.AddStrings("left", &lefts, "left image of one pair, in the order of --right", "IMAGE");
  flags.AddStrings("right", &rights, "right image of one pair", "IMAGE");
  flags.AddInt("cols", &board.inner_columns, "inner corners along a board row");
  flags.AddInt("rows", &board.inner_rows, "inner corners along a board column");
  flags.AddDouble("square", &board.square_m, "side of one chessboard square", "M");
  flags.AddString("out", &out, "calibration file to write (.yaml or .xml)", "FILE");
  flags.SetEpilog(
      "exit status: 0 ok; 1 bad input or too few usable pairs; 2 usage.\n"
      "example:\n  hpose calibrate stereo --dir ./chessboard --cols 9 --rows 6 --square 0.025 "
      "--out stereo.yaml\n");
  return flags;
}

FlagParser WorldFromGroundFlags::Parser() {
  FlagParser flags(
      "hpose calibrate world-from-ground (--pairs PAIRS.csv | --recording DIR | --depth DIR "
      "--stereo DIR)",
      "Finds where the depth sensor's ground frame lies in the landmarks' world frame "
      "(world_from_ground: x, y, yaw) from a recording in which both estimators saw the robot: "
      "a least-squares 2D rigid fit of the depth poses onto the stereo poses with outlier "
      "rejection. Both poses must be of the same robot point (set the stereo estimator's "
      "head_to_reference_m). Prints the placement for hposed's world_from_ground, the "
      "residuals, and what the robot's motion made observable: walk it around the field; a "
      "robot standing still gives the yaw only through its headings. The poses come from a "
      "CSV (--pairs), or from the recording itself: both estimators run over it offline and "
      "each depth pose is paired with the stereo pose nearest in time (within --max-dt).");
  flags.AddString("pairs", &pairs_path,
                  "CSV rows: timestamp_s, ground_x_m, ground_y_m, ground_theta_rad, world_x_m, "
                  "world_y_m, world_theta_rad (header and # lines skipped)",
                  "FILE");
  flags.AddString("recording", &recording,
                  "recording with DIR/depth (depth frames) and DIR/stereo (stereo pairs), as "
                  "`hpose simulate stereo --depth-sensor` writes",
                  "DIR");
  flags.AddString("depth", &depth,
                  "depth recording (a directory of depth frames or clouds, or an .oni file; frame "
                  "times from the file names, else source.fps of --config)",
                  "PATH");
  flags.AddString("stereo", &stereo,
                  "stereo sequence directory (frames.csv or left/ + right/, calibration.yaml)",
                  "DIR");
  flags.AddDouble("max-dt", &max_dt_s,
                  "pair a depth pose with the nearest stereo pose at most this far apart in time",
                  "S");
  flags.AddDouble("stereo-time-offset", &stereo_time_offset_s,
                  "added to the stereo times to put them on the depth recording's clock", "S");
  flags.AddString("config", &config_path,
                  "hposed YAML config: templates, search, floor, source.fps/intrinsics and the "
                  "stereo calibration and options used on the recording",
                  "FILE");
  flags.AddStrings("template", &templates,
                   "humanoid template, .bt file or shipped name (default: config's, else the "
                   "shipped templates)",
                   "FILE.bt");
  flags.AddString("stereo-calibration", &stereo_calibration,
                  "stereo calibration (default: config's, else the sequence's calibration.yaml)",
                  "FILE");
  flags.AddString("stereo-options", &stereo_options,
                  "stereo estimator options (head_to_reference_m, landmarks, ...)", "FILE");
  flags.AddString("pairs-out", &pairs_out, "write the paired poses of a recording as a --pairs CSV",
                  "FILE");
  flags.AddDouble("outlier", &options.outlier_threshold_m,
                  "position residual beyond which (and 3 robust sigmas) a pair is dropped", "M");
  flags.SetEpilog(
      "exit status: 0 ok; 1 bad input or no usable pairs; 2 usage.\n"
      "examples:\n  hpose calibrate world-from-ground --pairs pairs.csv\n"
      "  hpose calibrate world-from-ground --recording rec --config hposed.yaml\n");
  return flags;
}

int RunCalibrateSubcommand(const CalibrateSubcommands& subs, int argc, char** argv) {
  const std::string usage =
      "usage: hpose calibrate stereo|world-from-ground [--help] [options]\n"
      "  stereo             stereo pair calibration from chessboard views\n"
      "  world-from-ground  the depth sensor's place in the landmarks' frame\n";
  if (argc < 2 || std::string(argv[1]) == "--help" || std::string(argv[1]) == "-h") {
    (argc < 2 ? std::cerr : std::cout) << usage;
    return argc < 2 ? kExitUsage : kExitOk;
  }
  const std::string sub = argv[1];
  std::string prog = "hpose calibrate " + sub;
  argv[1] = prog.data();
  if (sub == "stereo") return subs.stereo(argc - 1, argv + 1);
  if (sub == "world-from-ground") return subs.world_from_ground(argc - 1, argv + 1);
  std::cerr << "hpose calibrate: unknown target '" << sub << "'\n" << usage;
  return kExitUsage;
}

}  // namespace hpose::tools
