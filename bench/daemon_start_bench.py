#!/usr/bin/env python3
"""Daemon start-up: how long hposed takes from launch to serving, and its memory then.

For each hposed binary given (e.g. two builds side by side) and each source.estimate_threads
value, starts hposed on a free loopback port with a directory of depth frames as its source
(replayed at 1 fps, so that the frames' estimates barely touch the figures) and the templates
given, waits for its "listening" log line, then reads its resident memory (VmRSS) and peak
(VmHWM) from /proc and stops it. Runs alternate between the binaries; medians are printed as a
Markdown table.

  bench/daemon_start_bench.py --source DIR [--template T.bt ...] [--threads 1,2] [--runs 5]
                              HPOSED [HPOSED ...]
"""
import argparse
import os
import signal
import socket
import statistics
import subprocess
import sys
import tempfile
import time


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def proc_kb(pid, key):
    with open(f"/proc/{pid}/status") as f:
        for line in f:
            if line.startswith(key + ":"):
                return int(line.split()[1])
    return 0


def start_once(hposed, source, templates, threads, timeout_s):
    with tempfile.NamedTemporaryFile("w", suffix=".yaml", delete=False) as cfg:
        cfg.write(f"source:\n  path: {source}\n  fps: 1\n  estimate_threads: {threads}\n")
        if templates:
            cfg.write("templates:\n" + "".join(f"  - {t}\n" for t in templates))
        path = cfg.name
    try:
        t0 = time.monotonic()
        p = subprocess.Popen([hposed, "--config", path, "--listen", f"127.0.0.1:{free_port()}"],
                             stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
        ready = None
        for line in p.stdout:
            if "listening on" in line:
                ready = time.monotonic() - t0
                break
            if time.monotonic() - t0 > timeout_s:
                break
        if ready is None:
            p.kill()
            sys.exit(f"{hposed}: never said it was listening")
        rss, hwm = proc_kb(p.pid, "VmRSS"), proc_kb(p.pid, "VmHWM")
        p.send_signal(signal.SIGTERM)
        try:
            p.wait(timeout=30)
        except subprocess.TimeoutExpired:
            p.kill()
        return ready * 1000.0, rss / 1024.0, hwm / 1024.0
    finally:
        os.unlink(path)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("hposed", nargs="+", help="hposed binaries to compare")
    ap.add_argument("--source", required=True, help="directory of depth frames (PNG + intrinsics.json)")
    ap.add_argument("--template", action="append", default=[], help=".bt template (repeatable; default: the shipped ones)")
    ap.add_argument("--threads", default="1,2", help="source.estimate_threads values (default 1,2)")
    ap.add_argument("--runs", type=int, default=5, help="starts per binary and value (default 5)")
    ap.add_argument("--timeout", type=float, default=120.0, help="seconds to wait for a start")
    a = ap.parse_args()
    threads = [int(t) for t in a.threads.split(",")]
    results = {}
    for t in threads:
        for run in range(a.runs):
            for h in a.hposed:
                results.setdefault((h, t), []).append(
                    start_once(os.path.abspath(h), os.path.abspath(a.source),
                               [os.path.abspath(x) for x in a.template], t, a.timeout))
    print(f"hposed start-up, median of {a.runs} run(s); templates: "
          f"{', '.join(os.path.basename(x) for x in a.template) or 'shipped'}\n")
    print("| hposed | estimate_threads | launch to listening, ms | resident MB | peak MB |")
    print("|---|---|---|---|---|")
    for t in threads:
        for h in a.hposed:
            r = results[(h, t)]
            print(f"| {h} | {t} | {statistics.median(x[0] for x in r):.0f} | "
                  f"{statistics.median(x[1] for x in r):.0f} | {statistics.median(x[2] for x in r):.0f} |")


if __name__ == "__main__":
    main()
