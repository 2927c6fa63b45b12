#!/usr/bin/env python3
"""Tracked headings of a humanoid walking out of the sensor's view (docs/BENCHMARKS.md).

Simulates --walks walks of --frames frames with `hpose simulate`, each starting 1.2-3.0 m away
14-24 degrees off the sensor's axis on either side and heading outward (+-60 degrees), turning
and stepping a little every frame among three clutter objects, the sensor 0.34 m high and level,
0.6 m high pitched 10 degrees down or 0.9 m at 20 degrees, either preset. Each walk is replayed
(`hpose replay`: tracked, as hposed does) with every program given, e.g. a build before a change
and one after, and every estimate is held against the simulation's truth. Per program: frames,
frames with the humanoid found (the first humanoid within 0.3 m of the truth), of those the
headings within 5 degrees and those off by more than 90 (front taken for back), frames flagged
heading_ambiguous, frames with a humanoid more than 0.3 m from the truth (clutter taken for a
humanoid, most often while the robot is out of view), and the median heading and position
errors; then the walks whose counts differ between the programs. The walks are the same for every program and every run of a seed.

  python3 bench/edge_walk_bench.py build/tools/hpose [OTHER_HPOSE ...] [--walks 32]
      [--frames 40] [--seed 7]
"""
import argparse
import json
import math
import os
import random
import statistics
import subprocess
import tempfile


def walk_args(rng, out_dir, frames, index):
    """The `hpose simulate` arguments of walk `index`."""
    distance = rng.uniform(1.2, 3.0)
    side = rng.choice([-1, 1])
    bearing = side * math.radians(rng.uniform(14.0, 24.0))
    heading_deg = side * 90.0 + rng.uniform(-60.0, 60.0)
    turn_deg = rng.uniform(-5.0, 5.0)
    step_m = rng.uniform(0.03, 0.06)
    height_m, pitch_deg = rng.choice([(0.34, 0.0), (0.34, 0.0), (0.9, 20.0), (0.6, 10.0)])
    preset = rng.choice(["standing", "right_arm_raised"])
    return ["simulate", "--out", out_dir, "--frames", str(frames),
            "--x", "%.3f" % (distance * math.cos(bearing)),
            "--y", "%.3f" % (distance * math.sin(bearing)),
            "--theta-deg", "%.1f" % heading_deg, "--turn-deg", "%.2f" % turn_deg,
            "--step-m", "%.3f" % step_m, "--clutter", "3", "--seed", str(index + 1),
            "--sensor-height", str(height_m), "--pitch-deg", str(pitch_deg), "--pose", preset,
            "--no-cloud"]


def angle_diff_deg(a, b):
    return math.degrees((a - b + math.pi) % (2.0 * math.pi) - math.pi)


def score_walk(truth_path, estimates_path):
    """Counts of one replayed walk against its truth."""
    with open(truth_path, encoding="utf-8") as f:
        truth = json.load(f)["frames"]
    with open(estimates_path, encoding="utf-8") as f:
        estimates = [json.loads(line) for line in f if line.strip()]
    counts = {"frames": len(truth), "found": 0, "within_5": 0, "off_90": 0, "ambiguous": 0,
              "elsewhere": 0, "heading_errors": [], "position_errors": []}
    for estimate, t in zip(estimates, truth):
        result = estimate.get("depth_template") or {}
        humans = [d for d in result.get("detections", []) if d["is_humanoid"]]
        if not humans:
            continue
        counts["elsewhere"] += any(
            math.hypot(h["best"]["pose"]["x"] - t["x"], h["best"]["pose"]["y"] - t["y"]) > 0.3
            for h in humans)
        best = humans[0]["best"]
        pose = best["pose"]
        position_error = math.hypot(pose["x"] - t["x"], pose["y"] - t["y"])
        if position_error > 0.3:
            continue
        heading_error = abs(angle_diff_deg(pose["theta"], t["theta"]))
        counts["found"] += 1
        counts["within_5"] += heading_error <= 5.0
        counts["off_90"] += heading_error > 90.0
        counts["ambiguous"] += bool(best["heading_ambiguous"])
        counts["heading_errors"].append(heading_error)
        counts["position_errors"].append(position_error)
    return counts


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("programs", nargs="+", help="hpose executables to compare")
    parser.add_argument("--walks", type=int, default=32, help="walks (default 32)")
    parser.add_argument("--frames", type=int, default=40, help="frames per walk (default 40)")
    parser.add_argument("--seed", type=int, default=7, help="seed of the walks (default 7)")
    args = parser.parse_args()
    if args.walks < 1 or args.frames < 1:
        parser.error("--walks and --frames must be at least 1")

    rng = random.Random(args.seed)
    totals = [dict(frames=0, found=0, within_5=0, off_90=0, ambiguous=0, elsewhere=0,
                   heading_errors=[], position_errors=[]) for _ in args.programs]
    differing = []
    with tempfile.TemporaryDirectory() as tmp:
        for w in range(args.walks):
            walk_dir = os.path.join(tmp, "walk%02d" % w)
            simulate = [args.programs[-1]] + walk_args(rng, walk_dir, args.frames, w)
            subprocess.run(simulate, stdout=subprocess.DEVNULL, check=True)
            per_program = []
            for p, program in enumerate(args.programs):
                out = os.path.join(tmp, "walk%02d.%d.jsonl" % (w, p))
                subprocess.run([program, "replay", walk_dir, "--out", out, "--no-progress"],
                               stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, check=True)
                counts = score_walk(os.path.join(walk_dir, "truth.json"), out)
                for key, value in counts.items():
                    totals[p][key] += value
                per_program.append(counts)
            keys = ("found", "within_5", "off_90", "ambiguous", "elsewhere")
            if any(tuple(c[k] for k in keys) != tuple(per_program[0][k] for k in keys)
                   for c in per_program):
                differing.append((" ".join(simulate[1:]).replace(walk_dir, "walk%02d" % w),
                                  per_program))
            print("walk %d of %d" % (w + 1, args.walks), flush=True, end="\r")
    print()
    print("| program | frames | humanoid found | heading within 5 deg | heading off by more than "
          "90 deg | flagged ambiguous | a humanoid elsewhere | median heading error (deg) | "
          "median position error (mm) |")
    print("|---|---|---|---|---|---|---|---|---|")
    for program, t in zip(args.programs, totals):
        print("| %s | %d | %d | %d | %d | %d | %d | %.2f | %.1f |" % (
            program, t["frames"], t["found"], t["within_5"], t["off_90"], t["ambiguous"],
            t["elsewhere"],
            statistics.median(t["heading_errors"]) if t["heading_errors"] else float("nan"),
            1000.0 * statistics.median(t["position_errors"]) if t["position_errors"]
            else float("nan")))
    if len(args.programs) > 1:
        print("\nwalks whose counts differ (found / within 5 / off by 90 / ambiguous / elsewhere, "
              "per program):" if differing else "\nno walk's counts differ between the programs")
        for command, per_program in differing:
            print("  hpose " + command)
            print("    " + "   ".join("%d / %d / %d / %d / %d" % (
                c["found"], c["within_5"], c["off_90"], c["ambiguous"], c["elsewhere"])
                for c in per_program))


if __name__ == "__main__":
    main()
