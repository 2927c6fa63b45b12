#!/usr/bin/env python3
"""The installed programs, run from an installation prefix (made by the install_tree test).

usage: install_run_test.py PREFIX
Checks the installed layout, that hpose and hposed start and explain themselves, that they find
the installed templates by themselves (no flag, no HPOSE_TEMPLATE_DIR), and that an estimate
made there finds the simulated humanoid.
"""

import json
import os
import subprocess
import sys
import tempfile
import unittest

PREFIX = os.path.abspath(sys.argv[1])
HPOSE = os.path.join(PREFIX, "bin", "hpose")
HPOSED = os.path.join(PREFIX, "bin", "hposed")
TEMPLATES = os.path.join(PREFIX, "share", "hpose", "templates")


def run(args, cwd=None):
    """Runs an installed program without HPOSE_TEMPLATE_DIR; returns (status, stdout, stderr)."""
    env = dict(os.environ)
    env.pop("HPOSE_TEMPLATE_DIR", None)
    p = subprocess.run(args, cwd=cwd, env=env, capture_output=True, text=True, timeout=300)
    return p.returncode, p.stdout, p.stderr


class InstalledProgramsTest(unittest.TestCase):

    def test_layout(self):
        for rel in ["bin/hpose", "bin/hposed", "share/hpose/templates/standing.bt",
                    "share/hpose/templates/standing.json",
                    "share/hpose/templates/right_arm_raised.bt",
                    "share/hpose/templates/right_arm_raised.json",
                    "share/hpose/templates/arms_swung.bt", "etc/hpose/hposed.yaml",
                    "lib/systemd/system/hposed.service", "include/hpose/client.h",
                    "libexec/hpose/hpose-estimate", "libexec/hpose/hpose-drawing.so"]:
            self.assertTrue(os.path.isfile(os.path.join(PREFIX, rel)), rel + " not installed")
        configs = [f for _, _, files in os.walk(PREFIX) for f in files
                   if f == "hposeConfig.cmake"]
        self.assertEqual(configs, ["hposeConfig.cmake"])

    def test_help(self):
        for program, usage in [(HPOSE, "usage: hpose"), (HPOSED, "usage: hposed")]:
            status, out, err = run([program, "--help"])
            self.assertEqual(status, 0, err)
            self.assertIn(usage, out + err)

    def test_unit_runs_the_installed_daemon_with_the_installed_config(self):
        with open(os.path.join(PREFIX, "lib/systemd/system/hposed.service")) as f:
            unit = f.read()
        self.assertIn("ExecStart=%s --config %s" % (
            HPOSED, os.path.join(PREFIX, "etc/hpose/hposed.yaml")), unit)
        self.assertIn("Restart=on-failure", unit)
        self.assertIn("DynamicUser=yes", unit)

    def test_daemon_finds_the_installed_templates(self):
        # The installed configuration names the shipped templates; they resolve to the prefix.
        with tempfile.TemporaryDirectory() as cwd:
            status, out, err = run([HPOSED, "--config",
                                    os.path.join(PREFIX, "etc/hpose/hposed.yaml"),
                                    "--print-config"], cwd=cwd)
        self.assertEqual(status, 0, err)
        self.assertIn("  - %s/standing.bt\n" % TEMPLATES, out)
        self.assertIn("  - %s/right_arm_raised.bt\n" % TEMPLATES, out)

    def test_estimate_with_the_installed_templates(self):
        with tempfile.TemporaryDirectory() as cwd:
            status, _, err = run([HPOSE, "simulate", "--out", "frames", "--frames", "1",
                                  "--width", "320", "--height", "240", "--no-cloud"], cwd=cwd)
            self.assertEqual(status, 0, err)
            status, out, err = run([HPOSE, "estimate", "--depth", "frames/depth.png",
                                    "--intrinsics", "frames/intrinsics.json", "--json",
                                    "--picture", "match.png"], cwd=cwd)
            # The picture is drawn by the installed drawing module, beside the programs.
            picture = os.path.join(cwd, "match.png")
            self.assertTrue(os.path.isfile(picture) and os.path.getsize(picture) > 1000, err)
        self.assertEqual(status, 0, err)
        result = json.loads(out)["depth_template"]
        self.assertTrue(result["humanoid_found"])
        best = result["best"]["best"]
        self.assertIn(best["template_name"], ["standing", "right_arm_raised"])
        self.assertAlmostEqual(best["pose"]["x"], 1.0, delta=0.1)  # simulated 1 m ahead.
        self.assertAlmostEqual(best["pose"]["y"], 0.0, delta=0.1)


if __name__ == "__main__":
    unittest.main(argv=sys.argv[:1], verbosity=2)
