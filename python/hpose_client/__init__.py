"""Python client of hposed, the hpose daemon (gRPC API hpose.v1.PoseService).

Install it from the repository with `pip install ./python` (see python/README.md); the
message and stub modules (package hpose.v1) come with it. Units are SI: metres, radians,
seconds.
"""

from hpose_client.client import (PoseClient, PoseClientError, best_pose, estimator_name,
                                 world_pose)

__all__ = ["PoseClient", "PoseClientError", "best_pose", "estimator_name", "world_pose"]
