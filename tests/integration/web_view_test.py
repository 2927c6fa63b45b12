#!/usr/bin/env python3
"""hposed's web view in a real browser (headless Chromium through Selenium).

A simulated recording of a humanoid turning is served by hposed with --http; the page must show
the pose GetLatest answers (within the page's display rounding), show it change as the robot
turns, log no console errors, agree field by field with the gRPC answer in its JSON, and show
the daemon as disconnected once it stops.

usage: web_view_test.py HPOSED HPOSE SOURCE_DIR [--screenshot PNG]
"""

import json
import math
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time
import unittest
import urllib.request

from daemon_process import start_daemon_with_http

HPOSED, HPOSE, SOURCE_DIR = sys.argv[1:4]
SCREENSHOT = sys.argv[sys.argv.index("--screenshot") + 1] if "--screenshot" in sys.argv else None

try:
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service
    HAVE_SELENIUM = True
except ImportError:
    HAVE_SELENIUM = False

CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
CHROMEDRIVER = shutil.which("chromedriver")

# The delivery stamps of a message (when it was handed to the transport, and the age then) are
# the only fields two reads of the same estimate may disagree on.
DELIVERY_FIELDS = {"send_time", "age"}


def get_json(url):
    """The JSON body of a GET."""
    with urllib.request.urlopen(url, timeout=10) as reply:
        return json.loads(reply.read().decode())


def grpc_latest(address):
    """GetLatest through the command-line client (the same JSON schema as the web view's)."""
    out = subprocess.run([HPOSE, "query", "--server", address, "latest", "--json"], check=True,
                         capture_output=True, text=True).stdout
    return json.loads(out.strip().splitlines()[-1])


def differences(a, b, path=""):
    """Paths where two JSON values differ (delivery stamps excluded)."""
    if isinstance(a, dict) and isinstance(b, dict):
        out = []
        for key in sorted(set(a) | set(b)):
            if key in DELIVERY_FIELDS and not path:
                continue
            if key not in a or key not in b:
                out.append(path + "/" + key + " (missing on one side)")
            else:
                out += differences(a[key], b[key], path + "/" + key)
        return out
    if isinstance(a, list) and isinstance(b, list):
        if len(a) != len(b):
            return [path + " (lengths %d, %d)" % (len(a), len(b))]
        return sum((differences(x, y, "%s[%d]" % (path, i)) for i, (x, y) in
                    enumerate(zip(a, b))), [])
    return [] if a == b else ["%s (%r != %r)" % (path, a, b)]


@unittest.skipUnless(HAVE_SELENIUM and CHROMIUM and CHROMEDRIVER,
                     "needs python3-selenium, chromium and chromium-driver (make deps)")
