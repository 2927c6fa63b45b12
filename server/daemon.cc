#include "server/daemon.h"

#include <grpcpp/ext/proto_server_reflection_plugin.h>
#include <grpcpp/grpcpp.h>
#include <grpcpp/health_check_service_interface.h>

#include <chrono>
#include <utility>

#include "core/templates/template_io.h"
#include "server/estimator_pool.h"
#include "server/frame_source.h"
#include "server/pose_pipeline.h"
#include "server/pose_service.h"

namespace hpose::server {

const char* HposeVersion() { return "0.1.0"; }

class Daemon::Impl {
 public:
  std::unique_ptr<EstimatorPool> pool;
  std::unique_ptr<PosePipeline> pipeline;
  std::unique_ptr<PoseServiceImpl> service;
  std::unique_ptr<grpc::Server> server;
  std::string host;
  int port = 0;
  bool shut_down = false;
};

Daemon::Daemon(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

Daemon::~Daemon() { Shutdown(); }

int Daemon::port() const { return impl_->port; }

std::string Daemon::address() const { return impl_->host + ":" + std::to_string(impl_->port); }

Result<std::unique_ptr<Daemon>> Daemon::Start(const DaemonConfig& config) {
  Status valid = ValidateDaemonConfig(config);
  if (!valid.ok()) return valid.error();

  std::vector<VoxelTemplate> templates;
  for (const std::string& path : config.templates) {
    Result<VoxelTemplate> t = LoadTemplate(path);
    if (!t.ok()) return t.error();
    templates.push_back(std::move(*t));
  }
  EstimatorOptions options = config.estimator;
  if (config.floor.fixed) {
    options.use_fixed_floor = true;
    options.fixed_floor = FloorEstimate::FromHeightPitchRoll(
        config.floor.height_m, config.floor.pitch_rad, config.floor.roll_rad);
  }

  auto impl = std::make_unique<Impl>();
  Result<std::unique_ptr<EstimatorPool>> pool =
      EstimatorPool::Create(options, templates, config.grpc.max_concurrent_estimates);
  if (!pool.ok()) return pool.error();
  impl->pool = std::move(*pool);

  std::unique_ptr<FrameSource> source;
  std::unique_ptr<Estimator> estimator;
  if (!config.source.path.empty()) {
    ReplayOptions replay;
    replay.realtime = config.source.realtime;
    replay.loop = config.source.loop;
    replay.fps = config.source.fps;
    Result<std::unique_ptr<FrameSource>> made = MakeFrameSource(config.source.path, replay);
    if (!made.ok()) return made.error();
    source = std::move(*made);
    Result<std::unique_ptr<Estimator>> e = Estimator::Create(options, templates);
    if (!e.ok()) return e.error();
    estimator = std::move(*e);
  }
  impl->pipeline =
      std::make_unique<PosePipeline>(std::move(source), std::move(estimator), config.source);
  impl->service = std::make_unique<PoseServiceImpl>(
      impl->pipeline.get(), impl->pool.get(), config.floor.fixed ? "fixed" : "fit", HposeVersion());

  grpc::EnableDefaultHealthCheckService(true);
  grpc::reflection::InitProtoReflectionServerBuilderPlugin();
  grpc::ServerBuilder builder;
  int selected_port = 0;
  builder.AddListeningPort(config.grpc.listen, grpc::InsecureServerCredentials(), &selected_port);
  // A second daemon on the same port must fail, not silently share it.
  builder.AddChannelArgument(GRPC_ARG_ALLOW_REUSEPORT, 0);
  builder.SetMaxReceiveMessageSize(config.grpc.max_receive_message_bytes);
  builder.SetMaxSendMessageSize(config.grpc.max_send_message_bytes);
  builder.RegisterService(impl->service.get());
  impl->server = builder.BuildAndStart();
  if (!impl->server || selected_port == 0) {
    return MakeError(ErrorCode::kUnavailable,
                     "cannot listen on '" + config.grpc.listen + "' (address in use or invalid)");
  }
  impl->port = selected_port;
  impl->host = config.grpc.listen.substr(0, config.grpc.listen.rfind(':'));
  if (grpc::HealthCheckServiceInterface* health = impl->server->GetHealthCheckService()) {
    health->SetServingStatus("hpose.v1.PoseService", true);
    health->SetServingStatus("", true);
  }
  impl->pipeline->Start();
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
  impl_->server->Shutdown(std::chrono::system_clock::now() +
                          std::chrono::milliseconds(static_cast<int>(grace_s * 1000)));
  impl_->server->Wait();
  impl_->pipeline->Stop();
}

}  // namespace hpose::server
