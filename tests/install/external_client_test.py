#!/usr/bin/env python3
"""An external CMake project built against the installed package, querying the installed daemon.

usage: external_client_test.py PREFIX PROJECT_DIR CMAKE [CMAKE_ARG...]
PREFIX holds the installation (made by the install_tree test), PROJECT_DIR is
tests/external_client; CMAKE_ARGs are added to the configure command (a sanitizer build passes
its compiler and sanitizer link flags). The project is configured with find_package(hpose) through
CMAKE_PREFIX_PATH=PREFIX only, built, and run against PREFIX/bin/hposed serving a looped
simulated recording made by PREFIX/bin/hpose with the installed templates.
"""

import os
import subprocess
import sys
import tempfile
import unittest

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "integration"))
import daemon_process  # noqa: E402

PREFIX, PROJECT_DIR, CMAKE = (os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2]),
                              sys.argv[3])
EXTRA_CMAKE_ARGS = sys.argv[4:]


class ExternalClientTest(unittest.TestCase):

    def test_external_project_queries_the_daemon(self):
        env = dict(os.environ)
        env.pop("HPOSE_TEMPLATE_DIR", None)
        with tempfile.TemporaryDirectory() as tmp:
            build = os.path.join(tmp, "build")
            subprocess.run([CMAKE, "-S", PROJECT_DIR, "-B", build, "-DCMAKE_PREFIX_PATH=" + PREFIX,
                            "-DCMAKE_BUILD_TYPE=Release"] + EXTRA_CMAKE_ARGS, check=True, env=env)
            # The package came from the prefix, not from anywhere else on the machine.
            with open(os.path.join(build, "CMakeCache.txt")) as f:
                self.assertIn("hpose_DIR:PATH=%s/" % PREFIX, f.read())
            subprocess.run([CMAKE, "--build", build], check=True, env=env)
            frames = os.path.join(tmp, "frames")
            subprocess.run([os.path.join(PREFIX, "bin", "hpose"), "simulate", "--out", frames,
                            "--frames", "3", "--width", "320", "--height", "240",
                            "--turn-deg", "20"], check=True, stdout=subprocess.DEVNULL, env=env)
            # No --template: the daemon uses the installed templates.
            proc, address = daemon_process.start_daemon(
                os.path.join(PREFIX, "bin", "hposed"),
                ["--source", frames, "--loop", "--fps", "10"])
            try:
                run = subprocess.run([os.path.join(build, "hpose_external_client"), address,
                                      os.path.join(frames, "cloud_000.pcd")],
                                     capture_output=True, text=True, timeout=300)
                print(run.stdout, run.stderr)
                self.assertEqual(run.returncode, 0, run.stdout + run.stderr)
                self.assertIn("0 failure(s)", run.stdout)
            finally:
                proc.terminate()
                proc.wait(timeout=60)


if __name__ == "__main__":
    unittest.main(argv=sys.argv[:1], verbosity=2)