class WebViewTest(unittest.TestCase):

    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        frames = os.path.join(self.tmp.name, "frames")
        # A humanoid walking a curve (4 cm and 12 degrees a frame) among clutter, replayed once at
        # 1 Hz. A tracked frame confirms the previous heading when its pose faces within 15 degrees
        # of it (EstimatorOptions::tracked_heading_confirm_rad): most frames of this walk do (at
        # 15 degrees a frame, few did).
        subprocess.run([HPOSE, "simulate", "--out", frames, "--frames", "12", "--width", "320",
                        "--height", "240", "--no-cloud", "--turn-deg", "12", "--step-m", "0.04",
                        "--clutter", "2"],
                       check=True, stdout=subprocess.DEVNULL)
        options = webdriver.ChromeOptions()
        options.binary_location = CHROMIUM
        for arg in ("--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage",
                    "--window-size=1200,860"):
            options.add_argument(arg)
        options.set_capability("goog:loggingPrefs", {"browser": "ALL"})
        # The browser first: it can take seconds to start on a busy machine, and the page must
        # see the recording play.
        self.driver = webdriver.Chrome(service=Service(CHROMEDRIVER), options=options)
        self.frames = frames
        self.proc = None

    def start_daemon(self, *args):
        """hposed serving the recording with the shipped templates; `args` are further flags."""
        templates = os.path.join(SOURCE_DIR, "templates")
        self.proc, self.grpc, self.http = start_daemon_with_http(HPOSED, [
            "--source", self.frames,
            "--template", os.path.join(templates, "standing.bt"),
            "--template", os.path.join(templates, "right_arm_raised.bt")] + list(args))

    def tearDown(self):
        self.driver.quit()
        if self.proc is not None and self.proc.poll() is None:
            self.proc.kill()
            self.proc.wait()
        self.tmp.cleanup()

    def text(self, element_id):
        return self.driver.find_element("id", element_id).text

    def wait_for(self, what, predicate, timeout):
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            if predicate():
                return
            time.sleep(0.2)
        self.fail("timed out waiting for %s; page shows connection '%s', message '%s'" %
                  (what, self.text("conn"), self.text("message")))

    def displayed_pose(self):
        """(sequence, x m, y m, theta deg) as the page shows them, or None."""
        try:
            return (int(self.text("sequence")), float(self.text("pose-x")),
                    float(self.text("pose-y")), float(self.text("pose-theta")))
        except ValueError:
            return None

    def wait_until_settled(self):
        """Until the recording finished and every frame read was published or dropped: under the
        sanitizers the last frames are still being estimated when the source reports FINISHED,
        and the latest estimate then changes while the page is read."""
        def settled():
            if get_json(self.http + "/api/status")["source"]["state"] != "SOURCE_STATE_FINISHED":
                return False
            with urllib.request.urlopen(self.http + "/metrics", timeout=10) as reply:
                text = reply.read().decode()
            count = {}
            for name in ("received", "estimated", "dropped", "failed"):
                found = re.search(r'^hposed_frames_%s_total\{source="depth"\} (\d+)$' % name,
                                  text, re.MULTILINE)
                count[name] = int(found.group(1)) if found else -1
            return count["received"] == 12 and (
                count["estimated"] + count["dropped"] + count["failed"] >= count["received"])
        self.wait_for("every frame read to be estimated or dropped", settled, 120)

    def test_live_view(self):
        self.start_daemon("--fps", "1")
        self.driver.get(self.http + "/")
        self.wait_for("the page to connect", lambda: self.text("conn") == "live", 60)

        # While the recording plays, the displayed heading follows the turning robot.
        thetas = set()
        margins = set()  # what the page said of the runner-up heading, frame by frame.
        template_margins = set()  # ... and of the second template.
        screenshot_taken = False
        deadline = time.monotonic() + 240
        while time.monotonic() < deadline:
            pose = self.displayed_pose()
            if pose is not None:
                thetas.add(pose[3])
                margins.add(self.text("margin"))
                template_margins.add(self.text("template-margin"))
            if SCREENSHOT and not screenshot_taken and len(thetas) >= 8:  # a trail to show.
                time.sleep(0.5)
                self.driver.save_screenshot(SCREENSHOT)
                screenshot_taken = True
            state = get_json(self.http + "/api/status")["source"]["state"]
            if state == "SOURCE_STATE_FINISHED":
                break
            time.sleep(0.2)
        self.assertEqual(get_json(self.http + "/api/status")["source"]["state"],
                         "SOURCE_STATE_FINISHED")
        self.assertGreaterEqual(len(thetas), 2, "the heading shown never changed: %s" % thetas)
        self.assertGreater(max(thetas) - min(thetas), 20.0, sorted(thetas))
        # The first frame, cold, searched a runner-up and shows its margin (a number); tracked
        # frames that confirmed the previous heading say so instead.
        self.assertIn("previous heading confirmed", margins)
        self.assertTrue(any(re.match(r"^-?\d+\.\d", m) for m in margins), sorted(margins))
        # The second template's margin in fit points where both were refined, in score points,
        # at least, where a tracked frame stopped its search far behind (this walk's second to
        # fourth frames, at 4-7 points).
        self.assertTrue(any(re.match(r"^at least -?\d+\.\d score points over ", m)
                            for m in template_margins), sorted(template_margins))
        self.assertTrue(any(re.match(r"^-?\d+\.\d over ", m) for m in template_margins),
                        sorted(template_margins))

        self.wait_until_settled()

        # Finished: the last estimate stays; page, web JSON and GetLatest must agree on it.
        latest = grpc_latest(self.grpc)
        best = latest["depth_template"]["best"]["best"]
        self.wait_for("the page to show the last frame",
                      lambda: (self.displayed_pose() or (0,))[0] == latest["sequence"], 10)
        sequence, x, y, theta = self.displayed_pose()
        self.assertTrue(latest["depth_template"]["humanoid_found"])
        self.assertAlmostEqual(x, best["pose"]["x"], delta=0.0005 + 1e-9)
        self.assertAlmostEqual(y, best["pose"]["y"], delta=0.0005 + 1e-9)
        self.assertAlmostEqual(theta, math.degrees(best["pose"]["theta"]), delta=0.05 + 1e-9)
        self.assertEqual(self.text("template"), best["template_name"])
        self.assertEqual(self.text("score"), "%.1f" % best["score"])
        self.assertEqual(self.text("found"), "yes")
        in_view = best["fit"].get("in_view")
        partly = (" (%d%% in view)" % math.floor(100 * in_view + 0.5)
                  if in_view is not None and in_view < 0.9 else "")
        self.assertEqual(self.text("fit"), "%.1f" % best["fit"]["fit"] + partly)
        # A tracked frame that confirmed the previous heading searched no runner-up.
        if best.get("heading_confirmed"):
            self.assertFalse(best.get("has_runner_up"))
            self.assertEqual(self.text("margin"), "previous heading confirmed")
        elif best.get("has_runner_up"):
            self.assertTrue(self.text("margin").startswith("%.1f" % best["runner_up_margin"]),
                            self.text("margin"))
        # The margin over the second template: in fit points where both templates were refined,
        # in score points where the tracked frame left the second unrefined, at least that many
        # where its search stopped (Detection.template_margin_kind).
        detection = latest["depth_template"]["best"]
        if detection.get("second_template"):
            second = [c for c in latest["depth_template"].get("candidates", [])
                      if c.get("cluster_index", 0) == best.get("cluster_index", 0) and
                      c.get("template_name") == detection["second_template"]]
            self.assertTrue(second, "no candidate of the second template on the best's cluster")
            kind = detection["template_margin_kind"]
            expected = ("TEMPLATE_MARGIN_FIT" if best.get("refined") and second[0].get("refined")
                        else "TEMPLATE_MARGIN_SCORE_AT_LEAST"
                        if second[0].get("stopped_below_threshold")
                        else "TEMPLATE_MARGIN_SCORE")
            self.assertEqual(kind, expected, detection)
            shown = self.text("template-margin")
            at_least = kind == "TEMPLATE_MARGIN_SCORE_AT_LEAST"
            self.assertTrue(shown.startswith(("at least " if at_least else "") +
                                             "%.1f" % detection["template_margin"]), shown)
            self.assertEqual("score points" in shown, kind != "TEMPLATE_MARGIN_FIT", shown)
            self.assertTrue(shown.endswith(detection["second_template"]) or "(ambiguous)" in shown,
                            shown)
        web = get_json(self.http + "/api/latest")["estimate"]
        self.assertEqual(differences(web, latest), [])
        # The recording's camera, as GetStatus gives it (the directory's intrinsics.json).
        with open(os.path.join(self.frames, "intrinsics.json")) as f:
            k = json.load(f)
        camera = get_json(self.http + "/api/status")["source"]["camera"]
        for name in ("width", "height", "fx", "fy", "cx", "cy"):
            self.assertAlmostEqual(camera[name], k[name], delta=1e-9, msg=name)
        self.assertEqual(self.text("camera"), "%d×%d, fx %.1f fy %.1f cx %.1f cy %.1f" % (
            k["width"], k["height"], k["fx"], k["fy"], k["cx"], k["cy"]))
        # No stereo source: its rows say so rather than showing blanks.
        self.assertEqual(self.text("stereo-source-state"), "not configured")
        self.assertEqual(self.text("stereo-camera"), "–")
        self.assertEqual(self.text("stereo-rate"), "–")

        # Metrics moved with the frames.
        with urllib.request.urlopen(self.http + "/metrics", timeout=10) as reply:
            metrics = reply.read().decode()
        # Every frame was read; a busy machine may drop some unestimated (a newer one came).
        self.assertIn('hposed_frames_received_total{source="depth"} 12', metrics)
        estimated = re.search(r'^hposed_frames_estimated_total\{source="depth"\} (\d+)$',
                              metrics, re.MULTILINE)
        self.assertGreaterEqual(int(estimated.group(1)), len(thetas))
        self.assertIn('hposed_clients_connected{kind="http_events"} 1', metrics)

        # No errors in the page's console while the daemon served it.
        errors = [e for e in self.driver.get_log("browser") if e["level"] == "SEVERE"]
        self.assertEqual(errors, [])

        # A stopped daemon is shown as disconnected.
        self.proc.send_signal(signal.SIGINT)
        self.proc.wait(timeout=30)
        self.wait_for("the page to show the daemon disconnected",
                      lambda: self.text("conn") == "disconnected", 15)

    def test_stereo_source_shown(self):
        # Beside the depth recording, a simulated stereo sequence (looped): the page's stereo rows
        # give its state, the size of its pairs with the calibration's left camera, and its rate,
        # as GetStatus does.
        stereo = os.path.join(self.tmp.name, "stereo")
        subprocess.run([HPOSE, "simulate-stereo", "--out", stereo, "--frames", "6"], check=True,
                       stdout=subprocess.DEVNULL)
        self.start_daemon("--fps", "5", "--stereo-source", stereo, "--loop")
        self.driver.get(self.http + "/")
        self.wait_for("the page to connect", lambda: self.text("conn") == "live", 60)
        self.wait_for("the page to show the stereo camera",
                      lambda: "pairs, left" in self.text("stereo-camera"), 60)
        status = get_json(self.http + "/api/status")["stereo_source"]
        self.assertEqual(status["state"], "SOURCE_STATE_RUNNING")
        self.assertEqual(self.text("stereo-source-state"), "running")
        cam = status["camera"]
        self.assertEqual(self.text("stereo-camera"),
                         "%d×%d pairs, left fx %.1f fy %.1f cx %.1f cy %.1f" % (
                             cam["width"], cam["height"], cam["fx"], cam["fy"], cam["cx"],
                             cam["cy"]))
        # The simulator's pairs and camera (hpose simulate-stereo: 512x240, a left camera with
        # its principal point inside the image).
        self.assertGreater(cam["fx"], 0.0)
        self.assertTrue(0.0 < cam["cx"] < cam["width"] and 0.0 < cam["cy"] < cam["height"], cam)
        self.wait_for("the stereo rate to be shown",
                      lambda: re.match(r"^\d+\.\d Hz$", self.text("stereo-rate")) is not None, 30)
        self.assertGreater(float(self.text("stereo-rate").split()[0]), 0.0)
        # The depth source's rows are its own (its camera once its first frame is read: under
        # the sanitizers the estimators warm up for seconds before the depth source opens).
        self.wait_for("the depth camera to be shown",
                      lambda: self.text("camera").startswith("320×240, fx "), 120)
        self.assertNotIn("pairs", self.text("camera"))
        errors = [e for e in self.driver.get_log("browser") if e["level"] == "SEVERE"]
        self.assertEqual(errors, [])

    def test_refusal_shown(self):
        # Asked for more evidence than one view of a robot holds (it sees under half of the
        # template), the robot is refused: the page must say why, with its fit, not a bare "no".
        config = os.path.join(self.tmp.name, "strict.yaml")
        with open(config, "w") as f:
            f.write("search:\n  min_humanoid_evidence: 0.9\n")
        self.start_daemon("--fps", "10", "--config", config)
        self.driver.get(self.http + "/")
        self.wait_for("the page to connect", lambda: self.text("conn") == "live", 60)
        self.wait_until_settled()
        latest = grpc_latest(self.grpc)
        self.assertFalse(latest["depth_template"].get("humanoid_found", False))
        detection = latest["depth_template"]["best"]
        self.assertEqual(detection["refused_by"], "REFUSAL_EVIDENCE")
        fit = "%.1f" % detection["best"]["fit"]["fit"]
        self.wait_for("the page to show the last frame",
                      lambda: self.text("sequence") == str(latest["sequence"]), 10)
        self.assertEqual(self.text("found"),
                         "no: fit %s, too little evidence: search.min_humanoid_evidence" % fit)
        self.assertEqual(self.text("fit"), fit)
        errors = [e for e in self.driver.get_log("browser") if e["level"] == "SEVERE"]
        self.assertEqual(errors, [])


if __name__ == "__main__":
    unittest.main(argv=sys.argv[:1], verbosity=2)
