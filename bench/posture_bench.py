#!/usr/bin/env python3
"""A robot seen in postures its templates were not made in (docs/BENCHMARKS.md).

The robot is a URDF (--robot, with --joints) or, without --robot, hpose's parametric humanoid
(--body; its postures and template sets are then the joint presets of `hpose template generate
--pose`). Makes templates of --template-sets with `hpose template from-urdf` (or `generate`), or
takes the --templates files given, then for every --postures set
and --mounts mount renders --frames frames of the robot in that posture with `hpose simulate`
(1.0-3.5 m ahead within 12 degrees of the optical axis, any heading, three clutter objects,
depth noise shared as a Kinect's) and estimates each with the templates (`hpose estimate
--json`, plus --estimate-args). A frame counts as found when the first humanoid lies within
0.15 m of the truth (the URDF's reference link projected on the floor); then its heading error,
its position error and the error along the line of sight (negative: toward the sensor) are
taken, and how far off the floor its template stood (`height_offset`). The frames are the same
for every posture (same seeds and draws) and for every binary.

  python3 bench/posture_bench.py build/tools/hpose --robot ROBOT.urdf --joints SETS.yaml
      [--template-sets standing,right_arm_raised] [--postures standing,crouch,...]
      [--frames 24] [--mounts 0.34:0,0.9:20] [--allow-missing] [--estimate-args '...']
  python3 bench/posture_bench.py build/tools/hpose [--body nao] --postures standing,arms_swung
      [--templates A.bt,B.bt]
"""
import argparse
import json
import math
import os
import random
import shlex
import statistics
import subprocess
import sys
import tempfile


def angle_diff_deg(a, b):
    return math.degrees((a - b + math.pi) % (2.0 * math.pi) - math.pi)


def run_json(cmd):
    """The JSON an `hpose ... --json` run prints, or None when it printed none."""
    done = subprocess.run(cmd, capture_output=True, text=True)
    try:
        return json.loads(done.stdout) if done.stdout.strip() else None
    except json.JSONDecodeError:
        return None


def frame_draws(frames, seed):
    """Where the robot stands in each frame: (x, y, heading in degrees), the same every run."""
    rng = random.Random(seed)
    draws = []
    for _ in range(frames):
        distance = rng.uniform(1.0, 3.5)
        bearing = math.radians(rng.uniform(-12.0, 12.0))
        draws.append((distance * math.cos(bearing), distance * math.sin(bearing),
                      rng.uniform(-180.0, 180.0)))
    return draws


