#!/usr/bin/env python3
"""hposed's HTTP side without a browser: /metrics (promtool check metrics when Debian's
prometheus package provides it; counters moving as frames flow), /healthz, the JSON endpoints,
/events, request bodies far too large or chunked, byte ranges, header floods, stalled,
trickled and malformed requests, a flood of connections, and the refusal of a non-loopback
--http address without --insecure.

usage: http_endpoints_test.py HPOSED HPOSE SOURCE_DIR
"""

import json
import os
import re
import shutil
import socket
import subprocess
import sys
import tempfile
import time
import unittest
import urllib.error
import urllib.request

from daemon_process import DaemonTestCase, simulate_frames, start_daemon_with_http

HPOSED, HPOSE, SOURCE_DIR = sys.argv[1:4]


def get(url):
    """(HTTP status, body text, content type) of a GET."""
    try:
        with urllib.request.urlopen(url, timeout=10) as reply:
            return reply.status, reply.read().decode(), reply.headers.get("Content-Type")
    except urllib.error.HTTPError as e:
        return e.code, e.read().decode(), e.headers.get("Content-Type")


def sample(metrics, name, labels):
    """The value of one sample line, e.g. sample(text, "x_total", 'source="depth"')."""
    match = re.search(r"^%s\{%s\} (\S+)$" % (re.escape(name), re.escape(labels)), metrics,
                      re.MULTILINE)
    if not match:
        raise AssertionError("no sample %s{%s} in:\n%s" % (name, labels, metrics))
    return float(match.group(1))


