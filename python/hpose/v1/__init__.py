"""hpose.v1: messages (pose_service_pb2) and stubs (pose_service_pb2_grpc) of hpose.v1.PoseService."""
