#!/usr/bin/env python3
"""The Python client against hposed running both estimators: a simulated stereo sequence beside
simulated depth frames, with the depth sensor placed in the world frame.

usage: python_stereo_client_test.py HPOSED HPOSE   (PYTHONPATH: <build>/python and python/)
"""

import csv
import math
import os
import subprocess
import sys
import tempfile
import unittest

import grpc

import daemon_process
from png_rgb import read_png_rgb
from hpose_client import PoseClient, PoseClientError, estimator_name, world_pose
from hpose_client.client import describe

HPOSED, HPOSE = sys.argv[1:3]

# The depth sensor 2 m behind the stereo robot's start, looking along world +y: the simulated
# humanoid 1 m ahead of the depth sensor then stands where the stereo simulator puts the robot,
# (0.05, -1.0) facing +y.
WORLD_FROM_GROUND = (0.05, -2.0, math.pi / 2)


def start_daemon(args, timeout=60.0):
    """Starts hposed on a free loopback port; returns (process, address)."""
    return daemon_process.start_daemon(HPOSED, args, timeout)


def angle_diff(a, b):
    return math.atan2(math.sin(a - b), math.cos(a - b))


class PythonStereoClientTest(daemon_process.DaemonTestCase):

    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory()
        cls.stereo = os.path.join(cls.tmp.name, "stereo")
        cls.depth = os.path.join(cls.tmp.name, "depth")
        subprocess.run([HPOSE, "simulate", "stereo", "--out", cls.stereo, "--frames", "20"],
                       check=True, stdout=subprocess.DEVNULL)
        daemon_process.simulate_frames(HPOSE, cls.depth, 2)
        with open(os.path.join(cls.stereo, "ground_truth.csv")) as f:
            cls.truth = list(csv.DictReader(f))
        cls.proc, cls.address = start_daemon([
            "--source", cls.depth, "--fps", "5", "--stereo-source", cls.stereo, "--loop",
            "--world-from-ground", "%r,%r,%r" % WORLD_FROM_GROUND])
        cls.client = PoseClient(cls.address)
        cls.client.wait_ready(timeout=20)

    @classmethod
    def tearDownClass(cls):
        cls.client.close()
        super().tearDownClass()

    def assert_near_truth(self, estimate):
        """The stereo estimate's robot pose against the simulator's head pose of that pair."""
        index = (estimate.sequence - 1) % len(self.truth)
        row = self.truth[index]
        pose = world_pose(estimate)
        self.assertIsNotNone(pose, describe(estimate))
        self.assertAlmostEqual(pose[0], float(row["head_x_m"]), delta=0.05)
        self.assertAlmostEqual(pose[1], float(row["head_y_m"]), delta=0.05)
        self.assertLess(abs(angle_diff(pose[2], float(row["head_theta_rad"]))), math.radians(5))
        self.assertAlmostEqual(estimate.source_time, float(row["timestamp_s"]), delta=1e-6)

    def test_latest_stereo_is_marked_and_near_the_truth(self):
        first = self.client.latest(estimator="stereo", timeout=30)
        estimate = self.client.latest(estimator="stereo", after_sequence=first.sequence,
                                      timeout=30)
        self.assertEqual(estimator_name(estimate), "stereo")
        self.assertTrue(estimate.HasField("stereo_marker"))
        self.assertEqual(estimate.stereo_marker.status, "ok")
        self.assertTrue(estimate.stereo_marker.robot_found)
        self.assert_near_truth(estimate)
        self.assertIn("robot world", describe(estimate))

    def test_stream_carries_both_estimators_in_the_world_frame(self):
        seen = {}
        for estimate in self.client.stream(timeout=120):
            seen.setdefault(estimator_name(estimate), []).append(estimate)
            if "depth" in seen and len(seen.get("stereo", [])) >= 3:
                break
        self.assertIn("depth", seen)
        self.assertGreaterEqual(len(seen["stereo"]), 3)
        for estimate in seen["stereo"]:
            self.assert_near_truth(estimate)
        depth = seen["depth"][0]
        self.assertTrue(depth.HasField("depth_template"))
        pose = world_pose(depth)
        self.assertIsNotNone(pose, describe(depth))
        # Simulated humanoid 1 m ahead of the depth sensor, facing away (theta 0): in the world
        # frame (0.05, -1.0) facing +y.
        self.assertAlmostEqual(pose[0], 0.05, delta=0.1)
        self.assertAlmostEqual(pose[1], -1.0, delta=0.1)
        self.assertLess(abs(angle_diff(pose[2], math.pi / 2)), math.radians(12))

    def test_stream_of_one_estimator(self):
        kinds = {estimator_name(e) for e in
                 self.client.stream(max_estimates=4, timeout=60, estimators=["stereo"])}
        self.assertEqual(kinds, {"stereo"})
        with self.assertRaises(ValueError):
            list(self.client.stream(max_estimates=1, estimators=["sonar"]))

    def test_estimate_stereo_pair(self):
        width, height, left = read_png_rgb(os.path.join(self.stereo, "left", "000004.png"))
        _, _, right = read_png_rgb(os.path.join(self.stereo, "right", "000004.png"))
        estimate = self.client.estimate_stereo(left, right, width, height, source_time=1.5)
        self.assertEqual(estimator_name(estimate), "stereo")
        self.assertEqual(estimate.source, "request")
        self.assertAlmostEqual(estimate.source_time, 1.5)
        row = self.truth[4]
        pose = world_pose(estimate)
        self.assertIsNotNone(pose, describe(estimate))
        self.assertAlmostEqual(pose[0], float(row["head_x_m"]), delta=0.05)
        self.assertAlmostEqual(pose[1], float(row["head_y_m"]), delta=0.05)
        # A blank pair: processed, but no landmark, so no pose.
        blank = bytes(width * height * 3)
        estimate = self.client.estimate_stereo(blank, blank, width, height)
        self.assertIsNone(world_pose(estimate))
        self.assertEqual(estimate.stereo_marker.status, "missing_landmark")
        # Images of different sizes are refused with the reason.
        with self.assertRaises(PoseClientError) as ctx:
            self.client._call(self.client._stub.EstimateStereo, self._pair(left, width, height),
                              10)
        self.assertEqual(ctx.exception.code, grpc.StatusCode.INVALID_ARGUMENT)
        self.assertIn("right image", ctx.exception.details)

    @staticmethod
    def _pair(left, width, height):
        from hpose.v1 import pose_service_pb2 as pb
        half = bytes((width // 2) * (height // 2) * 3)
        return pb.EstimateStereoRequest(
            left=pb.ColorImage(width=width, height=height, data=left),
            right=pb.ColorImage(width=width // 2, height=height // 2, data=half))

    def test_status_reports_both_sources_and_the_world_frame(self):
        status = self.client.status()
        self.assertEqual(status.source.kind, "png-dir")
        self.assertEqual(status.stereo_source.kind, "stereo-dir")
        self.assertTrue(status.stereo_calibrated)
        self.assertTrue(status.HasField("world_from_ground"))
        self.assertAlmostEqual(status.world_from_ground.y, -2.0)
        self.assertAlmostEqual(status.world_from_ground.theta, math.pi / 2, places=9)


if __name__ == "__main__":
    if os.environ.get("HPOSE_SANITIZED_BUILD"):
        print("skipped: renders stereo sequences, which take minutes under the sanitizers; "
              "it runs in the Release suite")
        sys.exit(77)
    unittest.main(argv=[sys.argv[0]], verbosity=2)