def one_case(args, robot_flags, templates, posture, height, pitch, draws, work):
    found, within5, headings, positions, radial, offsets = 0, 0, [], [], [], {}
    for index, (x, y, heading) in enumerate(draws):
        out = os.path.join(work, "frame")
        subprocess.run([args.hpose, "simulate", "--out", out] + robot_flags +
                       [posture, "--x", "%.3f" % x, "--y", "%.3f" % y,
                        "--theta-deg", "%.1f" % heading, "--clutter", "3",
                        "--seed", str(index + 1), "--sensor-height", str(height),
                        "--pitch-deg", str(pitch), "--noise-correlation", "0.9", "--no-cloud"],
                       check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        truth = json.load(open(os.path.join(out, "truth.json")))["humanoid"]
        cmd = [args.hpose, "estimate", os.path.join(out, "depth.png"), "--json"]
        for t in templates:
            cmd += ["--template", t]
        estimate = run_json(cmd + shlex.split(args.estimate_args))
        result = (estimate or {}).get("depth_template") or {}
        humans = [d for d in result.get("detections", []) if d.get("is_humanoid")]
        if not humans:
            continue
        best = humans[0]["best"]
        pose = best["pose"]
        dx, dy = pose["x"] - truth["x"], pose["y"] - truth["y"]
        if math.hypot(dx, dy) > 0.15:
            continue
        found += 1
        error = abs(angle_diff_deg(pose["theta"], truth["theta"]))
        headings.append(error)
        within5 += error <= 5.0
        offset = round(1000.0 * best.get("height_offset", 0.0))
        offsets[offset] = offsets.get(offset, 0) + 1
        if error < 90.0:
            positions.append(1000.0 * math.hypot(dx, dy))
            norm = math.hypot(truth["x"], truth["y"])
            radial.append(1000.0 * (dx * truth["x"] + dy * truth["y"]) / norm)
    median = lambda v: "%.2f" % statistics.median(v) if v else "-"
    mean = lambda v: "%+.1f" % (sum(v) / len(v)) if v else "-"
    offset_text = ", ".join("%+d mm: %d" % (k, v) for k, v in sorted(offsets.items())) or "-"
    print("| %s | %.2f m, %g deg | %d / %d | %d | %s | %s | %s | %s |" %
          (posture, height, pitch, found, len(draws), within5, median(headings),
           median(positions), mean(radial), offset_text), flush=True)


def main():
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("hpose", help="the hpose program")
    parser.add_argument("--robot", help="the robot's URDF (default: the parametric humanoid)")
    parser.add_argument("--joints", help="YAML of named joint sets (with --robot)")
    parser.add_argument("--body", default="nao",
                        help="the parametric humanoid's proportions (default %(default)s)")
    parser.add_argument("--templates", default="",
                        help="template files to use (comma-separated) instead of making them")
    parser.add_argument("--template-sets", default="standing,right_arm_raised",
                        help="the joint sets templates are made of (default %(default)s)")
    parser.add_argument("--postures", default="standing",
                        help="the joint sets the robot is rendered in (default %(default)s)")
    parser.add_argument("--frames", type=int, default=24, help="frames a posture and mount")
    parser.add_argument("--seed", type=int, default=7, help="seed of the robot's places")
    parser.add_argument("--mounts", default="0.34:0,0.9:20",
                        help="sensor HEIGHT:PITCH_DEG pairs (default %(default)s)")
    parser.add_argument("--package-path", action="append", default=[],
                        help="passed to from-urdf and simulate (repeatable)")
    parser.add_argument("--allow-missing", action="store_true",
                        help="skip missing meshes (the Darwin-OP's head)")
    parser.add_argument("--estimate-args", default="", help="more `hpose estimate` flags")
    args = parser.parse_args()
    if args.frames < 1:
        sys.exit("--frames must be at least 1")
    # What from-urdf and simulate both take, and simulate's robot besides.
    mesh_flags = []
    for p in args.package_path:
        mesh_flags += ["--package-path", p]
    if args.allow_missing:
        mesh_flags.append("--allow-missing")
    if args.robot and not args.joints:
        sys.exit("--robot needs --joints")
    # simulate's flags for the robot, ending in the flag that takes the posture's name.
    if args.robot:
        robot_flags = ["--robot", args.robot, "--joints", args.joints] + mesh_flags + [
            "--joint-set"]
    else:
        robot_flags = ["--body", args.body, "--pose"]
    mounts = [tuple(float(v) for v in m.split(":")) for m in args.mounts.split(",")]
    draws = frame_draws(args.frames, args.seed)
    with tempfile.TemporaryDirectory() as work:
        templates = [t for t in args.templates.split(",") if t]
        for name in [] if templates else args.template_sets.split(","):
            path = os.path.join(work, name + ".bt")
            if args.robot:
                cmd = [args.hpose, "template", "from-urdf", args.robot, "--joints", args.joints,
                       "--joint-set", name, "--out", path] + mesh_flags
            else:
                cmd = [args.hpose, "template", "generate", "--pose", name, "--body", args.body,
                       "--out", path]
            subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            templates.append(path)
        print("templates: %s; %d frames a posture and mount" %
              (args.templates or args.template_sets, args.frames))
        print("| posture | mount | found | heading within 5 deg | median heading error (deg) "
              "| median position error (mm) | mean error along the line of sight (mm) "
              "| template's height off the floor: frames |")
        print("|---|---|---|---|---|---|---|---|")
        for height, pitch in mounts:
            for posture in args.postures.split(","):
                one_case(args, robot_flags, templates, posture, height, pitch, draws, work)


if __name__ == "__main__":
    main()
