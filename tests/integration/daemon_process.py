"""Starting hposed for the Python integration tests."""

import select
import subprocess
import time


def start_daemon(hposed, args, timeout=60.0):
    """Starts `hposed` on a free loopback port with `args`; returns (process, address)."""
    proc = subprocess.Popen([hposed, "--listen", "127.0.0.1:0"] + args, stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, text=True)
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        ready, _, _ = select.select([proc.stdout], [], [], 0.5)
        if ready:
            line = proc.stdout.readline()
            if not line:
                break
            if "listening on" in line:
                return proc, line.split("listening on ")[1].split()[0]
    proc.kill()
    raise RuntimeError("hposed did not start: %s" % proc.stdout.read())
