// `hpose query`: a command-line client of hposed (hpose.v1.PoseService).
#include <grpcpp/grpcpp.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <iterator>
#include <string>
#include <thread>
#include <vector>

#include "core/common/clock_limits.h"
#include "core/common/closest_name.h"
#include "core/common/pose2d.h"
#include "core/io/atomic_file.h"
#include "core/io/cloud_io.h"
#include "core/io/depth_png.h"
#include "core/io/intrinsics_json.h"
#include "core/stereo/rgb_image_io.h"
#include "core/stereo/world_from_ground_fit.h"
#include "hpose/v1/pose_service.grpc.pb.h"
#include "server/message_json.h"
#include "server/proto_convert.h"
#include "server/stereo_proto_convert.h"
#include "tools/cmd_query_flags.h"
#include "tools/command.h"
#include "tools/estimate_report.h"
#include "tools/exit_codes.h"
#include "tools/fixed_text.h"
#include "tools/flag_parser.h"

namespace hpose::tools {

namespace {

std::atomic<bool> g_interrupted{false};

void OnSignal(int) { g_interrupted = true; }

std::string ToJson(const google::protobuf::Message& m) { return server::MessageToJsonLine(m); }

int ExitFor(const grpc::Status& s) {
  switch (s.error_code()) {
    case grpc::StatusCode::UNAVAILABLE:
    case grpc::StatusCode::DEADLINE_EXCEEDED:
      return kExitUnavailable;
    case grpc::StatusCode::FAILED_PRECONDITION:
      return s.error_message().find("floor") != std::string::npos ? kExitNoFloor : kExitError;
    default:
      return kExitError;
  }
}

// Prints the daemon's reason as a sentence (no status numbers) and returns the exit status
// documented in docs/API.md.
int Fail(const std::string& what, const grpc::Status& s) {
  std::string message = s.error_message();
  if (s.error_code() == grpc::StatusCode::DEADLINE_EXCEEDED &&
      message.find("deadline") == std::string::npos) {
    message = "no answer before the deadline (--timeout)";
  } else if (s.error_code() == grpc::StatusCode::UNAVAILABLE &&
             (message.find("connect") != std::string::npos ||
              message.find("Socket closed") != std::string::npos)) {
    message = "lost the connection to hposed (" + message + ")";
  } else if (message.empty()) {
    message = "the call failed without a reason";
  }
  std::cerr << "hpose query " << what << ": " << message << "\n";
  return ExitFor(s);
}

std::string PoseText(const char* label, const v1::Pose2D& p) {
  char buf[160];
  std::snprintf(buf, sizeof(buf), "%sx %.0f mm  y %.0f mm  theta %.1f deg", label, p.x() * 1000.0,
                p.y() * 1000.0, RadToDeg(p.theta()));
  return buf;
}

std::string DescribeDepth(const v1::PoseEstimate& e) {
  const v1::DepthTemplateResult& r = e.depth_template();
  std::string line;
  char buf[512];
  if (r.detections_size() == 0) {
    line += "  no cluster matched";
  } else {
    const v1::Detection& d = r.best();
    const v1::Candidate& c = d.best();
    // Why the best match is no humanoid: the rule that refused it.
    char why[64] = "";
    switch (d.is_humanoid() ? v1::REFUSAL_NONE : d.refused_by()) {
      case v1::REFUSAL_SCORE:
        std::snprintf(why, sizeof(why), " (below threshold %.0f)", d.score_threshold());
        break;
      case v1::REFUSAL_FIT:
        std::snprintf(why, sizeof(why), " (poor fit %.0f)", c.fit().fit());
        break;
      case v1::REFUSAL_EVIDENCE:
      case v1::REFUSAL_FAR_EVIDENCE:
        std::snprintf(why, sizeof(why), " (weak evidence, fit %.0f)", c.fit().fit());
        break;
      case v1::REFUSAL_OFF_FLOOR_COVERAGE:
        std::snprintf(why, sizeof(why), " (covers too little off the floor)");
        break;
      default:
        break;
    }
    std::snprintf(buf, sizeof(buf), "  %s%s  %s  score %.1f", c.template_name().c_str(), why,
                  PoseText("", c.pose()).c_str(), c.score());
    line += buf;
    if (!d.second_template().empty()) {
      // The margin over the next template, in the points its kind names: ">=" where the other
      // template's search stopped that far behind.
      const bool at_least = d.template_margin_kind() == v1::TEMPLATE_MARGIN_SCORE_AT_LEAST;
      std::snprintf(buf, sizeof(buf), "  margin %s%.1f %s", at_least ? ">=" : "",
                    d.template_margin(),
                    d.template_margin_kind() == v1::TEMPLATE_MARGIN_FIT ? "fit" : "score");
      line += buf;
    }
    if (c.has_runner_up()) {
      // Its score against the best's: below it, or above where the refined fit chose the best.
      std::snprintf(buf, sizeof(buf), "  runner-up theta %.1f deg (%+.1f)",
                    RadToDeg(c.runner_up_pose().theta()), 0.0 - c.runner_up_margin());
      line += buf;
    }
    // A template the image's edges cut: how much of it the fit rests on.
    if (c.refined() && c.fit().has_in_view() && c.fit().in_view() < kPartlyInViewBelow) {
      std::snprintf(buf, sizeof(buf), "  in view %.0f%%", 100.0 * c.fit().in_view());
      line += buf;
    }
    if (e.has_robot_pose_world()) line += "  | " + PoseText("world ", e.robot_pose_world());
  }
  return line;
}

std::string DescribeStereo(const v1::PoseEstimate& e) {
  const v1::StereoMarkerResult& r = e.stereo_marker();
  std::string line;
  char buf[512];
  if (r.robot_found()) {
    line += "  | " + PoseText("world ", r.robot_pose_world());
    if (r.has_robot_pose_world_mean()) {
      std::snprintf(buf, sizeof(buf), "  (mean of %d: x %.0f mm  y %.0f mm  theta %.1f deg)",
                    r.robot_mean_frames(), r.robot_pose_world_mean().x() * 1000.0,
                    r.robot_pose_world_mean().y() * 1000.0,
                    RadToDeg(r.robot_pose_world_mean().theta()));
      line += buf;
    }
  } else {
    line += "  no robot pose (" + r.status() + "): " + r.status_reason();
  }
  if (r.object_found()) {
    const v1::Vector3& o = r.object_position_world();
    std::snprintf(buf, sizeof(buf), "  ball x %.0f mm  y %.0f mm  %s", o.x() * 1000.0,
                  o.y() * 1000.0, r.object_moving() ? "MOVING" : "at rest");
    line += buf;
    if (r.has_path()) {
      std::snprintf(buf, sizeof(buf), "  v (%.0f, %.0f) mm/s", r.path().velocity().x() * 1000.0,
                    r.path().velocity().y() * 1000.0);
      line += buf;
      if (r.path().has_closest_approach()) {
        line += ApproachText(r.path().closest_approach_distance(),
                             r.path().closest_approach_time() - e.source_time());
      }
    }
  }
  return line;
}

// One line per estimate for people: millimetres and degrees, labelled; world-frame poses after
// a '|'.
std::string Describe(const v1::PoseEstimate& e) {
  char buf[512];
  std::string line;
  const bool stereo = e.estimator() == v1::ESTIMATOR_KIND_STEREO_MARKER;
  std::snprintf(buf, sizeof(buf), "%-6s seq %llu  t %.3f s", stereo ? "stereo" : "depth",
                static_cast<unsigned long long>(e.sequence()), e.source_time());
  line = buf;
  if (e.has_error() && !e.error().code().empty()) {
    line += "  no estimate: " + e.error().message();
  } else if (e.has_depth_template()) {
    line += DescribeDepth(e);
  } else if (e.has_stereo_marker()) {
    line += DescribeStereo(e);
  }
  if (!e.has_error() || e.error().code().empty()) {
    std::snprintf(buf, sizeof(buf), "  [%.1f ms, age %.0f ms]", e.timings().total() * 1000.0,
                  e.age() * 1000.0);
    line += buf;
  }
  if (e.skipped() > 0) line += "  (" + std::to_string(e.skipped()) + " skipped before this)";
  if (e.stale()) line += "  STALE: " + e.stale_reason();
  return line;
}

// Side by side: the newest world-frame pose of each estimator and their difference.
// `stream --compare`: each line shows the newest world-frame robot pose of both estimators, and
// the difference between the poses both made of the same instant: the other estimator's pose
// whose frame reached the daemon nearest in time (received_time, one clock for both sources),
// within max_dt_s. The slower estimator's pose is compared when it arrives, with the faster
// one's pose of its own frame's instant, not with the faster one's newest.
class Comparison {
 public:
  explicit Comparison(double max_dt_s) : max_dt_s_(max_dt_s) {}

