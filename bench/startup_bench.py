#!/usr/bin/env python3
"""Start-up cost of the `hpose` command line (docs/BENCHMARKS.md, "Start-up").

Times, as wall clock medians over --runs runs: `hpose --help`, `hpose COMMAND --help` for every
command, and `hpose estimate --json` of one simulated frame next to the estimator's own
`timings.total` (the issue's target: wall <= 2 x total + 50 ms). Several programs can be given
(e.g. the previous build and this one): their runs are interleaved so that a busy machine slows
them alike.

  python3 bench/startup_bench.py build/tools/hpose [OTHER_HPOSE ...] [--runs 20]
"""
import argparse
import json
import statistics
import subprocess
import tempfile
import time

COMMANDS = ["demo", "estimate", "simulate", "estimate-stereo", "simulate-stereo",
            "calibrate stereo", "template", "template from-urdf", "record", "replay", "query"]


def wall_ms(argv):
    start = time.perf_counter()
    done = subprocess.run(argv, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, check=False)
    return (time.perf_counter() - start) * 1000.0, done


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("programs", nargs="+", help="hpose executables to compare")
    parser.add_argument("--runs", type=int, default=20, help="runs per measurement")
    args = parser.parse_args()

    with tempfile.TemporaryDirectory() as frame_dir:
        subprocess.run([args.programs[-1], "simulate", "--out", frame_dir, "--clutter", "3"],
                       stdout=subprocess.DEVNULL, check=True)
        estimate = ["estimate", "--depth", frame_dir + "/depth.png", "--intrinsics",
                    frame_dir + "/intrinsics.json", "--json"]
        cases = [("--help", ["--help"])] + [(c + " --help", c.split() + ["--help"])
                                            for c in COMMANDS] + [("estimate (one frame)", estimate)]
        print("| command | " + " | ".join(args.programs) + " |")
        print("|---|" + "---|" * len(args.programs))
        for label, case in cases:
            walls = {p: [] for p in args.programs}
            totals = {p: [] for p in args.programs}
            for _ in range(args.runs):
                for p in args.programs:
                    ms, done = wall_ms([p] + case)
                    walls[p].append(ms)
                    if case is estimate:
                        line = done.stdout.decode().splitlines()[0]
                        totals[p].append(json.loads(line)["timings"]["total"] * 1000.0)
            cells = []
            for p in args.programs:
                cell = "%.1f" % statistics.median(walls[p])
                if totals[p]:
                    total = statistics.median(totals[p])
                    cell += " (total %.1f, wall - total %.1f)" % (
                        total, statistics.median(w - t for w, t in zip(walls[p], totals[p])))
                cells.append(cell)
            print("| `hpose %s` | %s |" % (label, " | ".join(cells)))


if __name__ == "__main__":
    main()
