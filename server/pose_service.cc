#include "server/pose_service.h"

#include <algorithm>
#include <exception>
#include <new>
#include <optional>
#include <utility>

#include "server/proto_convert.h"
#include "server/stereo_proto_convert.h"
#include "server/world_frame.h"

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

void FillSourceStatus(const PipelineStatus& s, v1::SourceStatus* src) {
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
  src->set_point_clouds(s.point_clouds);
  if (s.has_camera) IntrinsicsToProto(s.camera, src->mutable_camera());
}

void FillLatency(const PipelineStatus& s, v1::LatencyStatus* lat) {
  lat->set_median(s.latency_median_s);
  lat->set_p99(s.latency_p99_s);
  lat->set_last(s.latency_last_s);
  lat->set_samples(s.latency_samples);
}

// The delivery fields of a message about to be sent: when the estimate was published, the
// daemon's clock now, and the age of the frame (arrival to now, steady clock).
template <typename Published>
void StampDelivery(const Published& e, std::uint64_t skipped, v1::PoseEstimate* out) {
  SetTimestamp(e.published_wall, out->mutable_publish_time());
  SetTimestamp(std::chrono::system_clock::now(), out->mutable_send_time());
  out->set_age(e.latency_s + std::chrono::duration<double>(Clock::now() - e.published).count());
  out->set_skipped(skipped);
  out->set_source_epoch(e.source_epoch);
}

// An Estimate / EstimateStereo answer: latency and age both run from the request's arrival;
// published and sent now.
void StampAnswer(Clock::time_point start, v1::PoseEstimate* out) {
  const double elapsed = std::chrono::duration<double>(Clock::now() - start).count();
  out->mutable_timings()->set_latency(elapsed);
  const auto now = std::chrono::system_clock::now();
  SetTimestamp(now, out->mutable_publish_time());
  SetTimestamp(now, out->mutable_send_time());
  out->set_age(elapsed);
}

const char* EstimatorName(v1::EstimatorKind kind) {
  return kind == v1::ESTIMATOR_KIND_STEREO_MARKER ? "stereo-marker" : "depth-template";
}

