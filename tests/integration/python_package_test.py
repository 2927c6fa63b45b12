#!/usr/bin/env python3
"""Installs the Python client with pip from the repository into a fresh venv (system site
packages for Debian's grpcio/protobuf/numpy, no package index) and uses the installed package
against a running hposed: a 2-D numpy depth frame and the same frame as a flat list give the
same estimate, whose floor is the one the frame was built from.

usage: python_package_test.py HPOSED HPOSE SOURCE_DIR
"""

import os
import shutil
import subprocess
import sys
import tempfile
import textwrap
import unittest

HPOSED, HPOSE, SOURCE_DIR = sys.argv[1:4]
HERE = os.path.dirname(os.path.abspath(__file__))

# Runs inside the venv: the client must come from the installed package, not the repository.
CLIENT_SCRIPT = textwrap.dedent("""
    import math, sys
    import numpy as np
    sys.path.insert(0, sys.argv[2])  # the tests' daemon launcher only
    import daemon_process
    import hpose_client
    from hpose_client import PoseClient
    from hpose.v1 import pose_service_pb2 as pb
    assert "site-packages" in hpose_client.__file__, hpose_client.__file__
    print("client from", hpose_client.__file__)

    # A floor seen by a 320x240 camera 0.8 m above it, pitched 30 degrees down.
    w, h, f, cx, cy = 320, 240, 285.0, 160.0, 120.0
    height, pitch = 0.8, math.radians(30)
    u, v = np.meshgrid(np.arange(w), np.arange(h))
    up_dot = -math.cos(pitch) * (v - cy) / f - math.sin(pitch)  # up . ray (ray z = 1)
    with np.errstate(divide="ignore"):
        z = np.where(up_dot < -1e-3, -height / up_dot, 0.0)
    depth = np.where((z > 0.5) & (z < 4.0), z * 1000.0, 0).astype(np.uint16)

    proc, address = daemon_process.start_daemon(sys.argv[1], [])
    try:
        with PoseClient(address) as client:
            client.wait_ready(timeout=20)
            a = client.estimate_depth(depth, fx=f, fy=f, cx=cx, cy=cy, timeout=60)
            b = client.estimate_depth(depth.ravel().tolist(), w, h, f, f, cx, cy, timeout=60)
            try:
                client.estimate_depth(depth[None], fx=f, fy=f, cx=cx, cy=cy)
                raise SystemExit("a 3-D array was accepted")
            except ValueError as e:
                print("3-D array refused:", e)
    finally:
        proc.terminate()
        proc.wait()
    fa, fb = a.depth_template.floor, b.depth_template.floor
    print("floor height %.4f m, pitch %.2f deg" % (fa.height, math.degrees(fa.pitch)))
    assert a.estimator == pb.ESTIMATOR_KIND_DEPTH_TEMPLATE
    assert abs(fa.height - height) < 0.02, fa.height
    assert abs(fa.pitch - pitch) < math.radians(1.5), fa.pitch
    assert fa.height == fb.height and fa.pitch == fb.pitch
    print("ok")
""")


class PythonPackageTest(unittest.TestCase):

    def test_pip_install_and_use(self):
        with tempfile.TemporaryDirectory() as tmp:
            # Build from a copy: pip and setuptools write build files next to the sources.
            src = os.path.join(tmp, "src")
            shutil.copytree(os.path.join(SOURCE_DIR, "python"), src,
                            ignore=shutil.ignore_patterns("__pycache__", "*.egg-info", "build"))
            venv = os.path.join(tmp, "venv")
            subprocess.run([sys.executable, "-m", "venv", "--system-site-packages", venv],
                           check=True)
            py = os.path.join(venv, "bin", "python")
            env = dict(os.environ)
            env.pop("PYTHONPATH", None)
            env["PIP_NO_INDEX"] = "1"  # Debian's packages only: no package index is reachable.
            pip = subprocess.run([py, "-m", "pip", "install", "--no-build-isolation",
                                  "--disable-pip-version-check", src],
                                 env=env, capture_output=True, text=True)
            self.assertEqual(pip.returncode, 0, pip.stdout + pip.stderr)
            script = os.path.join(tmp, "use_client.py")
            with open(script, "w") as f:
                f.write(CLIENT_SCRIPT)
            run = subprocess.run([py, script, HPOSED, HERE], env=env, cwd=tmp,
                                 capture_output=True, text=True, timeout=300)
            print(run.stdout, run.stderr)
            self.assertEqual(run.returncode, 0, run.stdout + run.stderr)
            self.assertIn("ok", run.stdout.splitlines()[-1])


if __name__ == "__main__":
    unittest.main(argv=sys.argv[:1], verbosity=2)
