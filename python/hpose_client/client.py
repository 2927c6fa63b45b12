"""A small, blocking client of hposed for robot controllers."""

import array
import math
import sys

import grpc

from hpose.v1 import pose_service_pb2 as pb
from hpose.v1 import pose_service_pb2_grpc as pb_grpc


class PoseClientError(RuntimeError):
    """A call failed; `code` is the grpc.StatusCode, `details` the daemon's reason."""

    def __init__(self, code, details):
        super().__init__("%s: %s" % (code.name, details))
        self.code = code
        self.details = details


# Estimator names accepted by PoseClient.latest() and PoseClient.stream().
ESTIMATORS = {
    "depth": pb.ESTIMATOR_KIND_DEPTH_TEMPLATE,
    "stereo": pb.ESTIMATOR_KIND_STEREO_MARKER,
}


def _estimator_kind(name):
    if name is None:
        return pb.ESTIMATOR_KIND_UNSPECIFIED
    if name not in ESTIMATORS:
        raise ValueError("estimator must be one of %s, got %r" % (sorted(ESTIMATORS), name))
    return ESTIMATORS[name]


# A float depth array whose largest value is below this is in metres, not millimetres.
_METRES_BELOW = 20.0
_DEPTH_RANGE = "whole millimetres in [0, 65535] (0: no reading)"


def _numpy():
    try:
        import numpy
        return numpy
    except ImportError:
        return None


def _array_depth_bytes(depth):
    """Little-endian uint16 bytes of a 2-D array of millimetres, its values checked."""
    np = _numpy()
    kind = getattr(getattr(depth, "dtype", None), "kind", None)
    if np is None or not isinstance(depth, np.ndarray) or kind not in "biuf":
        return depth.astype("<u2").tobytes()
    if kind == "b":
        raise ValueError("depth array is boolean; expected " + _DEPTH_RANGE)
    if kind == "f":
        finite = np.isfinite(depth)
        top = float(depth[finite].max()) if finite.any() else 0.0
        if 0.0 < top < _METRES_BELOW:
            raise ValueError("depth values are at most %g: metres? estimate_depth takes "
                             "millimetres (multiply by 1000)" % top)
        depth = np.where(finite, np.rint(depth), 0.0)
    if depth.size and (depth.min() < 0 or depth.max() > 65535):
        raise ValueError("depth values span %s..%s; expected %s"
                         % (depth.min(), depth.max(), _DEPTH_RANGE))
    return depth.astype("<u2").tobytes()


def _values_bytes(values):
    """Little-endian uint16 bytes of a flat sequence of millimetres."""
    try:
        packed = array.array("H", values)
    except (OverflowError, TypeError):
        bad = next((v for v in values
                    if not isinstance(v, int) or isinstance(v, bool) or not 0 <= v <= 65535),
                   None)
        raise ValueError("depth value %r is not %s" % (bad, _DEPTH_RANGE)) from None
    if sys.byteorder != "little":
        packed.byteswap()
    return packed.tobytes()


def _depth_bytes(depth, width, height):
    """(width, height, bytes) of a depth frame given as estimate_depth takes it."""
    shape = getattr(depth, "shape", None)
    rows = None
    if shape is None and isinstance(depth, (list, tuple)) and depth and \
            isinstance(depth[0], (list, tuple)):
        rows = depth  # a list of rows.
        shape = (len(rows), len(rows[0]))
        if any(len(r) != shape[1] for r in rows):
            raise ValueError("depth rows differ in length (the first has %d values)" % shape[1])
    if shape is not None and len(shape) == 2:
        h, w = int(shape[0]), int(shape[1])
        if (width is not None and width != w) or (height is not None and height != h):
            raise ValueError("depth array is %dx%d (width x height) but width=%s, height=%s"
                             % (w, h, width, height))
        if rows is not None:
            return w, h, _values_bytes([v for r in rows for v in r])
        return w, h, _array_depth_bytes(depth)
    if shape is not None and len(shape) != 1:
        raise ValueError("depth array must be 2-D (height, width) or flat, got shape %s"
                         % (tuple(shape),))
    if width is None or height is None:
        raise ValueError("width and height are required with a flat depth sequence")
    if isinstance(depth, (bytes, bytearray)):
        return width, height, bytes(depth)
    if shape is not None:
        return width, height, _array_depth_bytes(depth)
    return width, height, _values_bytes(depth)


