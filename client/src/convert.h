// Conversions between the client's plain structs and the API's messages (library-internal).
#ifndef HPOSE_CLIENT_SRC_CONVERT_H_
#define HPOSE_CLIENT_SRC_CONVERT_H_

#include "hpose/client.h"
#include "hpose/v1/pose_service.pb.h"

namespace hpose::client::internal {

PoseEstimate FromProto(const v1::PoseEstimate& e);
DaemonStatus FromProto(const v1::GetStatusResponse& s);
v1::EstimatorKind ToProto(Estimator estimator);

// INVALID_ARGUMENT when the sizes disagree (the daemon would refuse the request anyway, with
// a less local message).
Status ToProto(const DepthImage& depth, v1::DepthImage* out);
Status ToProto(const PointCloud& cloud, v1::PointCloud* out);

}  // namespace hpose::client::internal

#endif  // HPOSE_CLIENT_SRC_CONVERT_H_
