#include "server/daemon.h"

#include <grpcpp/ext/proto_server_reflection_plugin.h>
#include <grpcpp/grpcpp.h>
#include <grpcpp/health_check_service_interface.h>
#include <grpcpp/resource_quota.h>

#include <spdlog/spdlog.h>

#include <chrono>
#include <future>
#include <memory>
#include <thread>
#include <utility>

#include "core/common/task_pool.h"
#include "core/io/atomic_file.h"
#include "core/io/intrinsics_file.h"
#include "core/sim/frame_simulator.h"
#include "core/stereo/stereo_calibration.h"
#include "core/stereo/stereo_estimator.h"
#include "core/stereo/stereo_marker_options.h"
#include "core/stereo/stereo_sequence.h"
#include "core/templates/template_io.h"
#include "server/admission_control.h"
#include "server/estimator_pool.h"
#include "server/frame_source.h"
#include "server/grpc_listener.h"
#include "server/http_view.h"
#include "server/live_scene.h"
#include "server/metrics.h"
#include "server/pose_pipeline.h"
#include "server/pose_service.h"
#include "server/publish_signal.h"
#include "server/rpc_metrics_interceptor.h"
#include "server/stereo_pipeline.h"
#include "server/stream_limiter.h"
#include "server/tcp_listener.h"
#include "server/token_auth.h"
#include "server/warm_up_frame.h"
#include "server/world_frame.h"