def estimator_name(estimate):
    """"depth" or "stereo": which estimator made `estimate`."""
    return "stereo" if estimate.estimator == pb.ESTIMATOR_KIND_STEREO_MARKER else "depth"


def best_pose(estimate):
    """(x, y, theta) of the humanoid in the ground frame (metres, radians), or None when the
    frame failed, no cluster passed the score threshold, or the estimate is not a
    depth-template estimate."""
    if estimate.error.code or not estimate.HasField("depth_template"):
        return None
    result = estimate.depth_template
    if not result.humanoid_found:
        return None
    pose = result.best.best.pose
    return (pose.x, pose.y, pose.theta)


def world_pose(estimate):
    """(x, y, theta) of the robot in the world (landmark field) frame, metres and radians, from
    either estimator, or None when it was not located or the world frame is unknown (a depth
    estimate from a daemon without world_from_ground)."""
    if estimate.error.code or not estimate.HasField("robot_pose_world"):
        return None
    pose = estimate.robot_pose_world
    return (pose.x, pose.y, pose.theta)


def _read_bytes(path):
    if not path:
        return None
    with open(path, "rb") as f:
        return f.read()


class PoseClient:
    """Talks to one hposed. Every call takes a timeout in seconds (the gRPC deadline)."""

    def __init__(self, address="127.0.0.1:50051", max_message_bytes=64 << 20, tls_ca=None,
                 tls_cert=None, tls_key=None, token=None, token_file=None):
        """`tls_ca`: PEM file of the CA that signed the daemon's certificate (connects with
        TLS); `tls_cert`/`tls_key`: PEM client certificate and key for mutual TLS; `token` or
        `token_file` (its first line): the bearer token sent with every call."""
        options = [
            ("grpc.max_receive_message_length", max_message_bytes),
            ("grpc.max_send_message_length", max_message_bytes),
            # No read-ahead: a stream read more slowly than the daemon publishes gets the newest
            # estimate instead of tens of older ones held by the transport (docs/API.md).
            ("grpc.http2.bdp_probe", 0),
            ("grpc.http2.lookahead_bytes", 1),
        ]
        if bool(tls_cert) != bool(tls_key):
            raise ValueError("tls_cert and tls_key go together")
        if tls_ca or tls_cert:
            creds = grpc.ssl_channel_credentials(
                root_certificates=_read_bytes(tls_ca),
                private_key=_read_bytes(tls_key),
                certificate_chain=_read_bytes(tls_cert))
            self._channel = grpc.secure_channel(address, creds, options=options)
        else:
            self._channel = grpc.insecure_channel(address, options=options)
        if token_file:
            with open(token_file, encoding="utf-8") as f:
                token = f.readline().strip()
            if not token:
                raise ValueError(f"{token_file}: the first line holds no token")
        self._metadata = (("authorization", "Bearer " + token),) if token else ()
        self._stub = pb_grpc.PoseServiceStub(self._channel)

    def close(self):
        self._channel.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def _call(self, method, request, timeout):
        try:
            return method(request, timeout=timeout, metadata=self._metadata)
        except grpc.RpcError as e:  # pylint: disable=no-member
            raise PoseClientError(e.code(), e.details()) from None

    def wait_ready(self, timeout=10.0):
        """Blocks until the channel connects (raises PoseClientError on timeout)."""
        try:
            grpc.channel_ready_future(self._channel).result(timeout=timeout)
        except grpc.FutureTimeoutError:
            raise PoseClientError(grpc.StatusCode.UNAVAILABLE, "daemon not reachable") from None

    def latest(self, after_sequence=0, timeout=5.0, estimator=None):
        """The newest estimate (a hpose.v1.PoseEstimate) of one of the daemon's sources:
        estimator "depth" or "stereo", or None for the depth source when there is one, else the
        stereo source. `after_sequence` counts in that source's sequence numbers."""
        req = pb.GetLatestRequest(after_sequence=after_sequence,
                                  estimator=_estimator_kind(estimator))
        return self._call(self._stub.GetLatest, req, timeout).estimate

    def stream(self, max_estimates=0, timeout=None, estimators=()):
        """Yields estimates as the daemon makes them, of every estimator with a source, or only
        of `estimators` (names: "depth", "stereo"). Breaking out of the loop cancels. The
        iteration ends by itself once every streamed source has ended (a finished recording)."""
        req = pb.StreamPosesRequest(max_estimates=max_estimates,
                                    estimators=[_estimator_kind(e) for e in estimators])
        call = self._stub.StreamPoses(req, timeout=timeout, metadata=self._metadata)
        try:
            for estimate in call:
                yield estimate
        except grpc.RpcError as e:  # pylint: disable=no-member
            if e.code() != grpc.StatusCode.CANCELLED:
                raise PoseClientError(e.code(), e.details()) from None
        finally:
            call.cancel()

    def estimate_depth(self, depth_mm, width=None, height=None, fx=None, fy=None, cx=None,
                       cy=None, templates=(), timeout=10.0):
        """Estimates one depth frame, millimetres (0 = no reading), intrinsics in pixels.

        `depth_mm` is a 2-D array (numpy or anything with .shape and .astype, rows first:
        shape (height, width)) or a list of equal rows; width and height may then be left out.
        Or a flat sequence of width*height values, or bytes (little-endian uint16), both
        row-major with width and height given. Values are whole millimetres in [0, 65535];
        a numpy float array is rounded, its NaN and infinities read as no reading, and one
        whose largest value is below 20 is refused as metres. fx, fy, cx, cy are required."""
        if None in (fx, fy, cx, cy):
            raise ValueError("estimate_depth needs the intrinsics fx, fy, cx, cy (pixels)")
        width, height, data = _depth_bytes(depth_mm, width, height)
        req = pb.EstimateRequest(
            depth=pb.DepthImage(width=width, height=height, data=data,
                                intrinsics=pb.Intrinsics(width=width, height=height, fx=fx,
                                                         fy=fy, cx=cx, cy=cy)),
            templates=list(templates))
        return self._call(self._stub.Estimate, req, timeout).estimate

    def estimate_cloud(self, points_xyz, templates=(), timeout=10.0):
        """Estimates a cloud: an iterable of (x, y, z) in the sensor frame, metres."""
        flat = [c for p in points_xyz for c in p]
        req = pb.EstimateRequest(cloud=pb.PointCloud(xyz=flat), templates=list(templates))
        return self._call(self._stub.Estimate, req, timeout).estimate

    def estimate_stereo(self, left_rgb, right_rgb, width, height, source_time=0.0,
                        timeout=10.0):
        """Runs the daemon's stereo-marker estimator on one pair: `left_rgb`, `right_rgb` are
        bytes of width*height*3 (R, G, B, row-major from the top-left)."""
        req = pb.EstimateStereoRequest(
            left=pb.ColorImage(width=width, height=height, data=bytes(left_rgb)),
            right=pb.ColorImage(width=width, height=height, data=bytes(right_rgb)),
            source_time=source_time)
        return self._call(self._stub.EstimateStereo, req, timeout).estimate

    def templates(self, timeout=5.0):
        return list(self._call(self._stub.ListTemplates, pb.ListTemplatesRequest(),
                               timeout).templates)

    def status(self, timeout=5.0):
        return self._call(self._stub.GetStatus, pb.GetStatusRequest(), timeout)


