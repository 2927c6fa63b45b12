#!/usr/bin/env python3
"""Per-stage profile of an hpose benchmark from `perf script` output.

Each sample is charged to the innermost estimator stage on its call stack (depth to cloud,
floor fit, clustering, range image, cluster voxels, free-space cells, pose search, refinement,
the view comparison of the refinement);
within a stage the leaf functions are ranked by samples. Usage:

  perf record -F 2000 --call-graph dwarf,16384 -o frame.data -- \
      taskset -c 0 build/bench/frame_bench --frames 30 --only "exact search"
  perf script -i frame.data -F comm,tid,time,event,ip,sym --no-inline | \
      bench/perf_stages.py [--top N] [--hz 2000 --frames 30]
"""
import argparse
import collections
import re
import sys

# (stage, pattern matched against a demangled frame); the innermost frame that matches wins, so
# a stage nested inside another (the range image inside the estimator's search loop) is found.
STAGES = [
    ("depth to cloud", re.compile(r"^hpose::DepthToCloud\b")),
    ("floor fit", re.compile(r"^hpose::FitFloor\b|^hpose::FloorTracker::")),
    ("clustering", re.compile(r"^hpose::ExtractClusters\b")),
    ("range image", re.compile(r"^hpose::RangeImage::FromCloud\b")),
    ("cluster voxels", re.compile(r"^hpose::VoxeliseCluster\b")),
    ("free-space cells", re.compile(r"^hpose::FreeSpaceCells\b")),
    ("refinement", re.compile(r"^hpose::(RefinePose|EvaluatePose)\b")),
    ("view comparison (refinement)", re.compile(r"^hpose::CompareViews\b")),
    ("pose search", re.compile(r"^hpose::\w+Search::Search\b")),
    ("scorer setup", re.compile(r"^hpose::MakePoseScorer\b")),
    ("frame simulation (bench setup)", re.compile(r"^hpose::SimulateFrame\b")),
    ("estimator setup", re.compile(r"^hpose::Estimator::Estimator\b|LoadShippedTemplates")),
]


def Samples(stream):
    frames = []
    for line in stream:
        line = line.rstrip("\n")
        if not line.strip():
            if frames:
                yield frames
            frames = []
            continue
        if line.startswith("\t") or line.startswith(" "):
            parts = line.strip().split(None, 1)
            frames.append(parts[1] if len(parts) > 1 else "[unknown]")
        else:
            frames = []
    if frames:
        yield frames


def Short(symbol):
    symbol = symbol.replace("(anonymous namespace)::", "")
    symbol = re.sub(r"<.*", "<...>", symbol)  # template arguments.
    return symbol[:80]


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--top", type=int, default=5, help="leaf functions per stage (5)")
    parser.add_argument("--hz", type=float, default=0.0,
                        help="the -F sampling rate of perf record: adds ms per frame")
    parser.add_argument("--frames", type=int, default=1, help="frames the run estimated")
    args = parser.parse_args()
    stage_samples = collections.Counter()
    leaves = collections.defaultdict(collections.Counter)
    total = 0
    for frames in Samples(sys.stdin):
        total += 1
        stage = "other (start-up, loading, bench bookkeeping)"
        for frame in frames:  # innermost first.
            hit = next((name for name, pattern in STAGES if pattern.search(frame)), None)
            if hit:
                stage = hit
                break
        stage_samples[stage] += 1
        leaves[stage][Short(frames[0])] += 1
    if total == 0:
        sys.exit("perf_stages: no samples on stdin (pipe `perf script` output in)")
    print(f"{total} samples\n")
    per_frame = args.hz > 0 and args.frames > 0
    print("| stage | share of samples |" + (" ms per frame |" if per_frame else "") +
          " top leaf functions (share of the stage) |")
    print("|---|---|" + ("---|" if per_frame else "") + "---|")
    for stage, n in stage_samples.most_common():
        top = ", ".join(f"`{sym}` {100.0 * c / n:.0f}%" for sym, c in leaves[stage].most_common(args.top))
        ms = f" {1e3 * n / args.hz / args.frames:.2f} |" if per_frame else ""
        print(f"| {stage} | {100.0 * n / total:.1f}% |{ms} {top} |")


if __name__ == "__main__":
    main()