namespace hpose::server {

const char* HposeVersion() { return "0.1.0"; }

namespace {

Error Prefixed(const std::string& prefix, Error e) {
  e.message = prefix + e.message;
  return e;
}

// The stereo estimator (calibration from stereo.calibration or the source's calibration.yaml)
// and, when a stereo source is configured, its pipeline. The source's first pair is read once
// here so that a sequence that does not fit the calibration fails at start with the reason.
Status StartStereo(const StereoConfig& config, PublishSignal* signal,
                   std::unique_ptr<StereoEstimator>* estimator,
                   std::unique_ptr<StereoPipeline>* pipeline) {
  Result<StereoSequence> sequence = MakeError(ErrorCode::kNotFound, "no stereo source");
  std::string calibration_path = config.calibration;
  if (!config.source.empty()) {
    sequence = StereoSequence::Open(config.source, config.fps);
    if (!sequence.ok()) return Prefixed("stereo source: ", sequence.error());
    if (sequence->size() == 0) {
      return MakeError(ErrorCode::kNotFound,
                       "stereo source: " + config.source + ": no stereo frame pairs");
    }
    if (calibration_path.empty()) calibration_path = sequence->calibration_path();
    if (calibration_path.empty()) {
      return MakeError(ErrorCode::kNotFound,
                       "stereo source: " + config.source +
                           " holds no calibration.yaml; give one with --stereo-calibration FILE "
                           "(stereo.calibration)");
    }
  }
  StereoCalibrationReadOptions read;
  read.translation_unit_m = config.calibration_unit == "mm" ? 0.001 : 1.0;
  Result<StereoCalibration> calibration = ReadStereoCalibration({calibration_path}, read);
  if (!calibration.ok()) return Prefixed("stereo calibration: ", calibration.error());
  StereoMarkerOptions options;
  if (!config.options.empty()) {
    Result<StereoMarkerOptions> loaded = LoadStereoMarkerOptions(config.options);
    if (!loaded.ok()) return Prefixed("stereo options: ", loaded.error());
    options = *loaded;
  }
  Result<std::unique_ptr<StereoEstimator>> made = StereoEstimator::Create(*calibration, options);
  if (!made.ok()) return Prefixed("stereo estimator: ", made.error());
  *estimator = std::move(*made);
  if (!sequence.ok()) return Status::Ok();
  Result<std::pair<RgbImage, RgbImage>> first = sequence->Load(0);
  if (!first.ok()) return Prefixed("stereo source: ", first.error());
  Result<StereoFrameResult> check =
      (*estimator)->Process(first->first, first->second, sequence->frame(0).timestamp_s);
  if (!check.ok()) {
    return Prefixed(
        "stereo source: " + sequence->frame(0).left_path + " with " + calibration_path + ": ",
        check.error());
  }
  *pipeline =
      std::make_unique<StereoPipeline>(std::move(*sequence), estimator->get(), config, signal);
  return Status::Ok();
}

}  // namespace

class Daemon::Impl {
 public:
  // Fed by the pipeline's estimation thread: declared first, destroyed last.
  std::unique_ptr<DaemonMetrics> metrics = std::make_unique<DaemonMetrics>();
  std::unique_ptr<LiveScene> scene;  // only with the web view.
  std::unique_ptr<PublishSignal> signal = std::make_unique<PublishSignal>();
  std::unique_ptr<StereoEstimator> stereo_estimator;  // shared by the pipeline and the calls.
  std::unique_ptr<StereoPipeline> stereo_pipeline;
  std::unique_ptr<EstimatorPool> pool;
  std::unique_ptr<AdmissionControl> admission;
  std::unique_ptr<StreamLimiter> streams;
  std::unique_ptr<TokenAuthorizer> tokens;
  std::unique_ptr<PosePipeline> pipeline;
  std::unique_ptr<PoseServiceImpl> service;
  std::unique_ptr<grpc::Server> server;
  // Accepts the server's connections (declared after the acceptor, so stopped before it goes).
  std::unique_ptr<grpc::experimental::ExternalConnectionAcceptor> acceptor;
  std::unique_ptr<GrpcListener> listener;
  std::unique_ptr<HttpView> http;
  // Warms the pool's estimators up in the background (GrpcConfig::warm_up).
  std::thread pool_warm_up;
  std::string host;
  int port = 0;
  bool shut_down = false;
};

namespace {

// Plaintext, TLS, or mutual TLS, from the PEM files of the config.
Result<std::shared_ptr<grpc::ServerCredentials>> ServerCredentials(const SecurityConfig& sec) {
  if (!sec.tls()) return grpc::InsecureServerCredentials();
  grpc::SslServerCredentialsOptions options;
  Result<std::string> cert = ReadFile(sec.tls_cert);
  if (!cert.ok()) return cert.error();
  Result<std::string> key = ReadFile(sec.tls_key);
  if (!key.ok()) return key.error();
  options.pem_key_cert_pairs.push_back({*key, *cert});
  if (!sec.tls_client_ca.empty()) {
    Result<std::string> ca = ReadFile(sec.tls_client_ca);
    if (!ca.ok()) return ca.error();
    options.pem_root_certs = *ca;
    options.client_certificate_request = GRPC_SSL_REQUEST_AND_REQUIRE_CLIENT_CERTIFICATE_AND_VERIFY;
  }
  return grpc::SslServerCredentials(options);
}

}  // namespace

Daemon::Daemon(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

Daemon::~Daemon() { Shutdown(); }

int Daemon::port() const { return impl_->port; }

int Daemon::http_port() const { return impl_->http ? impl_->http->port() : 0; }

std::string Daemon::http_address() const {
  return impl_->http ? impl_->http->address() : std::string();
}

double Daemon::search_resolution_m() const { return impl_->pool->options().lattice.resolution_m; }

std::string Daemon::address() const { return impl_->host + ":" + std::to_string(impl_->port); }

Result<std::unique_ptr<Daemon>> Daemon::Start(const DaemonConfig& config) {
  Status valid = ValidateDaemonConfig(config);
  if (!valid.ok()) return valid.error();
  // Both ports are bound before the long start-up: an address that cannot be served is told at
  // once, and nothing else takes the port meanwhile (connections wait in the kernel's queue).
  // The gRPC port without SO_REUSEPORT: a second daemon on it fails instead of sharing it.
  Result<HostPort> grpc_address = ParseHostPort(config.grpc.listen);
  if (!grpc_address.ok()) return Prefixed("listen: ", grpc_address.error());
  Result<std::unique_ptr<GrpcListener>> listener =
      GrpcListener::Bind(grpc_address->host, grpc_address->port);
  if (!listener.ok()) {
    return MakeError(ErrorCode::kUnavailable,
                     "cannot listen on '" + config.grpc.listen + "': " + listener.error().message);
  }
  std::unique_ptr<HttpView> http;
  if (!config.http.listen.empty()) {
    Result<std::unique_ptr<HttpView>> bound = HttpView::Bind(config.http);
    if (!bound.ok()) return bound.error();
    http = std::move(*bound);
  }

  std::vector<VoxelTemplate> templates;
  for (const std::string& path : config.templates) {
    Result<VoxelTemplate> t = LoadTemplate(path);
    if (!t.ok()) return t.error();
    templates.push_back(std::move(*t));
  }
  EstimatorOptions options = EffectiveEstimatorOptions(config);
  // Every search table made at start, once (all estimators share them): the first frames and
  // calls take no longer than the later ones.
  options.make_tables_at_start = true;

  auto impl = std::make_unique<Impl>();
  Result<std::unique_ptr<EstimatorPool>> pool =
      EstimatorPool::Create(options, templates, config.grpc.max_concurrent_estimates);
  if (!pool.ok()) return pool.error();
  impl->pool = std::move(*pool);

  std::unique_ptr<FrameSource> source;
  std::vector<std::unique_ptr<Estimator>> estimators;
  if (!config.source.path.empty()) {
    ReplayOptions replay;
    replay.realtime = config.source.realtime;
    replay.loop = config.source.loop;
    replay.fps = config.source.fps;
    if (!config.source.intrinsics.empty()) {
      Result<Intrinsics> k = ReadIntrinsicsFile(config.source.intrinsics);
      if (!k.ok()) return k.error();
      replay.has_intrinsics = true;
      replay.intrinsics = *k;
    }
    LiveDeviceOptions device;
    device.frame_timeout_s = config.source.frame_timeout_s;
    device.driver_reload_interval_s = config.source.driver_reload_interval_s;
    Result<std::unique_ptr<FrameSource>> made = MakeFrameSource(config.source.path, replay, device);
    if (!made.ok()) return made.error();
    source = std::move(*made);
    // The stream's estimators share the pool's models, tables included.
    for (int i = 0; i < config.source.estimate_threads; ++i) {
      Result<std::unique_ptr<Estimator>> e =
          Estimator::Create(options, templates, impl->pool->models());
      if (!e.ok()) return e.error();
      estimators.push_back(std::move(*e));
    }
  }
  if (config.stereo.enabled()) {
    Status stereo = StartStereo(config.stereo, impl->signal.get(), &impl->stereo_estimator,
                                &impl->stereo_pipeline);
    if (!stereo.ok()) return stereo.error();
  }
  impl->pipeline = std::make_unique<PosePipeline>(std::move(source), std::move(estimators),
                                                  config.source, impl->signal.get());
  if (http) {
    LiveSceneOptions scene;
    scene.min_height_m = options.clusters.min_height_above_floor_m;
    scene.max_height_m = options.clusters.max_height_above_floor_m;
    impl->scene = std::make_unique<LiveScene>(templates, scene);
  }
  impl->pipeline->SetPublishObserver([metrics = impl->metrics.get(), scene = impl->scene.get()](
                                         const PublishedEstimate& e, const Frame& frame) {
    metrics->RecordDepthEstimate(e);
    if (scene != nullptr) scene->Update(e, frame);
  });
  impl->admission = std::make_unique<AdmissionControl>(
      config.grpc.max_inflight_estimates,
      static_cast<std::uint64_t>(config.grpc.max_inflight_request_bytes));
  impl->service = std::make_unique<PoseServiceImpl>(
      impl->pipeline.get(), impl->pool.get(), config.floor.fixed ? "fixed" : "fit", HposeVersion());
  impl->service->SetAdmissionControl(impl->admission.get());
  impl->streams = std::make_unique<StreamLimiter>(config.grpc.max_pose_streams_per_client);
  impl->service->SetStreamLimiter(impl->streams.get());
  if (!config.security.tokens_file.empty()) {
    Result<std::unique_ptr<TokenAuthorizer>> tokens =
        TokenAuthorizer::Load(config.security.tokens_file);
    if (!tokens.ok()) return tokens.error();
    impl->tokens = std::move(*tokens);
    impl->service->SetTokenAuthorizer(impl->tokens.get());
  }
  impl->service->AttachStereo(impl->stereo_pipeline.get(), impl->stereo_estimator.get());
  impl->service->SetPublishSignal(impl->signal.get());
  if (config.world_from_ground.configured) {
    impl->service->SetWorldFromGround(WorldFromGround(config.world_from_ground));
  }

  grpc::EnableDefaultHealthCheckService(true);
  grpc::reflection::InitProtoReflectionServerBuilderPlugin();
  grpc::ServerBuilder builder;
  Result<std::shared_ptr<grpc::ServerCredentials>> credentials = ServerCredentials(config.security);
  if (!credentials.ok()) return credentials.error();
  // The daemon accepts connections itself (GrpcListener says why) and hands them to the server,
  // which serves them as if it had accepted them: TLS, limits and quota alike.
  impl->listener = std::move(*listener);
  impl->acceptor = builder.experimental().AddExternalConnectionAcceptor(
      grpc::ServerBuilder::experimental_type::ExternalConnectionType::FROM_FD, *credentials);
  // A connection that has not finished its HTTP/2 (and TLS) handshake within this is closed
  // (gRPC's default is 120 s): connections opened and left silent hold a descriptor no longer.
  builder.AddChannelArgument(GRPC_ARG_SERVER_HANDSHAKE_TIMEOUT_MS, 10000);
  builder.SetMaxReceiveMessageSize(config.grpc.max_receive_message_bytes);
  builder.SetMaxSendMessageSize(config.grpc.max_send_message_bytes);
  builder.AddChannelArgument(GRPC_ARG_MAX_CONCURRENT_STREAMS, config.grpc.max_streams_per_client);
  // gRPC's own buffers (requests being received) come out of a bounded quota: under pressure
  // the transport shrinks its flow-control windows, so clients wait instead of the daemon
  // buffering every large request at once.
  grpc::ResourceQuota quota("hposed");
  quota.Resize(static_cast<size_t>(config.grpc.max_inflight_request_bytes) * 4);
  builder.SetResourceQuota(quota);
  builder.RegisterService(impl->service.get());
  std::vector<std::unique_ptr<grpc::experimental::ServerInterceptorFactoryInterface>> counters;
  counters.push_back(std::make_unique<RpcMetricsInterceptorFactory>(impl->metrics.get()));
  builder.experimental().SetInterceptorCreators(std::move(counters));
  impl->server = builder.BuildAndStart();
  if (!impl->server) {
    return MakeError(ErrorCode::kUnavailable,
                     "cannot start the gRPC server on '" + config.grpc.listen + "'");
  }
  impl->listener->Start(impl->acceptor.get());
  impl->port = impl->listener->port();
  impl->host = config.grpc.listen.substr(0, config.grpc.listen.rfind(':'));
  if (grpc::HealthCheckServiceInterface* health = impl->server->GetHealthCheckService()) {
    health->SetServingStatus("hpose.v1.PoseService", true);
    health->SetServingStatus("", true);
  }
  if (impl->scene) {
    HttpViewSources sources;
    sources.service = impl->service.get();
    sources.pipeline = impl->pipeline.get();
    sources.stereo = impl->stereo_pipeline.get();
    sources.signal = impl->signal.get();
    sources.metrics = impl->metrics.get();
    sources.client_counter = impl->metrics.get();
    sources.scene = impl->scene.get();
    sources.version = HposeVersion();
    impl->http = std::move(http);
    impl->http->Start(std::move(sources));
  }
  // The Estimate calls' estimators warm up in the background; the source's frames are read once
  // they have (and the stream's own estimators), so that nothing competes with the first ones.
  // Only as many slots as there are cores: a call beyond them shares a core with another and
  // waits for it longer than its cold estimator's first frame costs (GrpcConfig::warm_up).
  std::shared_future<void> pool_warmed_up;
  if (config.grpc.warm_up) {
    auto done = std::make_shared<std::promise<void>>();
    pool_warmed_up = done->get_future().share();
    const int slots = config.grpc.max_concurrent_estimates;
    impl->pool_warm_up = std::thread([pool = impl->pool.get(), done, slots] {
      const auto start = std::chrono::steady_clock::now();
      const std::shared_ptr<const SimulatedFrame> frame = WarmUpFrame();
      // Calls that came first keep their slots: the warm-up waits for them half a second, then
      // leaves those estimators cold.
      const int warmed =
          frame == nullptr
              ? 0
              : pool->WarmUp(frame->depth, WarmUpIntrinsics(),
                             std::chrono::steady_clock::now() + std::chrono::milliseconds(500),
                             TaskPool::UsableCores());
      if (warmed > 0) {
        spdlog::info(
            "Estimate calls' estimators warmed up ({} of {}) in {:.0f} ms", warmed, slots,
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
                .count());
      } else if (frame != nullptr) {
        spdlog::info("Estimate calls' estimators not warmed up: busy with calls");
      }
      done->set_value();
    });
  }
  impl->pipeline->Start(pool_warmed_up);
  if (impl->stereo_pipeline) impl->stereo_pipeline->Start();
  return std::unique_ptr<Daemon>(new Daemon(std::move(impl)));
}

void Daemon::Shutdown(double grace_s) {
  if (!impl_ || impl_->shut_down) return;
  impl_->shut_down = true;
  if (grpc::HealthCheckServiceInterface* health = impl_->server->GetHealthCheckService()) {
    health->SetServingStatus("hpose.v1.PoseService", false);
    health->SetServingStatus("", false);
  }
  impl_->service->BeginShutdown();
  impl_->listener->Stop();
  if (impl_->http) impl_->http->Stop();
  impl_->server->Shutdown(std::chrono::system_clock::now() +
                          std::chrono::milliseconds(static_cast<int>(grace_s * 1000)));
  impl_->server->Wait();
  if (impl_->pool_warm_up.joinable()) impl_->pool_warm_up.join();
  impl_->pipeline->Stop();
  if (impl_->stereo_pipeline) impl_->stereo_pipeline->Stop();
}

}  // namespace hpose::server
