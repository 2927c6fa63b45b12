#include "hpose/client.h"

#include <grpcpp/grpcpp.h>

#include <chrono>
#include <fstream>
#include <sstream>
#include <utility>

#include "convert.h"
#include "hpose/v1/pose_service.grpc.pb.h"

namespace hpose::client {

namespace {

constexpr int kInvalidArgument = 3;
constexpr int kUnavailable = 14;

Status FromGrpc(const grpc::Status& s) {
  return Status{static_cast<int>(s.error_code()), s.error_message()};
}

Status ReadText(const std::string& path, const char* what, std::string* out) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return Status{kInvalidArgument, path + " (" + what + "): cannot be read"};
  std::ostringstream text;
  text << in.rdbuf();
  *out = text.str();
  return Status{};
}

// Plaintext, or TLS trusting the CA file (with a client certificate for mutual TLS).
Status Credentials(const ConnectOptions& o, std::shared_ptr<grpc::ChannelCredentials>* out) {
  if (o.tls_ca_file.empty() && o.tls_cert_file.empty()) {
    *out = grpc::InsecureChannelCredentials();
    return Status{};
  }
  if (o.tls_cert_file.empty() != o.tls_key_file.empty()) {
    return Status{kInvalidArgument, "tls_cert_file and tls_key_file go together"};
  }
  grpc::SslCredentialsOptions ssl;
  const struct {
    const std::string& path;
    const char* what;
    std::string* pem;
  } files[] = {{o.tls_ca_file, "tls_ca_file", &ssl.pem_root_certs},
               {o.tls_cert_file, "tls_cert_file", &ssl.pem_cert_chain},
               {o.tls_key_file, "tls_key_file", &ssl.pem_private_key}};
  for (const auto& f : files) {
    if (f.path.empty()) continue;
    if (Status s = ReadText(f.path, f.what, f.pem); !s.ok()) return s;
  }
  *out = grpc::SslCredentials(ssl);
  return Status{};
}

// The token of the options: `token`, or the first line of `token_file`.
Status Token(const ConnectOptions& o, std::string* out) {
  if (!o.token.empty() && !o.token_file.empty()) {
    return Status{kInvalidArgument, "give token or token_file, not both"};
  }
  if (o.token_file.empty()) {
    *out = o.token;
    return Status{};
  }
  std::string text;
  if (Status s = ReadText(o.token_file, "token_file", &text); !s.ok()) return s;
  *out = text.substr(0, text.find('\n'));
  if (!out->empty() && out->back() == '\r') out->pop_back();
  if (out->empty()) {
    return Status{kInvalidArgument, o.token_file + ": the first line holds no token"};
  }
  return Status{};
}

std::chrono::system_clock::time_point After(double seconds) {
  return std::chrono::system_clock::now() +
         std::chrono::microseconds(static_cast<long long>(seconds * 1e6));
}

}  // namespace

struct Client::Impl {
  std::shared_ptr<grpc::Channel> channel;
  std::unique_ptr<v1::PoseService::Stub> stub;
  std::string authorization;  // "Bearer TOKEN", or "".
  double call_timeout_s = 10.0;

  // A call's context: the bearer token, and the unary deadline when `deadline`.
  void Prepare(grpc::ClientContext* ctx, bool deadline) const {
    if (!authorization.empty()) ctx->AddMetadata("authorization", authorization);
    if (deadline && call_timeout_s > 0) ctx->set_deadline(After(call_timeout_s));
  }

  Status Estimate(const v1::EstimateRequest& request, PoseEstimate* out) {
    grpc::ClientContext ctx;
    Prepare(&ctx, true);
    v1::EstimateResponse response;
    const grpc::Status s = stub->Estimate(&ctx, request, &response);
    if (s.ok()) *out = internal::FromProto(response.estimate());
    return FromGrpc(s);
  }
};