def describe(estimate):
    """One human-readable line (mm, degrees) for an estimate."""
    head = "%-6s seq %d" % (estimator_name(estimate), estimate.sequence)
    if estimate.error.code:
        return "%s  no estimate: %s" % (head, estimate.error.message)
    world = world_pose(estimate)
    if estimate.HasField("stereo_marker"):
        result = estimate.stereo_marker
        if world is None:
            text = "%s  no robot pose (%s): %s" % (head, result.status, result.status_reason)
        else:
            text = "%s  robot world x %.0f mm  y %.0f mm  theta %.1f deg" % (
                head, world[0] * 1000, world[1] * 1000, math.degrees(world[2]))
        if result.object_found:
            ball = result.object_position_world
            text += "  ball x %.0f mm  y %.0f mm%s" % (ball.x * 1000, ball.y * 1000,
                                                       "  MOVING" if result.object_moving else "")
    else:
        pose = best_pose(estimate)
        if pose is None:
            return "%s  no humanoid" % head
        best = estimate.depth_template.best
        text = "%s  template %s  x %.0f mm  y %.0f mm  theta %.1f deg  score %.1f" % (
            head, best.best.template_name, pose[0] * 1000, pose[1] * 1000,
            math.degrees(pose[2]), best.best.score)
        if world is not None:
            text += "  world x %.0f mm  y %.0f mm  theta %.1f deg" % (
                world[0] * 1000, world[1] * 1000, math.degrees(world[2]))
    if estimate.stale:
        text += "  STALE: " + estimate.stale_reason
    return text