  std::string Update(const v1::PoseEstimate& e) {
    const bool stereo = e.estimator() == v1::ESTIMATOR_KIND_STEREO_MARKER;
    Slot& slot = stereo ? stereo_ : depth_;
    slot.sequence = e.sequence();
    slot.valid = e.has_robot_pose_world();
    const double received = e.received_time().seconds() + 1e-9 * e.received_time().nanos();
    if (slot.valid) {
      slot.pose = e.robot_pose_world();
      std::vector<TimedPose>& history = stereo ? stereo_history_ : depth_history_;
      history.push_back({received, Pose2D{slot.pose.x(), slot.pose.y(), slot.pose.theta()}});
      // Keep the last few seconds: enough for the slower estimator's latency.
      while (!history.empty() && history.front().timestamp_s < received - 10.0) {
        history.erase(history.begin());
      }
    }
    char buf[512];
    std::snprintf(buf, sizeof(buf), "%-6s t %8.3f s  depth %s  stereo %s",
                  stereo ? "stereo" : "depth", e.source_time(), Text(depth_).c_str(),
                  Text(stereo_).c_str());
    std::string line = buf;
    if (!slot.valid) return line;
    const std::vector<TimedPose>& own = stereo ? stereo_history_ : depth_history_;
    const std::vector<TimedPose>& other = stereo ? depth_history_ : stereo_history_;
    const std::vector<GroundWorldPair> same = PairPosesByTime({own.back()}, other, max_dt_s_);
    if (same.empty()) return line;
    // same[0].ground: this estimate's pose; .world: the other estimator's of the same instant.
    const Pose2D& mine = same[0].ground;
    const Pose2D& theirs = same[0].world;
    const double mm = std::hypot(mine.x - theirs.x, mine.y - theirs.y) * 1000.0;
    const double deg = RadToDeg(stereo ? AngleDiff(theirs.theta, mine.theta)
                                       : AngleDiff(mine.theta, theirs.theta));
    diffs_mm_.push_back(mm);
    diffs_deg_.push_back(std::abs(deg));
    std::snprintf(buf, sizeof(buf), "  diff %6.0f mm %6.1f deg (same instant)", mm, deg);
    return line + buf;
  }

