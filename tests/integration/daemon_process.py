"""Starting hposed for the Python integration tests."""

import os
import select
import subprocess
import time
import unittest


def watch_log(proc, wanted, timeout):
    """Reads `proc`'s log until every marker in `wanted` has appeared; returns {marker: the word
    after it}. Reads the pipe's descriptor directly: select() on Python's buffered reader would
    miss lines it had already read ahead (e.g. a source's state logged just before the
    address). What follows stays in the pipe for the caller (e.g. communicate())."""
    fd = proc.stdout.fileno()
    text = ""
    found = {}
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline and len(found) < len(wanted):
        ready, _, _ = select.select([fd], [], [], 0.5)
        if not ready:
            if proc.poll() is not None:
                break
            continue
        chunk = os.read(fd, 4096)
        if not chunk:
            break
        text += chunk.decode(errors="replace")
        for line in text.splitlines(keepends=True):
            for marker in wanted:
                if marker in line and line.endswith("\n"):
                    found[marker] = line.split(marker)[1].split()[0]
    if len(found) < len(wanted):
        proc.kill()
        raise RuntimeError("hposed did not start: %s" % text)
    return found


def simulate_frames(hpose, out_dir, frames=3, *extra):
    """Writes `frames` simulated 320x240 depth frames (no clouds) of a standing robot to
    `out_dir` with `hpose simulate`; `extra` are further flags (e.g. "--turn-deg", "20")."""
    subprocess.run([hpose, "simulate", "--out", out_dir, "--frames", str(frames), "--width", "320",
                    "--height", "240", "--no-cloud"] + list(extra), check=True,
                   stdout=subprocess.DEVNULL)


def start_daemon(hposed, args, timeout=60.0):
    """Starts `hposed` on a free loopback port with `args`; returns (process, address)."""
    proc = subprocess.Popen([hposed, "--listen", "127.0.0.1:0"] + args, stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, text=True)
    found = watch_log(proc, ["listening on "], timeout)
    return proc, found["listening on "]


def start_daemon_with_http(hposed, args, timeout=60.0, preexec_fn=None):
    """Starts `hposed` with --http on free loopback ports; returns (process, gRPC address, HTTP
    base URL such as http://127.0.0.1:PORT) once both are served. `preexec_fn` runs in the
    child before hposed (e.g. to set its limits)."""
    proc = subprocess.Popen([hposed, "--listen", "127.0.0.1:0", "--http", "127.0.0.1:0"] + args,
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                            preexec_fn=preexec_fn)
    found = watch_log(proc, ["listening on ", "web view on "], timeout)
    return proc, found["listening on "], found["web view on "].rstrip("/")


class DaemonTestCase(unittest.TestCase):
    """A test case with its own daemon (cls.proc, killed if still running) and temporary
    directory (cls.tmp), both made by its setUpClass."""

    @classmethod
    def tearDownClass(cls):
        if cls.proc.poll() is None:
            cls.proc.kill()
        cls.proc.communicate()  # waits, and closes the log pipe.
        cls.tmp.cleanup()
