// Daemon latency benchmark: `Estimate` round trip on loopback (median, p99) next to the
// estimator's own time, the transport overhead alone, and `StreamPoses` throughput with one
// and several clients. Starts hposed's core in-process on a free loopback port; frames are
// rendered by `hpose simulate`.
//
//   latency_bench [--calls N] [--seconds S] [--hpose PATH]
#include <grpcpp/grpcpp.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "core/io/depth_png.h"
#include "core/io/intrinsics_json.h"
#include "hpose/v1/pose_service.grpc.pb.h"
#include "server/daemon.h"
#include "server/proto_convert.h"

namespace {

using Clock = std::chrono::steady_clock;
using hpose::server::Daemon;
using hpose::server::DaemonConfig;
namespace v1 = hpose::v1;

double Quantile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<size_t>(q * (v.size() - 1) + 0.5))];
}

std::string CpuModel() {
  std::ifstream in("/proc/cpuinfo");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("model name", 0) == 0) return line.substr(line.find(':') + 2);
  }
  return "unknown";
}

struct Series {
  std::vector<double> rtt_ms, server_ms;
};

Series TimeEstimate(v1::PoseService::Stub* stub, const v1::EstimateRequest& request, int calls,
                    bool expect_ok) {
  Series s;
  for (int i = 0; i < calls; ++i) {
    grpc::ClientContext ctx;
    ctx.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(60));
    v1::EstimateResponse response;
    const Clock::time_point t0 = Clock::now();
    grpc::Status status = stub->Estimate(&ctx, request, &response);
    const double ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
    if (status.ok() != expect_ok) {
      std::fprintf(stderr, "unexpected status %d: %s\n", status.error_code(),
                   status.error_message().c_str());
      std::exit(1);
    }
    s.rtt_ms.push_back(ms);
    s.server_ms.push_back(response.estimate().timings().total() * 1e3);
  }
  return s;
}

// Estimates received per second by `clients` concurrent StreamPoses readers over `seconds`.
double StreamThroughput(int port, int clients, double seconds, long* total) {
  std::atomic<long> received{0};
  std::vector<std::thread> threads;
  for (int c = 0; c < clients; ++c) {
    threads.emplace_back([&] {
      auto stub = v1::PoseService::NewStub(grpc::CreateChannel("127.0.0.1:" + std::to_string(port),
                                                               grpc::InsecureChannelCredentials()));
      grpc::ClientContext ctx;
      ctx.set_deadline(std::chrono::system_clock::now() +
                       std::chrono::milliseconds(static_cast<long>(seconds * 1000)));
      auto reader = stub->StreamPoses(&ctx, v1::StreamPosesRequest());
      v1::PoseEstimate e;
      while (reader->Read(&e)) received.fetch_add(1);
      reader->Finish();
    });
  }
  for (std::thread& t : threads) t.join();
  *total = received.load();
  return received.load() / seconds / clients;
}

}  // namespace

