#!/usr/bin/env python3
"""Exercises the Python client (python/hpose_client) and example against a running hposed.

usage: python_client_test.py HPOSED HPOSE SOURCE_DIR   (PYTHONPATH: <build>/python and python/)
"""

import os
import signal
import subprocess
import sys
import tempfile
import time
import unittest

import grpc

import daemon_process
from hpose.v1 import pose_service_pb2 as pb
from hpose_client import PoseClient, PoseClientError, best_pose

HPOSED, HPOSE, SOURCE_DIR = sys.argv[1:4]


def start_daemon(args, timeout=60.0):
    """Starts hposed on a free loopback port; returns (process, address)."""
    return daemon_process.start_daemon(HPOSED, args, timeout)


class PythonClientTest(daemon_process.DaemonTestCase):

    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory()
        cls.frames = os.path.join(cls.tmp.name, "frames")
        daemon_process.simulate_frames(HPOSE, cls.frames, 3, "--turn-deg", "20")
        templates = os.path.join(SOURCE_DIR, "templates")
        cls.proc, cls.address = start_daemon([
            "--source", cls.frames, "--loop", "--fps", "10",
            "--template", os.path.join(templates, "standing.bt"),
            "--template", os.path.join(templates, "right_arm_raised.bt")])
        cls.client = PoseClient(cls.address)
        cls.client.wait_ready(timeout=20)

    @classmethod
    def tearDownClass(cls):
        cls.client.close()
        super().tearDownClass()

    def test_templates_and_status(self):
        names = sorted(t.name for t in self.client.templates())
        self.assertEqual(names, ["right_arm_raised", "standing"])
        status = self.client.status()
        self.assertEqual(status.source.kind, "png-dir")
        self.assertEqual(status.templates, 2)

    def test_stream_gives_increasing_sequences_and_a_pose(self):
        estimates = list(self.client.stream(max_estimates=3, timeout=120))
        self.assertEqual(len(estimates), 3)
        sequences = [e.sequence for e in estimates]
        self.assertEqual(sequences, sorted(sequences))
        self.assertEqual(len(set(sequences)), 3)
        poses = [best_pose(e) for e in estimates]
        found = [p for p in poses if p is not None]
        self.assertTrue(found, "no humanoid in %s" % estimates[0])
        # The simulated humanoid stands 1 m ahead of the sensor.
        for x, y, _ in found:
            self.assertAlmostEqual(x, 1.0, delta=0.1)
            self.assertAlmostEqual(y, 0.0, delta=0.1)

    def test_latest_after_sequence_waits_for_a_newer_one(self):
        first = self.client.latest(timeout=60)
        newer = self.client.latest(after_sequence=first.sequence, timeout=60)
        self.assertGreater(newer.sequence, first.sequence)

    def test_bad_request_is_invalid_argument_and_daemon_keeps_serving(self):
        with self.assertRaises(PoseClientError) as ctx:
            self.client.estimate_depth([0] * 10, 320, 240, 297.0, 295.0, 160.0, 120.0)
        self.assertEqual(ctx.exception.code, grpc.StatusCode.INVALID_ARGUMENT)
        self.assertIn("bytes", ctx.exception.details)
        with self.assertRaises(PoseClientError) as ctx:
            self.client.estimate_depth([0] * (4 * 4), 4, 4, float("nan"), 1.0, 2.0, 2.0)
        self.assertEqual(ctx.exception.code, grpc.StatusCode.INVALID_ARGUMENT)
        self.assertIn("fx", ctx.exception.details)
        self.assertEqual(self.client.status().templates, 2)

    def test_depth_given_every_way_gives_the_same_estimate_and_bad_values_are_named(self):
        import numpy as np
        # A level sensor 0.34 m above an empty floor, 80x60 pixels: rows below the centre see
        # the floor at z = h fy / (v - cy).
        w, h, fx, fy, cx, cy = 80, 60, 74.0, 74.0, 39.5, 29.5
        v = np.arange(h, dtype=np.float64)[:, None]
        metres = np.where(v > cy + 1, 0.34 * fy / np.maximum(v - cy, 1e-9), np.nan)
        metres = np.broadcast_to(metres, (h, w))
        metres = np.where(metres < 6.0, metres, np.nan)
        mm = np.where(np.isfinite(metres), np.rint(metres * 1000), 0).astype(np.uint16)
        k = dict(fx=fx, fy=fy, cx=cx, cy=cy)
        reference = self.client.estimate_depth(mm, **k).depth_template.floor
        self.assertAlmostEqual(reference.height, 0.34, delta=0.01)
        self.assertGreater(reference.inliers, 100)
        for name, depth, size in [
                ("rows", mm.tolist(), {}),
                ("flat list", mm.ravel().tolist(), dict(width=w, height=h)),
                ("flat bytes", mm.astype("<u2").tobytes(), dict(width=w, height=h)),
                ("float millimetres, NaN for no reading", metres * 1000, {})]:
            floor = self.client.estimate_depth(depth, **size, **k).depth_template.floor
            self.assertEqual(floor, reference, name)
        for depth, size, words in [
                (metres, {}, "metres"),
                (mm.astype(np.int32) - 60000, {}, "span"),
                (mm.astype(np.int32) * 100, {}, "span"),
                (mm > 0, {}, "boolean"),
                ([[1, 2], [3]], {}, "rows differ"),
                ([1, 2, -3, 4], dict(width=2, height=2), "-3"),
                ([1, 2, 3.5, 4], dict(width=2, height=2), "3.5")]:
            with self.assertRaises(ValueError) as ctx:
                self.client.estimate_depth(depth, **size, **k)
            self.assertIn(words, str(ctx.exception))

    def test_health_service_reports_serving(self):
        # grpc.health.v1.Health/Check with hand-encoded messages (field 1 = service name).
        check = self.client._channel.unary_unary("/grpc.health.v1.Health/Check")
        for service in (b"", b"hpose.v1.PoseService"):
            request = (b"\x0a" + bytes([len(service)]) + service) if service else b""
            response = check(request, timeout=10)
            self.assertEqual(response, b"\x08\x01", service)  # status = SERVING.
        with self.assertRaises(grpc.RpcError) as ctx:
            check(b"\x0a\x07unknown", timeout=10)
        self.assertEqual(ctx.exception.code(), grpc.StatusCode.NOT_FOUND)

    def test_reflection_lists_the_services(self):
        info = self.client._channel.stream_stream(
            "/grpc.reflection.v1alpha.ServerReflection/ServerReflectionInfo")
        # list_services (field 7) and file_containing_symbol (field 4).
        symbol = b"hpose.v1.PoseService"
        requests = [b"\x3a\x01*", b"\x22" + bytes([len(symbol)]) + symbol]
        responses = list(info(iter(requests), timeout=10))
        self.assertEqual(len(responses), 2)
        self.assertIn(b"hpose.v1.PoseService", responses[0])
        self.assertIn(b"grpc.health.v1.Health", responses[0])
        self.assertIn(b"hpose/v1/pose_service.proto", responses[1])
        self.assertIn(b"StreamPoses", responses[1])

    def test_example_program(self):
        example = os.path.join(SOURCE_DIR, "python", "example.py")
        out = subprocess.run([sys.executable, example, "--server", self.address, "--count", "2"],
                             capture_output=True, text=True, timeout=300, check=False)
        self.assertEqual(out.returncode, 0, out.stderr)
        self.assertIn("received 2 estimate(s)", out.stdout)
        self.assertIn("template standing", out.stdout)

    def test_zz_sigterm_shuts_down_cleanly(self):
        self.proc.send_signal(signal.SIGTERM)
        rest, _ = self.proc.communicate(timeout=30)
        self.assertEqual(self.proc.returncode, 0, rest)
        self.assertIn("stopped", rest)