class HttpEndpointsTest(DaemonTestCase):

    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory()
        frames = os.path.join(cls.tmp.name, "frames")
        simulate_frames(HPOSE, frames, 3, "--turn-deg", "20")
        templates = os.path.join(SOURCE_DIR, "templates")
        cls.proc, cls.grpc, cls.http = start_daemon_with_http(HPOSED, [
            "--source", frames, "--loop", "--fps", "5",
            "--template", os.path.join(templates, "standing.bt")])
        deadline = time.monotonic() + 120
        while get(cls.http + "/api/latest")[0] != 200 and time.monotonic() < deadline:
            time.sleep(0.2)

    def test_metrics_counters_move_and_the_text_is_valid(self):
        status, first, ctype = get(self.http + "/metrics")
        self.assertEqual(status, 200)
        self.assertTrue(ctype.startswith("text/plain; version=0.0.4"), ctype)
        estimated = sample(first, "hposed_frames_estimated_total", 'source="depth"')
        deadline = time.monotonic() + 120
        while time.monotonic() < deadline:
            later = get(self.http + "/metrics")[1]
            if sample(later, "hposed_frames_estimated_total", 'source="depth"') > estimated:
                break
            time.sleep(0.2)
        self.assertGreater(sample(later, "hposed_frames_estimated_total", 'source="depth"'),
                           estimated)
        self.assertGreater(sample(later, "hposed_frames_received_total", 'source="depth"'), 0)
        self.assertEqual(sample(later, "hposed_source_state", 'source="depth",state="running"'),
                         1)
        self.assertGreater(sample(later, "hposed_estimate_stage_seconds_count",
                                  'stage="search"'), 0)
        # The daemon's descriptors beside their limit.
        fds = re.search(r"^process_open_fds (\d+)$", later, re.MULTILINE)
        limit = re.search(r"^process_max_fds (\d+)$", later, re.MULTILINE)
        self.assertTrue(fds and limit, later)
        self.assertGreater(int(fds.group(1)), 3)
        self.assertLess(int(fds.group(1)), int(limit.group(1)))
        # A gRPC call is counted by method and code.
        subprocess.run([HPOSE, "query", "--server", self.grpc, "status"], check=True,
                       stdout=subprocess.DEVNULL)
        calls = get(self.http + "/metrics")[1]
        self.assertGreaterEqual(sample(calls, "hposed_rpc_total",
                                       'method="hpose.v1.PoseService/GetStatus",code="OK"'), 1)
        promtool = shutil.which("promtool")
        if promtool is None:
            self.skipTest("promtool (Debian package prometheus) is not installed; the format is "
                          "checked by server_unit_test's parser")
        check = subprocess.run([promtool, "check", "metrics"], input=calls, text=True,
                               capture_output=True)
        self.assertEqual(check.returncode, 0, check.stdout + check.stderr)

    def test_healthz_and_json_endpoints(self):
        status, body, _ = get(self.http + "/healthz")
        self.assertEqual(status, 200, body)
        self.assertEqual(json.loads(body)["source_state"], "running")
        status, body, ctype = get(self.http + "/api/latest?estimator=depth")
        self.assertEqual(status, 200, body)
        self.assertEqual(ctype, "application/json")
        estimate = json.loads(body)["estimate"]
        self.assertEqual(estimate["estimator"], "ESTIMATOR_KIND_DEPTH_TEMPLATE")
        status, body, _ = get(self.http + "/api/latest?estimator=stereo")
        self.assertEqual(status, 409, body)  # FAILED_PRECONDITION: no stereo source.
        status, body, _ = get(self.http + "/api/latest?estimator=sideways")
        self.assertEqual(status, 400, body)
        self.assertIn("sideways", json.loads(body)["message"])
        status, body, _ = get(self.http + "/api/status")
        self.assertEqual(json.loads(body)["source"]["kind"], "png-dir")
        status, body, _ = get(self.http + "/api/templates")
        self.assertEqual([t["name"] for t in json.loads(body)["templates"]], ["standing"])
        scene = json.loads(get(self.http + "/api/scene")[1])
        self.assertGreater(len(scene["points"]), 0)
        self.assertEqual(scene["template"], "standing")
        self.assertEqual(get(self.http + "/no-such-page")[0], 404)

    def test_events_stream_snapshots(self):
        with urllib.request.urlopen(self.http + "/events", timeout=30) as reply:
            self.assertEqual(reply.headers.get("Content-Type"), "text/event-stream")
            line = reply.readline().decode()
        self.assertTrue(line.startswith("data: "), line)
        snapshot = json.loads(line[len("data: "):])
        self.assertEqual(sorted(snapshot), ["latest", "latest_error", "scene", "status",
                                            "stereo", "stereo_error"])

    def test_page_is_self_contained(self):
        status, page, ctype = get(self.http + "/")
        self.assertEqual(status, 200)
        self.assertTrue(ctype.startswith("text/html"))
        # No external assets: nothing is loaded from another host.
        self.assertIsNone(re.search(r"(src|href)=\"(https?:)?//", page), "external asset")
        self.assertIn("new EventSource(\"events\")", page)

    def raw_request(self, head, body_chunk=b"", body_limit=0):
        """Sends head, then body_chunk repeatedly until body_limit bytes went out or the daemon
        stopped reading; returns (reply bytes, body bytes sent)."""
        host, port = self.http[len("http://"):].rsplit(":", 1)
        sent = 0
        with socket.create_connection((host, int(port)), timeout=30) as conn:
            conn.sendall(head)
            try:
                while sent < body_limit:
                    conn.sendall(body_chunk)
                    sent += len(body_chunk)
            except OSError:  # the daemon closed the connection: it read no further.
                pass
            reply = b""
            try:
                while True:
                    data = conn.recv(65536)
                    if not data:
                        break
                    reply += data
            except OSError:
                pass
        return reply, sent

    def test_a_huge_request_body_is_refused_unread(self):
        # Every route is a GET; a body announced as 2 GB is refused at once, not buffered, and
        # the daemon serves on.
        reply, _ = self.raw_request(b"POST /api/latest HTTP/1.1\r\nHost: x\r\n"
                                    b"Content-Length: 2000000000\r\n\r\n" + b"a" * 65536)
        self.assertTrue(reply.startswith(b"HTTP/1.1 405"), reply[:200])
        self.assertIn(b"Allow: GET, HEAD", reply)
        self.assertEqual(get(self.http + "/healthz")[0], 200)

    def test_a_chunked_request_body_is_refused_unread(self):
        # A chunked body has no declared length for a limit to check: the HTTP library the view
        # used before buffered the chunks as long as they came (1 GB sent, 1.3 GB resident).
        # The method is refused before any body is read, and the connection closes long before
        # 256 MB went out.
        chunk = b"100000\r\n" + b"a" * 0x100000 + b"\r\n"
        reply, sent = self.raw_request(
            b"POST /api/latest HTTP/1.1\r\nHost: x\r\nTransfer-Encoding: chunked\r\n\r\n",
            chunk, 256 * len(chunk))
        self.assertTrue(reply.startswith(b"HTTP/1.1 405"), reply[:200])
        self.assertIn(b"GET only, not POST", reply)
        self.assertLess(sent, 256 * len(chunk), "the daemon read the whole chunked body")
        self.assertEqual(get(self.http + "/healthz")[0], 200)

    def test_byte_ranges_are_not_served_in_parts(self):
        # 2 600 ranges of the page fit in 8 KB of header; the HTTP library the view used before
        # copied the page once a range (a 49 MB answer; 60 such requests unread: 2.9 GB
        # resident). The view serves the whole answer, once, whatever the Range.
        page = get(self.http + "/")[1].encode()
        for ranges in (b"bytes=" + b",".join([b"0-"] * 2600), b"bytes=0-99"):
            reply, _ = self.raw_request(b"GET / HTTP/1.1\r\nHost: x\r\nRange: " + ranges +
                                        b"\r\nConnection: close\r\n\r\n")
            self.assertTrue(reply.startswith(b"HTTP/1.1 200"), reply[:200])
            self.assertEqual(reply.split(b"\r\n\r\n", 1)[1], page)

    def test_a_header_flood_is_cut_off(self):
        # Header lines without end: the library the view used before stored every one (392 MB
        # sent in 5 s: 705 MB resident). A request head may hold 16 KiB: 431, and the
        # connection ends long before 64 MB went out.
        line = b"X-Filler: " + b"v" * 8000 + b"\r\n"
        reply, sent = self.raw_request(b"GET /healthz HTTP/1.1\r\nHost: x\r\n", line * 8,
                                       (64 << 20))
        self.assertTrue(reply.startswith(b"HTTP/1.1 431"), reply[:200])
        self.assertIn(b"request head larger than 16384 bytes", reply)
        self.assertLess(sent, 64 << 20, "the daemon read the whole flood")
        self.assertEqual(get(self.http + "/healthz")[0], 200)

    def test_a_trickled_request_head_is_cut_off(self):
        # A byte every 0.2 s never let the library's per-read timeout pass, so one such client
        # held a worker for as long as it liked; the whole head must come within 2 s.
        host, port = self.http[len("http://"):].rsplit(":", 1)
        start = time.monotonic()
        reply = b""
        with socket.create_connection((host, int(port)), timeout=30) as conn:
            try:
                for byte in b"GET /healthz HTTP/1.1\r\nHost: x\r\nX-Slow: " + b"z" * 100:
                    conn.sendall(bytes([byte]))
                    time.sleep(0.2)
            except OSError:
                pass
            try:
                reply = conn.recv(4096)
            except OSError:
                pass
        self.assertTrue(reply.startswith(b"HTTP/1.1 408"), reply[:200])
        self.assertLess(time.monotonic() - start, 5.0)

    def test_malformed_requests_get_400_naming_the_fault(self):
        for head, fault in ((b"GET healthz HTTP/1.1\r\n\r\n", b"does not start with '/'"),
                            (b"GET / HTTP/2.0\r\n\r\n", b"HTTP/1.0 or HTTP/1.1"),
                            (b"GET / HTTP/1.1\r\nno colon here\r\n\r\n", b"header line 1"),
                            (b"GET /api/latest?estimator=%zz HTTP/1.1\r\n\r\n",
                             b"percent escape")):
            reply, _ = self.raw_request(head)
            self.assertTrue(reply.startswith(b"HTTP/1.1 400"), reply[:200])
            self.assertIn(fault, reply)
        # Bytes that are not UTF-8, quoted back in the message, are replaced (the JSON writer
        # threw over them: 500).
        reply, _ = self.raw_request(b"GET /api/latest?estimator=%ff%00 HTTP/1.1\r\n\r\n")
        self.assertTrue(reply.startswith(b"HTTP/1.1 400"), reply[:200])
        self.assertIn("expected depth or stereo", json.loads(reply.split(b"\r\n\r\n", 1)[1])["message"])
        reply, _ = self.raw_request(b"HEAD /healthz HTTP/1.1\r\n\r\n")
        self.assertTrue(reply.startswith(b"HTTP/1.1 200"), reply[:200])
        self.assertTrue(reply.endswith(b"\r\n\r\n"), reply)
        self.assertIn(b"Content-Length: ", reply)

    def test_stalled_connections_do_not_hold_up_other_requests(self):
        # Three hundred connections that never finish their request head, each kept until the
        # head times out (2 s). One thread reads every connection's head and only whole requests
        # go to workers, so /healthz is answered at once; with a worker reading each connection
        # it waited about 2.1 s (256 workers held), and with a fixed pool of 12, seconds more.
        host, port = self.http[len("http://"):].rsplit(":", 1)
        stalled = []
        try:
            for _ in range(300):
                conn = socket.create_connection((host, int(port)), timeout=30)
                conn.sendall(b"GET /healthz HTTP/1.1\r\nHost: x\r\n")  # no blank line: unfinished.
                stalled.append(conn)
            start = time.monotonic()
            status = get(self.http + "/healthz")[0]
            waited = time.monotonic() - start
            metrics = get(self.http + "/metrics")[1]
        finally:
            for conn in stalled:
                conn.close()
        self.assertEqual(status, 200)
        self.assertLess(waited, 1.0, "/healthz waited behind the stalled connections")
        # /metrics shows them: still sending their head, and open beside the scrape itself.
        reading = sample(metrics, "hposed_http_connections", 'state="reading"')
        self.assertGreaterEqual(reading, 200)
        self.assertLessEqual(reading, 300)
        self.assertGreater(sample(metrics, "hposed_http_connections", 'state="open"'), reading)

    def test_a_connection_flood_leaves_the_daemon_its_descriptors(self):
        # Idle connections held open: each accepted one is a descriptor, and under a service's
        # usual limit (1 024) 1 400 of them left the PNG source unable to open its frames ("Too
        # many open files"). The view keeps at most 256 + 64 open and leaves the rest in the
        # kernel's backlog.
        host, port = self.http[len("http://"):].rsplit(":", 1)
        fd_dir = "/proc/%d/fd" % self.proc.pid
        before = len(os.listdir(fd_dir))
        held = []
        most = before
        try:
            for _ in range(600):
                held.append(socket.create_connection((host, int(port)), timeout=30))
            for _ in range(10):  # the accept loop catches up.
                most = max(most, len(os.listdir(fd_dir)))
                time.sleep(0.05)
        finally:
            for conn in held:
                conn.close()
        self.assertGreater(most - before, 200, "the flood did not reach the view")
        self.assertLessEqual(most - before, 320 + 10)
        deadline = time.monotonic() + 30
        while get(self.http + "/healthz")[0] != 200 and time.monotonic() < deadline:
            time.sleep(0.2)
        self.assertEqual(get(self.http + "/healthz")[0], 200)

    def test_non_loopback_http_needs_insecure(self):
        run = subprocess.run([HPOSED, "--http", "0.0.0.0:0", "--print-config"],
                             capture_output=True, text=True)
        self.assertNotEqual(run.returncode, 0)
        self.assertIn("http.listen", run.stderr)


if __name__ == "__main__":
    unittest.main(argv=sys.argv[:1], verbosity=2)