Client::Client(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Client::~Client() = default;

Status Client::Connect(const ConnectOptions& options, std::unique_ptr<Client>* out) {
  std::shared_ptr<grpc::ChannelCredentials> credentials;
  if (Status s = Credentials(options, &credentials); !s.ok()) return s;
  auto impl = std::make_unique<Impl>();
  std::string token;
  if (Status s = Token(options, &token); !s.ok()) return s;
  if (!token.empty()) impl->authorization = "Bearer " + token;
  impl->call_timeout_s = options.call_timeout_s;
  grpc::ChannelArguments args;
  args.SetMaxReceiveMessageSize(64 << 20);
  args.SetMaxSendMessageSize(64 << 20);
  // No read-ahead: a stream read more slowly than the daemon publishes gets the newest estimate
  // rather than older ones held by the transport (docs/API.md, "Streams").
  args.SetInt(GRPC_ARG_HTTP2_BDP_PROBE, 0);
  args.SetInt(GRPC_ARG_HTTP2_STREAM_LOOKAHEAD_BYTES, 1);
  impl->channel = grpc::CreateCustomChannel(options.address, credentials, args);
  if (!impl->channel->WaitForConnected(After(options.connect_timeout_s))) {
    return Status{kUnavailable, "cannot reach hposed at " + options.address};
  }
  impl->stub = v1::PoseService::NewStub(impl->channel);
  out->reset(new Client(std::move(impl)));
  return Status{};
}

Status Client::Latest(PoseEstimate* out, Estimator estimator) {
  grpc::ClientContext ctx;
  impl_->Prepare(&ctx, true);
  v1::GetLatestRequest request;
  request.set_estimator(internal::ToProto(estimator));
  v1::GetLatestResponse response;
  const grpc::Status s = impl_->stub->GetLatest(&ctx, request, &response);
  if (s.ok()) *out = internal::FromProto(response.estimate());
  return FromGrpc(s);
}

Status Client::Stream(const std::function<bool(const PoseEstimate&)>& on_estimate,
                      const StreamOptions& options) {
  grpc::ClientContext ctx;
  impl_->Prepare(&ctx, false);  // a stream runs until stopped: its own deadline only.
  if (options.timeout_s > 0) ctx.set_deadline(After(options.timeout_s));
  v1::StreamPosesRequest request;
  request.set_max_estimates(options.max_estimates);
  if (options.estimator != Estimator::kAny) {
    request.add_estimators(internal::ToProto(options.estimator));
  }
  std::unique_ptr<grpc::ClientReader<v1::PoseEstimate>> reader =
      impl_->stub->StreamPoses(&ctx, request);
  v1::PoseEstimate e;
  bool stopped = false;
  while (reader->Read(&e)) {
    if (!on_estimate(internal::FromProto(e))) {
      stopped = true;
      ctx.TryCancel();
      break;
    }
  }
  const grpc::Status s = reader->Finish();
  return stopped ? Status{} : FromGrpc(s);
}

Status Client::Estimate(const DepthImage& depth, PoseEstimate* out,
                        const std::vector<std::string>& templates) {
  v1::EstimateRequest request;
  if (Status s = internal::ToProto(depth, request.mutable_depth()); !s.ok()) return s;
  for (const std::string& t : templates) request.add_templates(t);
  return impl_->Estimate(request, out);
}

Status Client::Estimate(const PointCloud& cloud, PoseEstimate* out,
                        const std::vector<std::string>& templates) {
  v1::EstimateRequest request;
  if (Status s = internal::ToProto(cloud, request.mutable_cloud()); !s.ok()) return s;
  for (const std::string& t : templates) request.add_templates(t);
  return impl_->Estimate(request, out);
}

Status Client::GetStatus(DaemonStatus* out) {
  grpc::ClientContext ctx;
  impl_->Prepare(&ctx, true);
  v1::GetStatusResponse response;
  const grpc::Status s = impl_->stub->GetStatus(&ctx, v1::GetStatusRequest(), &response);
  if (s.ok()) *out = internal::FromProto(response);
  return FromGrpc(s);
}

Status Client::ListTemplates(std::vector<std::string>* names) {
  grpc::ClientContext ctx;
  impl_->Prepare(&ctx, true);
  v1::ListTemplatesResponse response;
  const grpc::Status s = impl_->stub->ListTemplates(&ctx, v1::ListTemplatesRequest(), &response);
  if (s.ok()) {
    names->clear();
    for (const v1::TemplateInfo& t : response.templates()) names->push_back(t.name());
  }
  return FromGrpc(s);
}

}  // namespace hpose::client
