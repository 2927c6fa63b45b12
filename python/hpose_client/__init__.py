"""Python client of hposed, the hpose daemon (gRPC API hpose.v1.PoseService).

The message and stub modules are generated from proto/hpose/v1/pose_service.proto by the
build (target hpose_proto_python) into <build>/python; put that directory and this one on
PYTHONPATH. Units are SI: metres, radians, seconds.
"""

from hpose_client.client import (PoseClient, PoseClientError, best_pose, estimator_name,
                                 world_pose)

__all__ = ["PoseClient", "PoseClientError", "best_pose", "estimator_name", "world_pose"]
