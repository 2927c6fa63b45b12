#ifndef HPOSE_SERVER_PROTO_CONVERT_H_
#define HPOSE_SERVER_PROTO_CONVERT_H_

#include <chrono>
#include <string>

#include <Eigen/Core>

#include "core/common/pose2d.h"
#include "core/common/status.h"
#include "core/depth/depth_image.h"
#include "core/depth/floor_estimate.h"
#include "core/depth/intrinsics.h"
#include "core/depth/point_cloud.h"
#include "core/search/estimate.h"
#include "hpose/v1/pose_service.pb.h"

namespace hpose::server {

// Largest point cloud accepted in a request (points).
constexpr size_t kMaxRequestCloudPoints = 4'000'000;

// Core results -> API messages (SI units, frames as documented in the proto). EstimateToProto
// writes the whole message: whatever *out held before is cleared.
void FloorToProto(const FloorEstimate& floor, v1::FloorFrame* out);
void EstimateToProto(const Estimate& estimate, v1::DepthTemplateResult* out);
void TimingsToProto(const StageTimings& timings, v1::Timings* out);
void SetTimestamp(std::chrono::system_clock::time_point t, google::protobuf::Timestamp* out);
void SetVector(const Eigen::Vector3d& v, v1::Vector3* out);
void SetPose2D(const Pose2D& p, v1::Pose2D* out);

// Fills a PoseEstimate from one frame's outcome: `result` set, or `error` when the frame
// failed.
void FillPoseEstimate(std::uint64_t sequence, double source_time_s,
                      std::chrono::system_clock::time_point received, const std::string& source,
                      const Estimate* result, const Error* error, v1::PoseEstimate* out);

// API request -> core inputs. Fail with kInvalidArgument naming the field: sizes that do not
// match (width * height * 2 bytes), intrinsics that are NaN, non-positive or disagree with the
// image size; a cloud whose length is not a multiple of 3, empty, or too large.
Result<DepthImage> DepthFromProto(const v1::DepthImage& depth, Intrinsics* intrinsics);
Result<PointCloud> CloudFromProto(const v1::PointCloud& cloud);

// The inverse helpers, for clients (hpose query estimate) and tests.
void DepthToProto(const DepthImage& depth, const Intrinsics& intrinsics, v1::DepthImage* out);
void CloudToProto(const PointCloud& cloud, v1::PointCloud* out);
void IntrinsicsToProto(const Intrinsics& intrinsics, v1::Intrinsics* out);

}  // namespace hpose::server

#endif  // HPOSE_SERVER_PROTO_CONVERT_H_
