#!/usr/bin/env python3
"""Floors and humanoids seen from mounts up to 85 degrees down (docs/BENCHMARKS.md).

For each --pitches value, simulates --scenes frames with `hpose simulate`: the humanoid where the
optical axis crosses its mid-height (0.3 m), 1.0-2.5 m ahead, the sensor as high as that makes it
(at most 3 m: higher mounts are drawn 2.2-3.0 m high, the humanoid nearer), give or take 0.2 m
along the floor and up to 0.3 m aside; under 5 degrees of pitch the sensor 0.3-1.0 m high and the
humanoid 1.2-3.0 m away within 15 degrees of the axis; any heading, either preset, three clutter
objects. Each frame is estimated once per --tilts value (`hpose estimate --json`; the
value "default" runs without --floor-max-tilt-deg) and held against the simulation's truth: the
floor fitted, the humanoid found (the first humanoid within 0.1 m of the truth), the heading
within 5 degrees, the right preset, the humanoid detections more than 0.3 m from the truth
(clutter taken for one), the median position and heading errors and the floor's height and pitch
errors. Then, per pitch, the frames whose first humanoid differs between the settings
by more than 1 mm or 0.1 degree. The frames are the same for every setting and run of a seed.

  python3 bench/steep_mount_bench.py build/tools/hpose [--scenes 12] [--seed 3]
      [--pitches 0,20,45,60,65,70,75,80,85] [--tilts default,85.9] [--estimate-args '...']
"""
import argparse
import json
import math
import os
import random
import statistics
import subprocess
import tempfile


def scene_args(rng, out_dir, pitch_deg, index):
    """The `hpose simulate` arguments of one frame at `pitch_deg`, and its preset."""
    pitch = math.radians(pitch_deg)
    if pitch_deg < 5.0:
        height = rng.uniform(0.3, 1.0)
        distance = rng.uniform(1.2, 3.0)
        bearing = math.radians(rng.uniform(-15.0, 15.0))
        x, y = distance * math.cos(bearing), distance * math.sin(bearing)
    else:
        # The optical axis crosses the humanoid's mid-height (0.3 m) this far ahead.
        ahead = rng.uniform(1.0, 2.5)
        height = 0.3 + ahead * math.tan(pitch)
        if height > 3.0:
            height = rng.uniform(2.2, 3.0)
            ahead = (height - 0.3) / math.tan(pitch)
        x = ahead + rng.uniform(-0.2, 0.2)
        y = rng.uniform(-0.3, 0.3)
    preset = rng.choice(["standing", "right_arm_raised"])
    args = ["simulate", "--out", out_dir, "--x", "%.3f" % x, "--y", "%.3f" % y,
            "--theta-deg", "%.1f" % rng.uniform(-180.0, 180.0), "--pose", preset,
            "--clutter", "3", "--seed", str(index + 1), "--sensor-height", "%.3f" % height,
            "--pitch-deg", str(pitch_deg), "--no-cloud"]
    return args, preset


def angle_diff_deg(a, b):
    return math.degrees((a - b + math.pi) % (2.0 * math.pi) - math.pi)


def score(estimate, truth, preset):
    """What one estimate got right; its first humanoid's pose, or None."""
    out = {"floor": False, "found": False, "within_5": False, "preset": False, "pose": None,
           "others": 0}
    result = estimate.get("depth_template")
    if not result:
        return out
    floor = result["floor"]
    sensor = truth["sensor"]
    out["floor"] = True
    out["floor_height_error"] = abs(floor["height"] - sensor["height_m"])
    out["floor_pitch_error"] = abs(math.degrees(floor["pitch"] - sensor["pitch_rad"]))
    humans = [d for d in result.get("detections", []) if d["is_humanoid"]]
    t = truth["humanoid"]
    out["others"] = sum(math.hypot(d["best"]["pose"]["x"] - t["x"],
                                   d["best"]["pose"]["y"] - t["y"]) > 0.3 for d in humans)
    if not humans:
        return out
    best = humans[0]["best"]
    pose = best["pose"]
    out["pose"] = pose
    position_error = math.hypot(pose["x"] - t["x"], pose["y"] - t["y"])
    if position_error > 0.1:
        return out
    heading_error = abs(angle_diff_deg(pose["theta"], t["theta"]))
    out.update(found=True, within_5=heading_error <= 5.0, preset=best["template_name"] == preset,
               position_error=position_error, heading_error=heading_error)
    return out


