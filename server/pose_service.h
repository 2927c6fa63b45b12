#ifndef HPOSE_SERVER_POSE_SERVICE_H_
#define HPOSE_SERVER_POSE_SERVICE_H_

// The gRPC service. Includes gRPC: only the daemon and its tests include this header.
#include <atomic>
#include <chrono>
#include <string>

#include <grpcpp/grpcpp.h>

#include "core/common/pose2d.h"
#include "core/common/status.h"
#include "core/stereo/stereo_estimator.h"
#include "hpose/v1/pose_service.grpc.pb.h"
#include "server/admission_control.h"
#include "server/estimator_pool.h"
#include "server/pose_pipeline.h"
#include "server/publish_signal.h"
#include "server/stereo_pipeline.h"
#include "server/stream_limiter.h"
#include "server/token_auth.h"

namespace hpose::server {

// Maps a core error to the canonical gRPC status with the same reason.
grpc::Status ToGrpcStatus(const Error& error);

// hpose.v1.PoseService on top of the daemon's pipeline (its own source) and an estimator pool
// (Estimate calls), optionally a stereo pipeline and stereo estimator (EstimateStereo calls).
// Everything passed in must outlive the service; the Attach/Set calls come before serving.
class PoseServiceImpl final : public v1::PoseService::Service {
 public:
  PoseServiceImpl(PosePipeline* pipeline, EstimatorPool* pool, std::string floor_mode,
                  std::string version);

  // The stereo source's pipeline (may be null: no stereo source) and the estimator used for
  // EstimateStereo calls (may be null: no calibration; the calls then fail).
  void AttachStereo(StereoPipeline* pipeline, const StereoEstimator* estimator);
  // Report depth-template poses also in the world frame.
  void SetWorldFromGround(const Pose2D& world_from_ground);
  // Notified by both pipelines; lets a stream of both estimators wait for either.
  void SetPublishSignal(const PublishSignal* signal) { signal_ = signal; }
  // Estimate calls pass it before their request is decoded (null: no admission control).
  void SetAdmissionControl(AdmissionControl* admission) { admission_ = admission; }
  // Every call must carry a bearer token it accepts (null: no tokens needed).
  void SetTokenAuthorizer(const TokenAuthorizer* tokens) { tokens_ = tokens; }
  // StreamPoses calls pass it, per client (null: no per-client limit).
  void SetStreamLimiter(StreamLimiter* streams) { streams_ = streams; }

  grpc::Status Estimate(grpc::ServerContext* context, const v1::EstimateRequest* request,
                        v1::EstimateResponse* response) override;
  grpc::Status EstimateStereo(grpc::ServerContext* context,
                              const v1::EstimateStereoRequest* request,
                              v1::EstimateResponse* response) override;
  grpc::Status GetLatest(grpc::ServerContext* context, const v1::GetLatestRequest* request,
                         v1::GetLatestResponse* response) override;
  grpc::Status StreamPoses(grpc::ServerContext* context, const v1::StreamPosesRequest* request,
                           grpc::ServerWriter<v1::PoseEstimate>* writer) override;
  grpc::Status ListTemplates(grpc::ServerContext* context, const v1::ListTemplatesRequest* request,
                             v1::ListTemplatesResponse* response) override;
  grpc::Status GetStatus(grpc::ServerContext* context, const v1::GetStatusRequest* request,
                         v1::GetStatusResponse* response) override;

  // The answers of GetLatest (after_sequence 0, no waiting) and GetStatus outside a gRPC call,
  // for the daemon's web view: the same messages, filled the same way. UNSPECIFIED chooses the
  // estimator as GetLatest does.
  grpc::Status ReadLatest(v1::EstimatorKind kind, v1::GetLatestResponse* response) const;
  void ReadStatus(v1::GetStatusResponse* response) const;
  // The templates the daemon matches, as ListTemplates answers.
  void ReadTemplates(v1::ListTemplatesResponse* response) const;

  // Ends running streams (called before the server shuts down).
  void BeginShutdown() { shutting_down_ = true; }

 private:
  // The message for `e` as sent now: staleness judged and delivery fields (send_time, age)
  // stamped at this moment; `skipped` = estimates this stream did not send before `e`.
  void ToProto(const PublishedEstimate& e, std::uint64_t skipped, v1::PoseEstimate* out) const;
  void ToProto(const PublishedStereoEstimate& e, std::uint64_t skipped,
               v1::PoseEstimate* out) const;

  // GetLatest: `context` may be null when `after` is 0 (no waiting, no deadline).
  grpc::Status Latest(grpc::ServerContext* context, v1::EstimatorKind kind, std::uint64_t after,
                      v1::GetLatestResponse* response) const;

  PosePipeline* pipeline_;
  StereoPipeline* stereo_pipeline_ = nullptr;
  const StereoEstimator* stereo_estimator_ = nullptr;
  const PublishSignal* signal_ = nullptr;
  bool has_world_from_ground_ = false;
  Pose2D world_from_ground_;
  EstimatorPool* pool_;
  AdmissionControl* admission_ = nullptr;
  const TokenAuthorizer* tokens_ = nullptr;
  StreamLimiter* streams_ = nullptr;
  grpc::Status Authorize(const grpc::ServerContext* context, TokenRole needed) const {
    return tokens_ == nullptr ? grpc::Status::OK : tokens_->Check(*context, needed);
  }
  const std::string floor_mode_;
  const std::string version_;
  const std::chrono::steady_clock::time_point start_;
  std::atomic<bool> shutting_down_{false};
  std::atomic<std::uint64_t> estimate_calls_{0};
  std::atomic<std::uint64_t> estimate_stereo_calls_{0};
};

}  // namespace hpose::server

#endif  // HPOSE_SERVER_POSE_SERVICE_H_
