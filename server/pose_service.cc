#include "server/pose_service.h"

#include <algorithm>
#include <utility>

#include "server/proto_convert.h"

namespace hpose::server {

namespace {

using Clock = std::chrono::steady_clock;

// The call's deadline on the steady clock (far future when the client set none).
Clock::time_point SteadyDeadline(const grpc::ServerContext* context) {
  const auto deadline = context->deadline();
  const auto now_sys = std::chrono::system_clock::now();
  if (deadline >= std::chrono::system_clock::time_point::max() - std::chrono::hours(24 * 365)) {
    return Clock::now() + std::chrono::hours(24 * 365);
  }
  return Clock::now() + std::chrono::duration_cast<Clock::duration>(deadline - now_sys);
}

v1::SourceState ToProtoState(SourceState s) {
  switch (s) {
    case SourceState::kNone:
      return v1::SOURCE_STATE_NONE;
    case SourceState::kStarting:
      return v1::SOURCE_STATE_STARTING;
    case SourceState::kRunning:
      return v1::SOURCE_STATE_RUNNING;
    case SourceState::kReconnecting:
      return v1::SOURCE_STATE_RECONNECTING;
    case SourceState::kFinished:
      return v1::SOURCE_STATE_FINISHED;
    case SourceState::kFailed:
      return v1::SOURCE_STATE_FAILED;
  }
  return v1::SOURCE_STATE_UNSPECIFIED;
}

}  // namespace

grpc::Status ToGrpcStatus(const Error& error) {
  grpc::StatusCode code = grpc::StatusCode::INTERNAL;
  switch (error.code) {
    case ErrorCode::kInvalidArgument:
      code = grpc::StatusCode::INVALID_ARGUMENT;
      break;
    case ErrorCode::kNotFound:
      code = grpc::StatusCode::NOT_FOUND;
      break;
    case ErrorCode::kDataLoss:
      code = grpc::StatusCode::DATA_LOSS;
      break;
    case ErrorCode::kFailedPrecondition:
      code = grpc::StatusCode::FAILED_PRECONDITION;
      break;
    case ErrorCode::kOutOfRange:
      code = grpc::StatusCode::OUT_OF_RANGE;
      break;
    case ErrorCode::kUnavailable:
      code = grpc::StatusCode::UNAVAILABLE;
      break;
    case ErrorCode::kInternal:
      code = grpc::StatusCode::INTERNAL;
      break;
  }
  return grpc::Status(code, error.message);
}

PoseServiceImpl::PoseServiceImpl(PosePipeline* pipeline, EstimatorPool* pool,
                                 std::string floor_mode, std::string version)
    : pipeline_(pipeline),
      pool_(pool),
      floor_mode_(std::move(floor_mode)),
      version_(std::move(version)),
      start_(Clock::now()) {}

void PoseServiceImpl::ToProto(const PublishedEstimate& e, v1::PoseEstimate* out) const {
  FillPoseEstimate(e.sequence, e.source_time_s, e.received, e.origin, e.ok ? &e.estimate : nullptr,
                   e.ok ? nullptr : &e.error, out);
  out->mutable_timings()->set_queue(e.queue_s);
  out->mutable_timings()->set_latency(e.latency_s);
  std::string reason;
  if (pipeline_->IsStale(e, &reason)) {
    out->set_stale(true);
    out->set_stale_reason(reason);
  }
}

grpc::Status PoseServiceImpl::Estimate(grpc::ServerContext* context,
                                       const v1::EstimateRequest* request,
                                       v1::EstimateResponse* response) {
  const Clock::time_point deadline = SteadyDeadline(context);
  const auto received = std::chrono::system_clock::now();
  const Clock::time_point start = Clock::now();
  if (start >= deadline)
    return grpc::Status(grpc::StatusCode::DEADLINE_EXCEEDED, "deadline passed");
  const std::vector<std::string> names(request->templates().begin(), request->templates().end());
  Result<hpose::Estimate> result = MakeError(ErrorCode::kInternal, "not run");
  switch (request->input_case()) {
    case v1::EstimateRequest::kDepth: {
      Intrinsics intrinsics;
      Result<DepthImage> depth = DepthFromProto(request->depth(), &intrinsics);
      if (!depth.ok()) return ToGrpcStatus(depth.error());
      result = pool_->EstimateDepth(*depth, intrinsics, names, deadline);
      break;
    }
    case v1::EstimateRequest::kCloud: {
      Result<PointCloud> cloud = CloudFromProto(request->cloud());
      if (!cloud.ok()) return ToGrpcStatus(cloud.error());
      result = pool_->EstimateCloud(*cloud, names, deadline);
      break;
    }
    default:
      return grpc::Status(grpc::StatusCode::INVALID_ARGUMENT,
                          "request holds neither a depth image nor a cloud");
  }
  if (context->IsCancelled()) return grpc::Status(grpc::StatusCode::CANCELLED, "cancelled");
  if (!result.ok()) {
    if (result.error().code == ErrorCode::kUnavailable && Clock::now() >= deadline) {
      return grpc::Status(grpc::StatusCode::DEADLINE_EXCEEDED, result.error().message);
    }
    return ToGrpcStatus(result.error());
  }
  const std::uint64_t seq = ++estimate_calls_;
  v1::PoseEstimate* out = response->mutable_estimate();
  FillPoseEstimate(seq, request->source_time(), received, "request", &*result, nullptr, out);
  out->mutable_timings()->set_latency(std::chrono::duration<double>(Clock::now() - start).count());
  return grpc::Status::OK;
}

grpc::Status PoseServiceImpl::GetLatest(grpc::ServerContext* context,
                                        const v1::GetLatestRequest* request,
                                        v1::GetLatestResponse* response) {
  if (!pipeline_->has_source()) {
    return grpc::Status(grpc::StatusCode::FAILED_PRECONDITION,
                        "the daemon has no source; send frames with Estimate");
  }
  const Clock::time_point deadline = SteadyDeadline(context);
  std::shared_ptr<const PublishedEstimate> latest = pipeline_->Latest();
  const std::uint64_t after = request->after_sequence();
  while (after > 0 && (!latest || latest->sequence <= after)) {
    if (context->IsCancelled()) return grpc::Status(grpc::StatusCode::CANCELLED, "cancelled");
    const Clock::time_point now = Clock::now();
    if (now >= deadline) {
      return grpc::Status(
          grpc::StatusCode::DEADLINE_EXCEEDED,
          "no estimate after sequence " + std::to_string(after) + " before the deadline");
    }
    if (shutting_down_) return grpc::Status(grpc::StatusCode::UNAVAILABLE, "shutting down");
    latest = pipeline_->WaitNewer(latest ? latest->publish_id : 0,
                                  std::min(deadline, now + std::chrono::milliseconds(100)));
  }
  if (!latest) {
    const PipelineStatus s = pipeline_->Status();
    return grpc::Status(grpc::StatusCode::UNAVAILABLE,
                        std::string("no estimate yet (source ") + SourceStateName(s.state) +
                            (s.reason.empty() ? "" : ": " + s.reason) + ")");
  }
  ToProto(*latest, response->mutable_estimate());
  return grpc::Status::OK;
}

grpc::Status PoseServiceImpl::StreamPoses(grpc::ServerContext* context,
                                          const v1::StreamPosesRequest* request,
                                          grpc::ServerWriter<v1::PoseEstimate>* writer) {
  if (!pipeline_->has_source()) {
    return grpc::Status(grpc::StatusCode::FAILED_PRECONDITION,
                        "the daemon has no source; send frames with Estimate");
  }
  const Clock::time_point deadline = SteadyDeadline(context);
  std::uint64_t last_id = 0;
  if (auto latest = pipeline_->Latest()) last_id = latest->publish_id;  // only new ones.
  std::uint32_t sent = 0;
  while (!context->IsCancelled() && !shutting_down_) {
    const Clock::time_point now = Clock::now();
    if (now >= deadline) break;
    std::shared_ptr<const PublishedEstimate> e =
        pipeline_->WaitNewer(last_id, std::min(deadline, now + std::chrono::milliseconds(100)));
    if (!e || e->publish_id <= last_id) continue;
    last_id = e->publish_id;
    v1::PoseEstimate msg;
    ToProto(*e, &msg);
    if (!writer->Write(msg)) break;  // the client went away.
    if (request->max_estimates() > 0 && ++sent >= request->max_estimates()) break;
  }
  if (context->IsCancelled()) return grpc::Status(grpc::StatusCode::CANCELLED, "cancelled");
  if (shutting_down_) return grpc::Status(grpc::StatusCode::UNAVAILABLE, "daemon shutting down");
  return grpc::Status::OK;
}

grpc::Status PoseServiceImpl::ListTemplates(grpc::ServerContext* /*context*/,
                                            const v1::ListTemplatesRequest* /*request*/,
                                            v1::ListTemplatesResponse* response) {
  for (const VoxelTemplate& t : pool_->templates()) {
    v1::TemplateInfo* info = response->add_templates();
    info->set_name(t.name);
    info->set_variant(t.variant);
    info->set_resolution(t.resolution_m);
    info->set_voxels(static_cast<int>(t.voxels.size()));
    info->set_height(t.Height());
    info->set_source(t.source);
  }
  return grpc::Status::OK;
}

grpc::Status PoseServiceImpl::GetStatus(grpc::ServerContext* /*context*/,
                                        const v1::GetStatusRequest* /*request*/,
                                        v1::GetStatusResponse* response) {
  const PipelineStatus s = pipeline_->Status();
  response->set_version(version_);
  response->set_uptime(std::chrono::duration<double>(Clock::now() - start_).count());
  v1::SourceStatus* src = response->mutable_source();
  src->set_description(s.description);
  src->set_kind(s.kind);
  src->set_state(ToProtoState(s.state));
  src->set_state_reason(s.reason);
  src->set_frames_in(s.frames_in);
  src->set_frames_dropped(s.frames_dropped);
  src->set_frames_estimated(s.frames_estimated);
  src->set_frames_failed(s.frames_failed);
  src->set_reconnects(s.reconnects);
  src->set_input_rate(s.input_rate_hz);
  src->set_estimate_rate(s.estimate_rate_hz);
  v1::LatencyStatus* lat = response->mutable_latency();
  lat->set_median(s.latency_median_s);
  lat->set_p99(s.latency_p99_s);
  lat->set_last(s.latency_last_s);
  lat->set_samples(s.latency_samples);
  response->set_floor_mode(floor_mode_);
  if (s.has_floor) {
    FloorToProto(s.last_floor, response->mutable_floor());
  } else if (pool_->options().use_fixed_floor) {
    FloorToProto(pool_->options().fixed_floor, response->mutable_floor());
  }
  response->set_templates(static_cast<std::uint32_t>(pool_->templates().size()));
  response->set_estimate_calls(estimate_calls_.load());
  return grpc::Status::OK;
}

}  // namespace hpose::server