class PythonFinishedRecordingTest(daemon_process.DaemonTestCase):
    """A recording played once to its end: streams end, waiting for a newer estimate fails."""

    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory()
        frames = os.path.join(cls.tmp.name, "frames")
        daemon_process.simulate_frames(HPOSE, frames, 2)
        cls.proc, cls.address = start_daemon([
            "--source", frames, "--rate", "fast",
            "--template", os.path.join(SOURCE_DIR, "templates", "standing.bt")])

    def test_stream_ends_and_no_newer_estimate_will_come(self):
        with PoseClient(self.address) as client:
            client.wait_ready(timeout=20)
            deadline = time.monotonic() + 120
            while time.monotonic() < deadline:  # finished, and both frames' estimates out.
                source = client.status().source
                if (source.state == pb.SOURCE_STATE_FINISHED
                        and source.frames_estimated + source.frames_failed == 2):
                    break
                time.sleep(0.1)
            last = client.latest(timeout=60)
            self.assertEqual(last.sequence, 2)
            # Ends by itself (a deadline would raise DEADLINE_EXCEEDED).
            self.assertEqual(list(client.stream(timeout=60)), [])
            with self.assertRaises(PoseClientError) as ctx:
                client.latest(after_sequence=last.sequence, timeout=60)
            self.assertEqual(ctx.exception.code, grpc.StatusCode.OUT_OF_RANGE)
            self.assertIn("finished", str(ctx.exception))


