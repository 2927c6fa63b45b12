#ifndef HPOSE_SERVER_POSE_SERVICE_H_
#define HPOSE_SERVER_POSE_SERVICE_H_

// The gRPC service. Includes gRPC: only the daemon and its tests include this header.
#include <atomic>
#include <chrono>
#include <string>

#include <grpcpp/grpcpp.h>

#include "core/common/status.h"
#include "hpose/v1/pose_service.grpc.pb.h"
#include "server/estimator_pool.h"
#include "server/pose_pipeline.h"

namespace hpose::server {

// Maps a core error to the canonical gRPC status with the same reason.
grpc::Status ToGrpcStatus(const Error& error);

// hpose.v1.PoseService on top of the daemon's pipeline (its own source) and an estimator pool
// (Estimate calls). Both must outlive the service.
class PoseServiceImpl final : public v1::PoseService::Service {
 public:
  PoseServiceImpl(PosePipeline* pipeline, EstimatorPool* pool, std::string floor_mode,
                  std::string version);

  grpc::Status Estimate(grpc::ServerContext* context, const v1::EstimateRequest* request,
                        v1::EstimateResponse* response) override;
  grpc::Status GetLatest(grpc::ServerContext* context, const v1::GetLatestRequest* request,
                         v1::GetLatestResponse* response) override;
  grpc::Status StreamPoses(grpc::ServerContext* context, const v1::StreamPosesRequest* request,
                           grpc::ServerWriter<v1::PoseEstimate>* writer) override;
  grpc::Status ListTemplates(grpc::ServerContext* context, const v1::ListTemplatesRequest* request,
                             v1::ListTemplatesResponse* response) override;
  grpc::Status GetStatus(grpc::ServerContext* context, const v1::GetStatusRequest* request,
                         v1::GetStatusResponse* response) override;

  // Ends running streams (called before the server shuts down).
  void BeginShutdown() { shutting_down_ = true; }

 private:
  void ToProto(const PublishedEstimate& e, v1::PoseEstimate* out) const;

  PosePipeline* pipeline_;
  EstimatorPool* pool_;
  const std::string floor_mode_;
  const std::string version_;
  const std::chrono::steady_clock::time_point start_;
  std::atomic<bool> shutting_down_{false};
  std::atomic<std::uint64_t> estimate_calls_{0};
};

}  // namespace hpose::server

#endif  // HPOSE_SERVER_POSE_SERVICE_H_
