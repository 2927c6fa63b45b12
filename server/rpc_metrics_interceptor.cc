#include "server/rpc_metrics_interceptor.h"

#include <grpcpp/grpcpp.h>
#include <spdlog/spdlog.h>

#include <string>

namespace hpose::server {

namespace {

// Lives as long as its call: counts it in progress from creation to destruction and records
// its status when sent.
class RpcMetricsInterceptor final : public grpc::experimental::Interceptor {
 public:
  RpcMetricsInterceptor(DaemonMetrics* metrics, grpc::experimental::ServerRpcInfo* info)
      : metrics_(metrics),
        info_(info),
        method_(info->method() != nullptr && info->method()[0] == '/' ? info->method() + 1
                                                                      : info->method()),
        streaming_(info->type() != grpc::experimental::ServerRpcInfo::Type::UNARY) {
    metrics_->ClientConnected("grpc_call");
  }
  ~RpcMetricsInterceptor() override {
    metrics_->ClientDisconnected("grpc_call");
    if (streaming_) spdlog::info("client {} closed {} ({})", peer_, method_, code_);
  }

  void Intercept(grpc::experimental::InterceptorBatchMethods* methods) override {
    if (!announced_) {  // the peer is known once the call's first batch runs.
      announced_ = true;
      if (info_->server_context() != nullptr) peer_ = info_->server_context()->peer();
      if (streaming_) {
        spdlog::info("client {} opened {}", peer_, method_);
      } else {
        spdlog::debug("client {} called {}", peer_, method_);
      }
    }
    if (methods->QueryInterceptionHookPoint(
            grpc::experimental::InterceptionHookPoints::PRE_SEND_STATUS)) {
      code_ = GrpcCodeName(methods->GetSendStatus().error_code());
      metrics_->RecordRpc(method_, code_);
    }
    methods->Proceed();
  }

 private:
  DaemonMetrics* metrics_;
  grpc::experimental::ServerRpcInfo* info_;  // outlives the interceptor (gRPC owns both).
  std::string method_;
  std::string peer_;
  std::string code_ = "no status";
  bool streaming_;
  bool announced_ = false;
};

}  // namespace

const char* GrpcCodeName(grpc::StatusCode code) {
  switch (code) {
    case grpc::StatusCode::OK:
      return "OK";
    case grpc::StatusCode::CANCELLED:
      return "CANCELLED";
    case grpc::StatusCode::UNKNOWN:
      return "UNKNOWN";
    case grpc::StatusCode::INVALID_ARGUMENT:
      return "INVALID_ARGUMENT";
    case grpc::StatusCode::DEADLINE_EXCEEDED:
      return "DEADLINE_EXCEEDED";
    case grpc::StatusCode::NOT_FOUND:
      return "NOT_FOUND";
    case grpc::StatusCode::ALREADY_EXISTS:
      return "ALREADY_EXISTS";
    case grpc::StatusCode::PERMISSION_DENIED:
      return "PERMISSION_DENIED";
    case grpc::StatusCode::RESOURCE_EXHAUSTED:
      return "RESOURCE_EXHAUSTED";
    case grpc::StatusCode::FAILED_PRECONDITION:
      return "FAILED_PRECONDITION";
    case grpc::StatusCode::ABORTED:
      return "ABORTED";
    case grpc::StatusCode::OUT_OF_RANGE:
      return "OUT_OF_RANGE";
    case grpc::StatusCode::UNIMPLEMENTED:
      return "UNIMPLEMENTED";
    case grpc::StatusCode::INTERNAL:
      return "INTERNAL";
    case grpc::StatusCode::UNAVAILABLE:
      return "UNAVAILABLE";
    case grpc::StatusCode::DATA_LOSS:
      return "DATA_LOSS";
    case grpc::StatusCode::UNAUTHENTICATED:
      return "UNAUTHENTICATED";
    default:
      return "UNKNOWN";
  }
}

grpc::experimental::Interceptor* RpcMetricsInterceptorFactory::CreateServerInterceptor(
    grpc::experimental::ServerRpcInfo* info) {
  return new RpcMetricsInterceptor(metrics_, info);
}

}  // namespace hpose::server