// GetLatest on one pipeline (PosePipeline or StereoPipeline): the newest estimate, waiting for
// one with a sequence above `after` within the deadline when `after` > 0.
template <typename Pipeline, typename Published>
grpc::Status LatestFrom(const Pipeline& pipeline, grpc::ServerContext* context, std::uint64_t after,
                        Clock::time_point deadline, const std::atomic<bool>& shutting_down,
                        std::shared_ptr<const Published>* out) {
  std::shared_ptr<const Published> latest = pipeline.Latest();
  while (after > 0 && (!latest || latest->sequence <= after)) {
    if (context != nullptr && context->IsCancelled()) {
      return grpc::Status(grpc::StatusCode::CANCELLED, "cancelled");
    }
    const Clock::time_point now = Clock::now();
    if (now >= deadline) {
      return grpc::Status(
          grpc::StatusCode::DEADLINE_EXCEEDED,
          "no estimate after sequence " + std::to_string(after) + " before the deadline");
    }
    if (shutting_down) return grpc::Status(grpc::StatusCode::UNAVAILABLE, "shutting down");
    if (pipeline.Ended()) {  // read before Latest: whatever it ended with is in `latest`.
      latest = pipeline.Latest();
      if (latest && latest->sequence > after) break;
      const PipelineStatus s = pipeline.Status();
      return grpc::Status(grpc::StatusCode::OUT_OF_RANGE,
                          "no estimate after sequence " + std::to_string(after) +
                              " will come: the source " + SourceStateName(s.state) +
                              (s.reason.empty() ? "" : ": " + s.reason));
    }
    latest = pipeline.WaitNewer(latest ? latest->publish_id : 0,
                                std::min(deadline, now + std::chrono::milliseconds(100)));
  }
  if (!latest) {
    const PipelineStatus s = pipeline.Status();
    return grpc::Status(grpc::StatusCode::UNAVAILABLE,
                        std::string("no estimate yet (source ") + SourceStateName(s.state) +
                            (s.reason.empty() ? "" : ": " + s.reason) + ")");
  }
  *out = std::move(latest);
  return grpc::Status::OK;
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

void PoseServiceImpl::AttachStereo(StereoPipeline* pipeline, const StereoEstimator* estimator) {
  stereo_pipeline_ = pipeline;
  stereo_estimator_ = estimator;
}

void PoseServiceImpl::SetWorldFromGround(const Pose2D& world_from_ground) {
  has_world_from_ground_ = true;
  world_from_ground_ = world_from_ground;
}

void PoseServiceImpl::ToProto(const PublishedEstimate& e, std::uint64_t skipped,
                              v1::PoseEstimate* out) const {
  FillPoseEstimate(e.sequence, e.source_time_s, e.received, e.origin, e.ok ? &e.estimate : nullptr,
                   e.ok ? nullptr : &e.error, out);
  if (has_world_from_ground_) AddDepthWorldFrame(world_from_ground_, out);
  out->mutable_timings()->set_queue(e.queue_s);
  out->mutable_timings()->set_latency(e.latency_s);
  std::string reason;
  if (pipeline_->IsStale(e, &reason)) {
    out->set_stale(true);
    out->set_stale_reason(reason);
  }
  StampDelivery(e, skipped, out);
}

void PoseServiceImpl::ToProto(const PublishedStereoEstimate& e, std::uint64_t skipped,
                              v1::PoseEstimate* out) const {
  FillStereoPoseEstimate(e.sequence, e.source_time_s, e.received, e.origin,
                         e.ok ? &e.frame : nullptr, e.ok ? &e.track : nullptr,
                         e.ok ? nullptr : &e.error, e.process_s, out);
  out->mutable_timings()->set_latency(e.latency_s);
  std::string reason;
  if (stereo_pipeline_->IsStale(e, &reason)) {
    out->set_stale(true);
    out->set_stale_reason(reason);
  }
  StampDelivery(e, skipped, out);
}

grpc::Status PoseServiceImpl::Estimate(grpc::ServerContext* context,
                                       const v1::EstimateRequest* request,
                                       v1::EstimateResponse* response) {
  if (grpc::Status auth = Authorize(context, TokenRole::kEstimate); !auth.ok()) return auth;
  const Clock::time_point deadline = SteadyDeadline(context);
  const auto received = std::chrono::system_clock::now();
  const Clock::time_point start = Clock::now();
  if (start >= deadline)
    return grpc::Status(grpc::StatusCode::DEADLINE_EXCEEDED, "deadline passed");
  // Admission before any copy of the request: a bounded number of calls and bytes at once.
  std::optional<AdmissionControl::Ticket> ticket;
  if (admission_ != nullptr) {
    ticket.emplace(admission_->TryAdmit(request->ByteSizeLong()));
    if (!ticket->admitted()) {
      return grpc::Status(grpc::StatusCode::RESOURCE_EXHAUSTED,
                          "busy: " + std::to_string(admission_->max_calls()) +
                              " Estimate calls or " + std::to_string(admission_->max_bytes()) +
                              " request bytes are in flight; retry later");
    }
  }
  const std::vector<std::string> names(request->templates().begin(), request->templates().end());
  Result<hpose::Estimate> result = MakeError(ErrorCode::kInternal, "not run");
  // Inputs are validated in core; a library that still throws fails this call, not the daemon.
  try {
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
  } catch (const std::bad_alloc&) {
    return grpc::Status(grpc::StatusCode::RESOURCE_EXHAUSTED, "out of memory for this request");
  } catch (const std::exception& e) {
    return grpc::Status(grpc::StatusCode::INTERNAL, std::string("estimation failed: ") + e.what());
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
  if (has_world_from_ground_) AddDepthWorldFrame(world_from_ground_, out);
  StampAnswer(start, out);
  return grpc::Status::OK;
}

grpc::Status PoseServiceImpl::EstimateStereo(grpc::ServerContext* context,
                                             const v1::EstimateStereoRequest* request,
                                             v1::EstimateResponse* response) {
  if (grpc::Status auth = Authorize(context, TokenRole::kEstimate); !auth.ok()) return auth;
  const Clock::time_point deadline = SteadyDeadline(context);
  const auto received = std::chrono::system_clock::now();
  const Clock::time_point start = Clock::now();
  if (start >= deadline) {
    return grpc::Status(grpc::StatusCode::DEADLINE_EXCEEDED, "deadline passed");
  }
  if (stereo_estimator_ == nullptr) {
    return grpc::Status(grpc::StatusCode::FAILED_PRECONDITION,
                        "the daemon has no stereo calibration (start it with "
                        "--stereo-calibration FILE or --stereo-source DIR)");
  }
  if (!request->has_left() || !request->has_right()) {
    return grpc::Status(grpc::StatusCode::INVALID_ARGUMENT,
                        std::string("request is missing the ") +
                            (request->has_left() ? "right" : "left") + " image");
  }
  Result<RgbImage> left = ColorImageFromProto(request->left(), "left");
  if (!left.ok()) return ToGrpcStatus(left.error());
  Result<RgbImage> right = ColorImageFromProto(request->right(), "right");
  if (!right.ok()) return ToGrpcStatus(right.error());
  const Clock::time_point process_start = Clock::now();
  Result<StereoFrameResult> result =
      stereo_estimator_->Process(*left, *right, request->source_time());
  const double process_s = std::chrono::duration<double>(Clock::now() - process_start).count();
  if (!result.ok()) return ToGrpcStatus(result.error());
  const std::uint64_t seq = ++estimate_stereo_calls_;
  v1::PoseEstimate* out = response->mutable_estimate();
  FillStereoPoseEstimate(seq, request->source_time(), received, "request", &*result, nullptr,
                         nullptr, process_s, out);
  StampAnswer(start, out);
  return grpc::Status::OK;
}

grpc::Status PoseServiceImpl::GetLatest(grpc::ServerContext* context,
                                        const v1::GetLatestRequest* request,
                                        v1::GetLatestResponse* response) {
  if (grpc::Status auth = Authorize(context, TokenRole::kRead); !auth.ok()) return auth;
  return Latest(context, request->estimator(), request->after_sequence(), response);
}

grpc::Status PoseServiceImpl::ReadLatest(v1::EstimatorKind kind,
                                         v1::GetLatestResponse* response) const {
  return Latest(nullptr, kind, 0, response);
}

grpc::Status PoseServiceImpl::Latest(grpc::ServerContext* context, v1::EstimatorKind kind,
                                     std::uint64_t after, v1::GetLatestResponse* response) const {
  if (kind == v1::ESTIMATOR_KIND_UNSPECIFIED) {
    kind = pipeline_->has_source() || stereo_pipeline_ == nullptr
               ? v1::ESTIMATOR_KIND_DEPTH_TEMPLATE
               : v1::ESTIMATOR_KIND_STEREO_MARKER;
  }
  const Clock::time_point deadline =
      context != nullptr ? SteadyDeadline(context) : Clock::now() + std::chrono::hours(24);
  if (kind == v1::ESTIMATOR_KIND_DEPTH_TEMPLATE) {
    if (!pipeline_->has_source()) {
      return grpc::Status(grpc::StatusCode::FAILED_PRECONDITION,
                          "the daemon has no depth source; send frames with Estimate");
    }
    std::shared_ptr<const PublishedEstimate> latest;
    grpc::Status s = LatestFrom(*pipeline_, context, after, deadline, shutting_down_, &latest);
    if (!s.ok()) return s;
    ToProto(*latest, 0, response->mutable_estimate());
    return grpc::Status::OK;
  }
  if (kind != v1::ESTIMATOR_KIND_STEREO_MARKER) {
    return grpc::Status(grpc::StatusCode::INVALID_ARGUMENT,
                        "estimator: unknown value " + std::to_string(static_cast<int>(kind)));
  }
  if (stereo_pipeline_ == nullptr) {
    return grpc::Status(grpc::StatusCode::FAILED_PRECONDITION,
                        "the daemon has no stereo source (start it with --stereo-source DIR)");
  }
  std::shared_ptr<const PublishedStereoEstimate> latest;
  grpc::Status s = LatestFrom(*stereo_pipeline_, context, after, deadline, shutting_down_, &latest);
  if (!s.ok()) return s;
  ToProto(*latest, 0, response->mutable_estimate());
  return grpc::Status::OK;
}

grpc::Status PoseServiceImpl::StreamPoses(grpc::ServerContext* context,
                                          const v1::StreamPosesRequest* request,
                                          grpc::ServerWriter<v1::PoseEstimate>* writer) {
  if (grpc::Status auth = Authorize(context, TokenRole::kRead); !auth.ok()) return auth;
  std::optional<StreamLimiter::Slot> slot;
  if (streams_ != nullptr) {
    const auto& metadata = context->client_metadata();
    const auto it = metadata.find("authorization");
    const bool by_token = tokens_ != nullptr && it != metadata.end();
    const std::string token = by_token ? std::string(it->second.data(), it->second.size()) : "";
    slot.emplace(streams_->TryOpen(ClientKey(by_token, token, context->peer())));
    if (!slot->admitted()) {
      return grpc::Status(
          grpc::StatusCode::RESOURCE_EXHAUSTED,
          "too many streams: " +
              (by_token ? std::string("this token") : "client " + PeerHost(context->peer())) +
              " already has " + std::to_string(streams_->max_per_client()) +
              " StreamPoses calls open (grpc.max_pose_streams_per_client); end one first");
    }
  }
  bool want_depth = request->estimators().empty() && pipeline_->has_source();
  bool want_stereo = request->estimators().empty() && stereo_pipeline_ != nullptr;
  for (const int k : request->estimators()) {
    const auto kind = static_cast<v1::EstimatorKind>(k);
    const bool present = kind == v1::ESTIMATOR_KIND_DEPTH_TEMPLATE  ? pipeline_->has_source()
                         : kind == v1::ESTIMATOR_KIND_STEREO_MARKER ? stereo_pipeline_ != nullptr
                                                                    : false;
    if (kind != v1::ESTIMATOR_KIND_DEPTH_TEMPLATE && kind != v1::ESTIMATOR_KIND_STEREO_MARKER) {
      return grpc::Status(grpc::StatusCode::INVALID_ARGUMENT,
                          "estimators: unknown value " + std::to_string(k));
    }
    if (!present) {
      return grpc::Status(
          grpc::StatusCode::FAILED_PRECONDITION,
          std::string("the daemon has no source for the ") + EstimatorName(kind) + " estimator");
    }
    (kind == v1::ESTIMATOR_KIND_DEPTH_TEMPLATE ? want_depth : want_stereo) = true;
  }
  if (!want_depth && !want_stereo) {
    return grpc::Status(grpc::StatusCode::FAILED_PRECONDITION,
                        "the daemon has no source; send frames with Estimate");
  }
  const Clock::time_point deadline = SteadyDeadline(context);
  // Publish ids of the last estimate sent (at first: the newest when the stream began, so only
  // estimates published from now on are sent; those published but not sent count as skipped).
  std::uint64_t last_depth = 0, last_stereo = 0;
  if (want_depth) {
    if (auto latest = pipeline_->Latest()) last_depth = latest->publish_id;
  }
  if (want_stereo) {
    if (auto latest = stereo_pipeline_->Latest()) last_stereo = latest->publish_id;
  }
  std::uint32_t sent = 0;
  const std::uint32_t max = request->max_estimates();
  bool deadline_passed = false;
  while (!context->IsCancelled() && !shutting_down_) {
    const Clock::time_point now = Clock::now();
    if (now >= deadline) {
      deadline_passed = true;
      break;
    }
    const std::uint64_t seen = signal_ != nullptr ? signal_->count() : 0;
    // Read before looking for news: a source that had ended has published everything it will.
    const bool ended =
        (!want_depth || pipeline_->Ended()) && (!want_stereo || stereo_pipeline_->Ended());
    bool wrote = false, done = false;
    if (want_depth) {
      std::shared_ptr<const PublishedEstimate> e = pipeline_->Latest();
      if (e && e->publish_id > last_depth) {
        v1::PoseEstimate msg;
        ToProto(*e, e->publish_id - last_depth - 1, &msg);
        last_depth = e->publish_id;
        // Write-through: the call returns once the message is on the wire, so a client slower
        // than the source holds this loop back and the next message is the newest estimate.
        if (!writer->Write(msg, grpc::WriteOptions().set_write_through())) break;  // client gone.
        wrote = true;
        done = max > 0 && ++sent >= max;
      }
    }
    if (want_stereo && !done) {
      std::shared_ptr<const PublishedStereoEstimate> e = stereo_pipeline_->Latest();
      if (e && e->publish_id > last_stereo) {
        v1::PoseEstimate msg;
        ToProto(*e, e->publish_id - last_stereo - 1, &msg);
        last_stereo = e->publish_id;
        if (!writer->Write(msg, grpc::WriteOptions().set_write_through())) break;
        wrote = true;
        done = max > 0 && ++sent >= max;
      }
    }
    if (done) break;
    if (wrote) continue;
    if (ended) break;  // every source streamed has ended and all it published was sent.
    const Clock::time_point wait_until = std::min(deadline, now + std::chrono::milliseconds(100));
    if (signal_ != nullptr) {
      signal_->WaitChange(seen, wait_until);
    } else if (want_depth && !pipeline_->Ended()) {  // an ended one would not wait.
      pipeline_->WaitNewer(last_depth, wait_until);
    } else {
      stereo_pipeline_->WaitNewer(last_stereo, wait_until);
    }
  }
  if (context->IsCancelled()) return grpc::Status(grpc::StatusCode::CANCELLED, "cancelled");
  if (shutting_down_) return grpc::Status(grpc::StatusCode::UNAVAILABLE, "daemon shutting down");
  // Ended by the caller's deadline: say so, as gRPC would had its own timer fired first (which
  // of the two sees the deadline first is a race).
  if (deadline_passed) {
    return grpc::Status(grpc::StatusCode::DEADLINE_EXCEEDED,
                        "stream deadline reached after " + std::to_string(sent) + " estimate(s)");
  }
  return grpc::Status::OK;
}

grpc::Status PoseServiceImpl::ListTemplates(grpc::ServerContext* context,
                                            const v1::ListTemplatesRequest* /*request*/,
                                            v1::ListTemplatesResponse* response) {
  if (grpc::Status auth = Authorize(context, TokenRole::kRead); !auth.ok()) return auth;
  ReadTemplates(response);
  return grpc::Status::OK;
}

void PoseServiceImpl::ReadTemplates(v1::ListTemplatesResponse* response) const {
  for (const VoxelTemplate& t : pool_->templates()) {
    v1::TemplateInfo* info = response->add_templates();
    info->set_name(t.name);
    info->set_variant(t.variant);
    info->set_resolution(t.resolution_m);
    info->set_voxels(static_cast<int>(t.voxels.size()));
    info->set_height(t.Height());
    info->set_source(t.source);
    info->set_search_resolution(pool_->options().lattice.resolution_m);
  }
}

grpc::Status PoseServiceImpl::GetStatus(grpc::ServerContext* context,
                                        const v1::GetStatusRequest* /*request*/,
                                        v1::GetStatusResponse* response) {
  if (grpc::Status auth = Authorize(context, TokenRole::kRead); !auth.ok()) return auth;
  ReadStatus(response);
  return grpc::Status::OK;
}

void PoseServiceImpl::ReadStatus(v1::GetStatusResponse* response) const {
  const PipelineStatus s = pipeline_->Status();
  response->set_version(version_);
  response->set_uptime(std::chrono::duration<double>(Clock::now() - start_).count());
  FillSourceStatus(s, response->mutable_source());
  FillLatency(s, response->mutable_latency());
  if (stereo_pipeline_ != nullptr) {
    const PipelineStatus st = stereo_pipeline_->Status();
    FillSourceStatus(st, response->mutable_stereo_source());
    FillLatency(st, response->mutable_stereo_latency());
  } else {
    response->mutable_stereo_source()->set_state(v1::SOURCE_STATE_NONE);
    response->mutable_stereo_source()->set_state_reason("no stereo source configured");
  }
  response->set_stereo_calibrated(stereo_estimator_ != nullptr);
  response->set_estimate_stereo_calls(estimate_stereo_calls_.load());
  if (has_world_from_ground_) {
    v1::Pose2D* w = response->mutable_world_from_ground();
    w->set_x(world_from_ground_.x);
    w->set_y(world_from_ground_.y);
    w->set_theta(world_from_ground_.theta);
  }
  response->set_floor_mode(floor_mode_);
  if (s.has_floor) {
    FloorToProto(s.last_floor, response->mutable_floor());
  } else if (pool_->options().use_fixed_floor) {
    FloorToProto(pool_->options().fixed_floor, response->mutable_floor());
  }
  response->set_templates(static_cast<std::uint32_t>(pool_->templates().size()));
  response->set_estimate_calls(estimate_calls_.load());
}

}  // namespace hpose::server