READ_TOKEN = "python-read-token-0123456789"
ESTIMATE_TOKEN = "python-estimate-token-0123456789"


class PythonSecureClientTest(daemon_process.DaemonTestCase):
    """TLS and bearer tokens through the Python client (certificates made with openssl)."""

    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory()
        d = cls.tmp.name
        with open(os.path.join(d, "server.ext"), "w", encoding="utf-8") as f:
            f.write("subjectAltName=IP:127.0.0.1,DNS:localhost\n")
        for cmd in (
                ["req", "-x509", "-newkey", "rsa:2048", "-nodes", "-days", "2", "-subj", "/CN=ca",
                 "-keyout", "ca.key", "-out", "ca.pem"],
                ["req", "-newkey", "rsa:2048", "-nodes", "-subj", "/CN=localhost", "-keyout",
                 "server.key", "-out", "server.csr"],
                ["x509", "-req", "-in", "server.csr", "-CA", "ca.pem", "-CAkey", "ca.key",
                 "-CAcreateserial", "-days", "2", "-extfile", "server.ext", "-out",
                 "server.pem"]):
            subprocess.run(["openssl"] + cmd, cwd=d, check=True, stdout=subprocess.DEVNULL,
                           stderr=subprocess.DEVNULL)
        with open(os.path.join(d, "tokens"), "w", encoding="utf-8") as f:
            f.write(f"{READ_TOKEN} read\n{ESTIMATE_TOKEN} estimate\n")
        with open(os.path.join(d, "my_token"), "w", encoding="utf-8") as f:
            f.write(READ_TOKEN + "\n")
        cls.proc, cls.address = start_daemon([
            "--template", os.path.join(SOURCE_DIR, "templates", "standing.bt"),
            "--tls-cert", os.path.join(d, "server.pem"), "--tls-key", os.path.join(d, "server.key"),
            "--token-file", os.path.join(d, "tokens")])
        cls.ca = os.path.join(d, "ca.pem")

    def test_tokens_and_roles(self):
        with PoseClient(self.address, tls_ca=self.ca) as client:
            client.wait_ready(timeout=20)
            with self.assertRaises(PoseClientError) as ctx:
                client.status()
            self.assertEqual(ctx.exception.code, grpc.StatusCode.UNAUTHENTICATED)
        with PoseClient(self.address, tls_ca=self.ca,
                        token_file=os.path.join(self.tmp.name, "my_token")) as client:
            self.assertEqual(client.status().templates, 1)
            with self.assertRaises(PoseClientError) as ctx:
                client.estimate_cloud([(0.0, 0.3, 1.0)] * 10)
            self.assertEqual(ctx.exception.code, grpc.StatusCode.PERMISSION_DENIED)
            try:  # streams carry the token too (no source here: no estimates to stream).
                list(client.stream(max_estimates=1, timeout=3))
            except PoseClientError as e:
                self.assertNotIn(e.code, (grpc.StatusCode.UNAUTHENTICATED,
                                          grpc.StatusCode.PERMISSION_DENIED))
        with PoseClient(self.address, tls_ca=self.ca, token=ESTIMATE_TOKEN) as client:
            with self.assertRaises(PoseClientError) as ctx:
                client.estimate_cloud([(0.0, 0.3, 1.0)] * 10)
            # Past authorization: the tiny cloud itself is what fails.
            self.assertNotIn(ctx.exception.code, (grpc.StatusCode.UNAUTHENTICATED,
                                                  grpc.StatusCode.PERMISSION_DENIED))

    def test_plaintext_client_fails(self):
        with PoseClient(self.address, token=READ_TOKEN) as client:
            with self.assertRaises(PoseClientError) as ctx:
                client.status(timeout=5)
            self.assertEqual(ctx.exception.code, grpc.StatusCode.UNAVAILABLE)


if __name__ == "__main__":
    unittest.main(argv=[sys.argv[0]], verbosity=2)
