#ifndef HPOSE_SERVER_DAEMON_H_
#define HPOSE_SERVER_DAEMON_H_

#include <memory>
#include <string>

#include "core/common/status.h"
#include "server/daemon_config.h"

namespace hpose::server {

// The running daemon: templates loaded, the source's pipeline started, and the gRPC server
// (PoseService, grpc.health.v1 health, server reflection) listening. gRPC stays out of this
// header.
class Daemon {
 public:
  // Validates `config`, loads the templates (kNotFound / kDataLoss naming the file), creates
  // the source (a missing path fails here; a device that is absent is retried in the
  // background) and listens (kUnavailable when the address cannot be bound). Port 0 in
  // `config.grpc.listen` picks a free port: see port().
  static Result<std::unique_ptr<Daemon>> Start(const DaemonConfig& config);
  ~Daemon();

  int port() const;             // the bound TCP port.
  std::string address() const;  // host:port actually bound.
  // The web view's bound address ("" / 0 when http.listen is off).
  int http_port() const;
  std::string http_address() const;
  // The voxel edge the templates are searched at, metres (EstimatorOptions::
  // resolution_from_templates, max_height_voxels).
  double search_resolution_m() const;

  // Marks the service NOT_SERVING, ends streams, waits up to `grace_s` for calls in flight,
  // then stops the source. Idempotent.
  void Shutdown(double grace_s = 2.0);

 private:
  class Impl;
  explicit Daemon(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

// hpose's version string.
const char* HposeVersion();

}  // namespace hpose::server

#endif  // HPOSE_SERVER_DAEMON_H_
