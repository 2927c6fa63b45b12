#ifndef HPOSE_SERVER_RPC_METRICS_INTERCEPTOR_H_
#define HPOSE_SERVER_RPC_METRICS_INTERCEPTOR_H_

// Includes gRPC: only the daemon includes this header.
#include <grpcpp/support/server_interceptor.h>
#include <grpcpp/support/status_code_enum.h>

#include "server/metrics.h"

namespace hpose::server {

// The canonical name of a gRPC status code ("OK", "UNAVAILABLE", ...), as metrics and the web
// view's error bodies spell it.
const char* GrpcCodeName(grpc::StatusCode code);

// Counts every gRPC call of the server by method and final status code, and the calls in
// progress, in `metrics` (which must outlive the server). Logs streams opening and closing at
// info level and unary calls at debug level (never one line per frame at info).
class RpcMetricsInterceptorFactory final
    : public grpc::experimental::ServerInterceptorFactoryInterface {
 public:
  explicit RpcMetricsInterceptorFactory(DaemonMetrics* metrics) : metrics_(metrics) {}
  grpc::experimental::Interceptor* CreateServerInterceptor(
      grpc::experimental::ServerRpcInfo* info) override;

 private:
  DaemonMetrics* metrics_;
};

}  // namespace hpose::server

#endif  // HPOSE_SERVER_RPC_METRICS_INTERCEPTOR_H_