  // A summary of the same-instant differences, for the end of the stream.
  std::string Summary() const {
    if (diffs_mm_.empty()) {
      return "compare: no pair of depth and stereo poses of the same instant (within " +
             std::to_string(static_cast<int>(max_dt_s_ * 1000.0)) + " ms)";
    }
    char buf[256];
    std::snprintf(buf, sizeof(buf),
                  "compare: %zu same-instant pairs (frames within %.0f ms): position difference "
                  "median %.1f mm, max %.1f mm; heading difference median %.1f deg",
                  diffs_mm_.size(), max_dt_s_ * 1000.0, Median(diffs_mm_),
                  *std::max_element(diffs_mm_.begin(), diffs_mm_.end()), Median(diffs_deg_));
    return buf;
  }

 private:
  struct Slot {
    bool valid = false;
    std::uint64_t sequence = 0;
    v1::Pose2D pose;
  };
  static std::string Text(const Slot& s) {
    if (!s.valid)
      return s.sequence == 0 ? "(none yet)                     "
                             : "(not located)                  ";
    char buf[96];
    std::snprintf(buf, sizeof(buf), "%6.0f %6.0f mm %6.1f deg", s.pose.x() * 1000.0,
                  s.pose.y() * 1000.0, RadToDeg(s.pose.theta()));
    return std::string(buf) + "      ";
  }
  static double Median(std::vector<double> v) {
    std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
    return v[v.size() / 2];
  }
  double max_dt_s_;
  Slot depth_, stereo_;
  std::vector<TimedPose> depth_history_, stereo_history_;  // by received_time, oldest first.
  std::vector<double> diffs_mm_, diffs_deg_;
};

void PrintEstimate(const v1::PoseEstimate& e, bool json) {
  std::cout << (json ? ToJson(e) : Describe(e)) << std::endl;
}

// Plaintext, or TLS trusting `ca` (with a client certificate for mutual TLS).
Result<std::shared_ptr<grpc::ChannelCredentials>> ClientCredentials(const std::string& ca,
                                                                    const std::string& cert,
                                                                    const std::string& key) {
  if (ca.empty() && cert.empty()) return grpc::InsecureChannelCredentials();
  if (cert.empty() != key.empty()) {
    return MakeError(ErrorCode::kInvalidArgument, "--tls-cert and --tls-key go together");
  }
  grpc::SslCredentialsOptions options;
  for (const auto& [path, out] :
       {std::pair<const std::string*, std::string*>{&ca, &options.pem_root_certs},
        {&cert, &options.pem_cert_chain},
        {&key, &options.pem_private_key}}) {
    if (path->empty()) continue;
    Result<std::string> text = ReadFile(*path);
    if (!text.ok()) return text.error();
    *out = *text;
  }
  return grpc::SslCredentials(options);
}

// "Bearer TOKEN" sent with every call when --token-file was given.
std::string& BearerMetadata() {
  static std::string value;
  return value;
}

// Sets the call's deadline (none for seconds <= 0) and its bearer token.
void PrepareCall(grpc::ClientContext* ctx, double seconds) {
  if (!BearerMetadata().empty()) ctx->AddMetadata("authorization", BearerMetadata());
  if (seconds > 0) {
    ctx->set_deadline(std::chrono::system_clock::now() +
                      std::chrono::milliseconds(static_cast<long>(seconds * 1000)));
  }
}

// Reads a depth PNG (with --intrinsics or the intrinsics.json beside it) or a PCD/PLY cloud.
Result<v1::EstimateRequest> MakeRequest(const std::string& path,
                                        const std::string& intrinsics_path) {
  v1::EstimateRequest request;
  const std::string ext = std::filesystem::path(path).extension().string();
  if (ext == ".png") {
    Result<DepthImage> depth = ReadDepthPng(path);
    if (!depth.ok()) return depth.error();
    const std::string kpath =
        !intrinsics_path.empty() ? intrinsics_path : IntrinsicsJsonBeside(path);
    Result<Intrinsics> k = ReadIntrinsicsJson(kpath);
    if (!k.ok()) return k.error();
    server::DepthToProto(*depth, *k, request.mutable_depth());
  } else if (ext == ".pcd" || ext == ".ply") {
    Result<PointCloud> cloud = ReadCloud(path);
    if (!cloud.ok()) return cloud.error();
    PointCloud finite;
    for (const auto& p : cloud->points) {
      if (p.allFinite()) finite.points.push_back(p);
    }
    if (finite.points.empty()) {  // said here: the daemon would only see an empty cloud.
      return MakeError(ErrorCode::kInvalidArgument,
                       path + (cloud->points.empty() ? std::string(": the cloud holds no points")
                                                     : ": the cloud has no finite points (all " +
                                                           std::to_string(cloud->points.size()) +
                                                           " are NaN or infinite)"));
    }
    server::CloudToProto(finite, request.mutable_cloud());
  } else {
    return MakeError(ErrorCode::kInvalidArgument,
                     path + ": expected a 16-bit depth .png or a .pcd/.ply cloud");
  }
  return request;
}

// Waits up to `seconds` for the daemon, which may still be starting (a script starts hposed and
// asks it at once). A person who typed the command against no daemon is told after a second
// what it waits for, and at the end what to check.
bool WaitForDaemon(grpc::Channel& channel, const std::string& server, double seconds, bool tls) {
  using Clock = std::chrono::system_clock;
  const Clock::time_point end =
      Clock::now() + std::chrono::milliseconds(static_cast<long>(seconds * 1000));
  const Clock::time_point note = Clock::now() + std::chrono::seconds(1);
  const std::string limit = Fixed(seconds, seconds < 10 ? 1 : 0) + " s";
  if (end > note) {
    if (channel.WaitForConnected(note)) return true;
    std::cerr << "hpose query: waiting for hposed at " << server << " (up to " << limit
              << ", --timeout) ...\n";
  }
  if (channel.WaitForConnected(end)) return true;
  std::cerr << "hpose query: cannot reach hposed at " << server << " within " << limit
            << ": is it running there? (start one with `hposed --source RECORDING`; --server "
               "names another address"
            << (tls ? "" : "; a daemon that serves TLS needs --tls-ca") << ")\n";
  return false;
}

const char* const kQueryCommands[] = {"latest",          "stream", "estimate",
                                      "estimate-stereo", "status", "templates"};

int UnknownQueryCommand(const std::string& cmd) {
  const std::vector<std::string> names(std::begin(kQueryCommands), std::end(kQueryCommands));
  std::string expected;
  for (size_t i = 0; i < names.size(); ++i) {
    expected += (i == 0 ? "" : i + 1 == names.size() ? " or " : ", ") + names[i];
  }
  std::cerr << "hpose query: unknown command '" << cmd << "'" << DidYouMean(cmd, names)
            << " (expected " << expected << ")\n";
  return kExitUsage;
}

}  // namespace

int RunQuery(int argc, char** argv) {
  QueryFlags f;
  FlagParser flags = f.Parser();
  if (const int code = flags.ParseOrExitCode(argc, argv); code >= 0) return code;
  const std::vector<std::string>& args = flags.positional();
  if (args.empty()) {
    std::cerr << flags.Help() << "\nerror: missing COMMAND\n";
    return kExitUsage;
  }
  const std::string& cmd = args[0];
  if (std::find(std::begin(kQueryCommands), std::end(kQueryCommands), cmd) ==
      std::end(kQueryCommands)) {
    return UnknownQueryCommand(cmd);  // before waiting for a daemon.
  }
  const size_t files = cmd == "estimate" ? 1 : cmd == "estimate-stereo" ? 2 : 0;
  if (args.size() != files + 1) {
    std::cerr << "hpose query: "
              << (cmd == "estimate"          ? "estimate needs one FILE"
                  : cmd == "estimate-stereo" ? "estimate-stereo needs LEFT and RIGHT images"
                                             : "unexpected argument")
              << "\n";
    return kExitUsage;
  }
  v1::EstimatorKind kind = v1::ESTIMATOR_KIND_UNSPECIFIED;
  if (f.estimator == "depth") {
    kind = v1::ESTIMATOR_KIND_DEPTH_TEMPLATE;
  } else if (f.estimator == "stereo") {
    kind = v1::ESTIMATOR_KIND_STEREO_MARKER;
  } else if (f.estimator != "all") {
    std::cerr << "hpose query: --estimator must be depth, stereo or all, got '" << f.estimator
              << "'\n";
    return kExitUsage;
  }

  // Deadlines become milliseconds on the clock: a day at most (0 or less: none).
  if (!(f.timeout_s <= kMaxWaitS)) {
    std::cerr << "hpose query: --timeout must be at most 86400 seconds (0: no deadline), got "
              << f.timeout_s << "\n";
    return kExitUsage;
  }
  if (!(f.max_dt_s <= 60.0)) {
    std::cerr << "hpose query: --max-dt must be at most 60 seconds, got " << f.max_dt_s << "\n";
    return kExitUsage;
  }
  grpc::ChannelArguments channel_args;
  channel_args.SetMaxReceiveMessageSize(64 << 20);
  channel_args.SetMaxSendMessageSize(64 << 20);
  // No read-ahead: `stream` read more slowly than the daemon publishes gets the newest estimate
  // rather than older ones held by the transport (docs/API.md, "Streams").
  channel_args.SetInt(GRPC_ARG_HTTP2_BDP_PROBE, 0);
  channel_args.SetInt(GRPC_ARG_HTTP2_STREAM_LOOKAHEAD_BYTES, 1);
  Result<std::shared_ptr<grpc::ChannelCredentials>> credentials =
      ClientCredentials(f.tls_ca, f.tls_cert, f.tls_key);
  if (!credentials.ok()) return ReportError("query", credentials.error());
  if (!f.token_file.empty()) {
    Result<std::string> token = ReadFile(f.token_file);
    if (!token.ok()) return ReportError("query", token.error());
    const std::string first = token->substr(0, token->find('\n'));
    if (first.empty()) {
      return ReportError("query", MakeError(ErrorCode::kInvalidArgument,
                                            f.token_file + ": the first line holds no token"));
    }
    BearerMetadata() = "Bearer " + first;
  }
  auto channel = grpc::CreateCustomChannel(f.server, *credentials, channel_args);
  if (!WaitForDaemon(*channel, f.server, f.timeout_s > 0 ? f.timeout_s : 10.0, !f.tls_ca.empty())) {
    return kExitUnavailable;
  }
  std::unique_ptr<v1::PoseService::Stub> stub = v1::PoseService::NewStub(channel);

  if (cmd == "latest") {
    grpc::ClientContext ctx;
    PrepareCall(&ctx, f.timeout_s);
    v1::GetLatestResponse response;
    v1::GetLatestRequest request;
    request.set_estimator(kind);
    grpc::Status s = stub->GetLatest(&ctx, request, &response);
    if (!s.ok()) return Fail("latest", s);
    PrintEstimate(response.estimate(), f.json);
    return kExitOk;
  }
  if (cmd == "stream") {
    grpc::ClientContext ctx;
    PrepareCall(&ctx, 0.0);  // a stream runs until stopped: no deadline.
    v1::StreamPosesRequest request;
    request.set_max_estimates(f.count > 0 ? static_cast<std::uint32_t>(f.count) : 0);
    if (kind != v1::ESTIMATOR_KIND_UNSPECIFIED) request.add_estimators(kind);
    if (!(f.max_dt_s > 0.0)) {
      std::cerr << "hpose query: --max-dt must be more than 0 seconds\n";
      return kExitUsage;
    }
    Comparison comparison(f.max_dt_s);
    std::signal(SIGINT, OnSignal);
    std::signal(SIGTERM, OnSignal);
    std::atomic<bool> done{false};
    std::thread watcher([&] {
      while (!done && !g_interrupted) std::this_thread::sleep_for(std::chrono::milliseconds(50));
      if (g_interrupted) ctx.TryCancel();
    });
    std::unique_ptr<grpc::ClientReader<v1::PoseEstimate>> reader = stub->StreamPoses(&ctx, request);
    v1::PoseEstimate e;
    long received = 0;
    while (reader->Read(&e)) {
      if (f.compare && !f.json) {
        std::cout << comparison.Update(e) << std::endl;
      } else {
        PrintEstimate(e, f.json);
      }
      ++received;
    }
    grpc::Status s = reader->Finish();
    done = true;
    watcher.join();
    if (f.compare && !f.json) std::cout << comparison.Summary() << std::endl;
    if (g_interrupted || s.error_code() == grpc::StatusCode::CANCELLED) {
      std::cerr << "hpose query stream: stopped after " << received << " estimate(s)\n";
      return kExitOk;
    }
    if (!s.ok()) return Fail("stream", s);
    if (f.count <= 0 || received < f.count) {  // ended by the daemon, not by --count.
      std::cerr << "hpose query stream: the stream ended after " << received
                << " estimate(s): the daemon's source has ended (a finished recording or a "
                   "failed source; `hpose query status` says which), no estimate will follow\n";
    }
    return kExitOk;
  }
  if (cmd == "estimate") {
    Result<v1::EstimateRequest> request = MakeRequest(args[1], f.intrinsics);
    if (!request.ok()) return ReportError("query", request.error());
    for (const std::string& t : f.templates) request->add_templates(t);
    grpc::ClientContext ctx;
    PrepareCall(&ctx, f.timeout_s);
    v1::EstimateResponse response;
    grpc::Status s = stub->Estimate(&ctx, *request, &response);
    if (!s.ok()) return Fail("estimate", s);
    PrintEstimate(response.estimate(), f.json);
    const auto& r = response.estimate().depth_template();
    return r.humanoid_found() ? kExitOk : kExitNoHumanoid;
  }
  if (cmd == "estimate-stereo") {
    v1::EstimateStereoRequest request;
    for (int i = 0; i < 2; ++i) {
      Result<RgbImage> image = ReadRgbImage(args[1 + i]);
      if (!image.ok()) return ReportError("query", image.error());
      server::ColorImageToProto(*image, i == 0 ? request.mutable_left() : request.mutable_right());
    }
    grpc::ClientContext ctx;
    PrepareCall(&ctx, f.timeout_s);
    v1::EstimateResponse response;
    grpc::Status s = stub->EstimateStereo(&ctx, request, &response);
    if (!s.ok()) return Fail("estimate-stereo", s);
    PrintEstimate(response.estimate(), f.json);
    return response.estimate().stereo_marker().robot_found() ? kExitOk : kExitNoHumanoid;
  }
  if (cmd == "status") {
    grpc::ClientContext ctx;
    PrepareCall(&ctx, f.timeout_s);
    v1::GetStatusResponse st;
    grpc::Status s = stub->GetStatus(&ctx, v1::GetStatusRequest(), &st);
    if (!s.ok()) return Fail("status", s);
    if (f.json) {
      std::cout << ToJson(st) << std::endl;
      return kExitOk;
    }
    const v1::SourceStatus& src = st.source();
    std::printf("hposed %s, up %.1f s, %u template(s), %llu Estimate call(s)\n",
                st.version().c_str(), st.uptime(), st.templates(),
                static_cast<unsigned long long>(st.estimate_calls()));
    std::printf("source: %s (%s) %s%s%s\n",
                src.description().empty() ? "(none)" : src.description().c_str(),
                src.kind().c_str(), v1::SourceState_Name(src.state()).c_str(),
                src.state_reason().empty() ? "" : ": ", src.state_reason().c_str());
    if (src.has_camera()) {
      const v1::Intrinsics& k = src.camera();
      std::printf("camera: %ux%u depth frames, fx %.1f fy %.1f cx %.1f cy %.1f\n", k.width(),
                  k.height(), k.fx(), k.fy(), k.cx(), k.cy());
    } else if (src.point_clouds()) {
      std::printf("camera: none, point clouds in the sensor frame\n");
    } else if (src.state() != v1::SOURCE_STATE_NONE) {
      std::printf("camera: not known before the first frame\n");
    }
    std::printf("frames: in %llu, dropped %llu, estimated %llu, failed %llu, reconnects %llu\n",
                static_cast<unsigned long long>(src.frames_in()),
                static_cast<unsigned long long>(src.frames_dropped()),
                static_cast<unsigned long long>(src.frames_estimated()),
                static_cast<unsigned long long>(src.frames_failed()),
                static_cast<unsigned long long>(src.reconnects()));
    std::printf("rate: input %.1f Hz, estimates %.1f Hz\n", src.input_rate(), src.estimate_rate());
    std::printf("latency: median %.1f ms, p99 %.1f ms, last %.1f ms (%u samples)\n",
                st.latency().median() * 1e3, st.latency().p99() * 1e3, st.latency().last() * 1e3,
                st.latency().samples());
    std::printf("floor (%s): height %.0f mm, pitch %.1f deg, roll %.1f deg\n",
                st.floor_mode().c_str(), st.floor().height() * 1e3, RadToDeg(st.floor().pitch()),
                RadToDeg(st.floor().roll()));
    const v1::SourceStatus& ss = st.stereo_source();
    std::printf("stereo source: %s (%s) %s%s%s%s\n",
                ss.description().empty() ? "(none)" : ss.description().c_str(), ss.kind().c_str(),
                v1::SourceState_Name(ss.state()).c_str(), ss.state_reason().empty() ? "" : ": ",
                ss.state_reason().c_str(), st.stereo_calibrated() ? ", calibrated" : "");
    if (ss.state() != v1::SOURCE_STATE_NONE) {
      if (ss.has_camera()) {
        const v1::Intrinsics& k = ss.camera();
        std::printf("stereo camera: %ux%u pairs, left fx %.1f fy %.1f cx %.1f cy %.1f\n", k.width(),
                    k.height(), k.fx(), k.fy(), k.cx(), k.cy());
      } else {
        std::printf("stereo camera: not known before the first pair\n");
      }
      std::printf(
          "stereo pairs: in %llu, dropped %llu, with pose %llu, without %llu; "
          "rate %.1f Hz; latency median %.1f ms\n",
          static_cast<unsigned long long>(ss.frames_in()),
          static_cast<unsigned long long>(ss.frames_dropped()),
          static_cast<unsigned long long>(ss.frames_estimated()),
          static_cast<unsigned long long>(ss.frames_failed()), ss.estimate_rate(),
          st.stereo_latency().median() * 1e3);
    }
    if (st.has_world_from_ground()) {
      std::printf("world_from_ground: x %.0f mm, y %.0f mm, yaw %.1f deg\n",
                  st.world_from_ground().x() * 1e3, st.world_from_ground().y() * 1e3,
                  RadToDeg(st.world_from_ground().theta()));
    } else {
      std::printf("world_from_ground: not configured (depth poses in the ground frame only)\n");
    }
    return kExitOk;
  }
  if (cmd == "templates") {
    grpc::ClientContext ctx;
    PrepareCall(&ctx, f.timeout_s);
    v1::ListTemplatesResponse list;
    grpc::Status s = stub->ListTemplates(&ctx, v1::ListTemplatesRequest(), &list);
    if (!s.ok()) return Fail("templates", s);
    if (f.json) {
      std::cout << ToJson(list) << std::endl;
      return kExitOk;
    }
    for (const v1::TemplateInfo& t : list.templates()) {
      std::printf("%-20s variant %-18s %6d voxels of %.0f mm, height %.0f mm", t.name().c_str(),
                  t.variant().c_str(), t.voxels(), t.resolution() * 1e3, t.height() * 1e3);
      // A daemon before search_resolution sends 0: nothing to add then.
      const double search = t.search_resolution();
      if (search > 0.0 && std::abs(search - t.resolution()) > 1e-9) {
        std::printf(", searched on %.0f mm voxels", search * 1e3);
      }
      std::printf("\n");
    }
    return kExitOk;
  }
  return UnknownQueryCommand(cmd);
}

}  // namespace hpose::tools
