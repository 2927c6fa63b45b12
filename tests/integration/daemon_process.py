"""Starting hposed for the Python integration tests."""

import queue
import select
import subprocess
import threading
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


def start_daemon_with_http(hposed, args, timeout=60.0):
    """Starts `hposed` with --http on free loopback ports; returns (process, gRPC address, HTTP
    base URL such as http://127.0.0.1:PORT) once both are served. The log is read on a thread."""
    proc = subprocess.Popen([hposed, "--listen", "127.0.0.1:0", "--http", "127.0.0.1:0"] + args,
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    # A thread reads the log: select() on a buffered pipe misses lines already read ahead.
    lines = queue.Queue()
    def read_log():
        for line in proc.stdout:
            lines.put(line)
        proc.stdout.close()
    threading.Thread(target=read_log, daemon=True).start()
    grpc_address = http_url = None
    deadline = time.monotonic() + timeout
    seen = []
    while time.monotonic() < deadline and not (grpc_address and http_url):
        try:
            line = lines.get(timeout=0.5)
        except queue.Empty:
            if proc.poll() is not None:
                break
            continue
        seen.append(line)
        if "listening on " in line:
            grpc_address = line.split("listening on ")[1].split()[0]
        if "web view on " in line:
            http_url = line.split("web view on ")[1].split()[0].rstrip("/")
    if not (grpc_address and http_url):
        proc.kill()
        raise RuntimeError("hposed did not start: %s" % "".join(seen))
    return proc, grpc_address, http_url