def same_pose(a, b):
    if a is None or b is None:
        return a is None and b is None
    return (math.hypot(a["x"] - b["x"], a["y"] - b["y"]) <= 0.001 and
            abs(angle_diff_deg(a["theta"], b["theta"])) <= 0.1)


def median(values, scale=1.0, digits=1):
    return "%.*f" % (digits, scale * statistics.median(values)) if values else "-"


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("program", help="the hpose executable")
    parser.add_argument("--scenes", type=int, default=12, help="frames per pitch (default 12)")
    parser.add_argument("--seed", type=int, default=3, help="seed of the frames (default 3)")
    parser.add_argument("--pitches", default="0,20,45,60,65,70,75,80,85",
                        help="sensor pitches, degrees down (default 0,20,45,60,65,70,75,80,85)")
    parser.add_argument("--tilts", default="default,85.9",
                        help="--floor-max-tilt-deg values; 'default' runs without the flag "
                             "(default: default,85.9)")
    parser.add_argument("--estimate-args", default="",
                        help="more `hpose estimate` flags for every setting, e.g. "
                             "'--threshold 40'")
    args = parser.parse_args()
    pitches = [float(p) for p in args.pitches.split(",")]
    tilts = args.tilts.split(",")
    if args.scenes < 1 or any(abs(p) > 85.0 for p in pitches):
        parser.error("--scenes must be at least 1 and every pitch within +-85 degrees")

    rng = random.Random(args.seed)
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for pitch in pitches:
            results = {t: [] for t in tilts}
            differing = 0
            for s in range(args.scenes):
                frame_dir = os.path.join(tmp, "p%g_%02d" % (pitch, s))
                simulate, preset = scene_args(rng, frame_dir, pitch, s)
                subprocess.run([args.program] + simulate, stdout=subprocess.DEVNULL, check=True)
                with open(os.path.join(frame_dir, "truth.json"), encoding="utf-8") as f:
                    truth = json.load(f)
                poses = []
                for tilt in tilts:
                    command = [args.program, "estimate", os.path.join(frame_dir, "depth.png"),
                               "--json"] + args.estimate_args.split()
                    if tilt != "default":
                        command += ["--floor-max-tilt-deg", tilt]
                    run = subprocess.run(command, capture_output=True, text=True, check=False)
                    if run.returncode not in (0, 3, 4):
                        raise SystemExit("%s failed (%d): %s" % (" ".join(command),
                                                                 run.returncode, run.stderr))
                    counted = score(json.loads(run.stdout), truth, preset)
                    results[tilt].append(counted)
                    poses.append(counted["pose"])
                differing += any(not same_pose(p, poses[0]) for p in poses[1:])
                print("pitch %g: frame %d of %d" % (pitch, s + 1, args.scenes), flush=True,
                      end="\r")
            rows.append((pitch, results, differing))
    print()
    print("| pitch (deg) | max tilt | frames | floor fitted | humanoid found | heading within 5 "
          "deg | right preset | other humanoids | median position error (mm) | median heading "
          "error (deg) | median floor height error (mm) / pitch error (deg) |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for pitch, results, _ in rows:
        for tilt in tilts:
            r = results[tilt]
            found = [c for c in r if c["found"]]
            floors = [c for c in r if c["floor"]]
            print("| %g | %s | %d | %d | %d | %d | %d | %d | %s | %s | %s / %s |" % (
                pitch, tilt, len(r), len(floors), len(found), sum(c["within_5"] for c in found),
                sum(c["preset"] for c in found), sum(c["others"] for c in r),
                median([c["position_error"] for c in found], 1000.0),
                median([c["heading_error"] for c in found], digits=2),
                median([c["floor_height_error"] for c in floors], 1000.0),
                median([c["floor_pitch_error"] for c in floors], digits=3)))
    if len(tilts) > 1:
        print("\nframes whose first humanoid differs between the settings (> 1 mm or 0.1 deg): " +
              ", ".join("%g deg: %d" % (pitch, d) for pitch, _, d in rows))


if __name__ == "__main__":
    main()