int main(int argc, char** argv) {
  int calls = 100;
  double seconds = 10.0;
  std::string hpose = HPOSE_PROGRAM;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string flag = argv[i];
    if (flag == "--calls")
      calls = std::atoi(argv[i + 1]);
    else if (flag == "--seconds")
      seconds = std::atof(argv[i + 1]);
    else if (flag == "--hpose")
      hpose = argv[i + 1];
  }
  const std::string dir =
      (std::filesystem::temp_directory_path() / ("hpose_latency_" + std::to_string(getpid())))
          .string();
  const std::string sim = hpose + " simulate --out " + dir +
                          " --frames 8 --turn-deg 45 --width 320 --height 240 --no-cloud "
                          "--clutter 2 > /dev/null";
  if (std::system(sim.c_str()) != 0) {
    std::fprintf(stderr, "cannot render frames with: %s\n", sim.c_str());
    return 1;
  }
  DaemonConfig config;
  config.grpc.listen = "127.0.0.1:0";
  config.source.path = dir;
  config.source.loop = true;
  config.source.realtime = false;  // as fast as the estimator goes: measures throughput.
  config.source.queue_capacity = 4;
  config.templates = {std::string(HPOSE_TEMPLATE_DIR) + "/standing.bt",
                      std::string(HPOSE_TEMPLATE_DIR) + "/right_arm_raised.bt"};
  config.grpc.max_concurrent_estimates = 1;
  auto daemon = Daemon::Start(config);
  if (!daemon.ok()) {
    std::fprintf(stderr, "%s\n", daemon.error().ToString().c_str());
    return 1;
  }
  const int port = (*daemon)->port();
  auto stub = v1::PoseService::NewStub(
      grpc::CreateChannel("127.0.0.1:" + std::to_string(port), grpc::InsecureChannelCredentials()));

  std::printf("# hposed latency benchmark\n");
  std::printf("machine: %u cores, %s\n", std::thread::hardware_concurrency(), CpuModel().c_str());
  std::printf("frames: 320x240 simulated (hpose simulate, 2 clutter objects), 2 templates\n\n");

  // 1. Throughput first, with the source running flat out.
  long total1 = 0, total4 = 0;
  const double rate1 = StreamThroughput(port, 1, seconds, &total1);
  const double rate4 = StreamThroughput(port, 4, seconds, &total4);
  grpc::ClientContext sctx;
  v1::GetStatusResponse st;
  stub->GetStatus(&sctx, v1::GetStatusRequest(), &st);
  std::printf("StreamPoses throughput over %.0f s (source replayed as fast as possible):\n",
              seconds);
  std::printf("  1 client : %.2f estimates/s per client (%ld received)\n", rate1, total1);
  std::printf("  4 clients: %.2f estimates/s per client (%ld received); ratio 4/1 = %.2f\n", rate4,
              total4, rate1 > 0 ? rate4 / rate1 : 0.0);
  std::printf("  daemon: %.2f estimates/s published, latency median %.1f ms, p99 %.1f ms\n\n",
              st.source().estimate_rate(), st.latency().median() * 1e3, st.latency().p99() * 1e3);
  (*daemon)->Shutdown();

  // 2. Estimate round trips with the source stopped (a daemon without a source).
  config.source.path.clear();
  auto quiet = Daemon::Start(config);
  if (!quiet.ok()) return 1;
  stub = v1::PoseService::NewStub(grpc::CreateChannel(
      "127.0.0.1:" + std::to_string((*quiet)->port()), grpc::InsecureChannelCredentials()));
  v1::EstimateRequest frame;
  auto depth = hpose::ReadDepthPng(dir + "/depth_000.png");
  auto k = hpose::ReadIntrinsicsJson(dir + "/intrinsics.json");
  if (!depth.ok() || !k.ok()) return 1;
  hpose::server::DepthToProto(*depth, *k, frame.mutable_depth());
  TimeEstimate(stub.get(), frame, 3, true);  // warm-up.
  const Series full = TimeEstimate(stub.get(), frame, calls, true);
  // A frame with no floor is rejected after validation and cloud building only: transport
  // plus decoding cost.
  v1::EstimateRequest empty = frame;
  std::string zeros(empty.depth().data().size(), '\0');
  empty.mutable_depth()->set_data(zeros);
  const Series bare = TimeEstimate(stub.get(), empty, calls, false);
  std::vector<double> overhead;
  for (size_t i = 0; i < full.rtt_ms.size(); ++i) {
    overhead.push_back(full.rtt_ms[i] - full.server_ms[i]);
  }
  std::printf("Estimate round trip on loopback, %d calls, 320x240 depth (150 KiB request):\n",
              calls);
  std::printf("  round trip        : median %7.2f ms  p99 %7.2f ms\n", Quantile(full.rtt_ms, 0.5),
              Quantile(full.rtt_ms, 0.99));
  std::printf("  estimator inside  : median %7.2f ms  p99 %7.2f ms\n",
              Quantile(full.server_ms, 0.5), Quantile(full.server_ms, 0.99));
  std::printf("  round trip - estimator: median %5.2f ms  p99 %7.2f ms\n", Quantile(overhead, 0.5),
              Quantile(overhead, 0.99));
  std::printf("  empty frame (rejected, transport + checks): median %.2f ms  p99 %.2f ms\n",
              Quantile(bare.rtt_ms, 0.5), Quantile(bare.rtt_ms, 0.99));
  (*quiet)->Shutdown();
  std::filesystem::remove_all(dir);
  return 0;
}
