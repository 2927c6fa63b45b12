// Daemon latency benchmark: `Estimate` round trip on loopback (median, p99) next to the
// estimator's own time, the transport overhead alone, and `StreamPoses` throughput with one
// and several clients; then the pose pipeline on 640x480 frames: estimates published per
// second with a PNG file sequence at `rate: fast`, and frame-arrival -> published latency
// (median, p99) at 30 fps paced input, for each `source.estimate_threads` value. Starts hposed's
// core in-process on a free loopback port; frames are rendered by `hpose simulate`. Run it
// under `taskset -c 0` and `taskset -c 0,1` to compare one and two cores.
//
//   latency_bench [--calls N] [--seconds S] [--hpose PATH] [--pipeline-only]
//                 [--pipeline-seconds S] [--threads 1,2] [--pipeline-frames N]
//                 [--start-rounds N]
#include <grpcpp/grpcpp.h>
#include <sched.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
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

v1::GetStatusResponse GetStatus(int port) {
  auto stub = v1::PoseService::NewStub(
      grpc::CreateChannel("127.0.0.1:" + std::to_string(port), grpc::InsecureChannelCredentials()));
  grpc::ClientContext ctx;
  ctx.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(10));
  v1::GetStatusResponse st;
  stub->GetStatus(&ctx, v1::GetStatusRequest(), &st);
  return st;
}

// What the pose pipeline did over one measurement window.
struct PipelineRun {
  double publish_rate_hz = 0.0;  // estimates published (ok or failed) per second.
  double input_rate_hz = 0.0;    // frames read per second.
  double latency_median_ms = 0.0, latency_p99_ms = 0.0;
  unsigned latency_samples = 0;
  unsigned long long published = 0, dropped = 0;
};

// Starts the daemon on the frame directory `dir` (looped), waits `warmup_s`, then measures for
// `seconds`: the publish and input rates from the counters, the arrival -> published latency
// over the last 256 published frames (the daemon's own statistics).
bool RunPipeline(DaemonConfig config, const std::string& dir, bool fast, int threads,
                 double seconds, double warmup_s, PipelineRun* run) {
  config.source.path = dir;
  config.source.loop = true;
  config.source.realtime = !fast;
  config.source.fps = 30.0;
  config.source.estimate_threads = threads;
  // Fast: room for every estimation thread plus one waiting frame (nothing is dropped at
  // rate: fast). Paced: the default, one frame (newest only, lowest latency).
  config.source.queue_capacity = fast ? threads + 1 : 1;
  auto daemon = Daemon::Start(config);
  if (!daemon.ok()) {
    std::fprintf(stderr, "%s\n", daemon.error().ToString().c_str());
    return false;
  }
  const int port = (*daemon)->port();
  std::this_thread::sleep_for(std::chrono::duration<double>(warmup_s));
  const v1::GetStatusResponse a = GetStatus(port);
  const Clock::time_point t0 = Clock::now();
  std::this_thread::sleep_for(std::chrono::duration<double>(seconds));
  const v1::GetStatusResponse b = GetStatus(port);
  const double dt = std::chrono::duration<double>(Clock::now() - t0).count();
  (*daemon)->Shutdown();
  auto done = [](const v1::GetStatusResponse& s) {
    return s.source().frames_estimated() + s.source().frames_failed();
  };
  run->published = done(b) - done(a);
  run->dropped = b.source().frames_dropped() - a.source().frames_dropped();
  run->publish_rate_hz = static_cast<double>(run->published) / dt;
  run->input_rate_hz = static_cast<double>(b.source().frames_in() - a.source().frames_in()) / dt;
  run->latency_median_ms = b.latency().median() * 1e3;
  run->latency_p99_ms = b.latency().p99() * 1e3;
  run->latency_samples = b.latency().samples();
  return true;
}

int AllowedCpus() {
  cpu_set_t set;
  CPU_ZERO(&set);
  if (sched_getaffinity(0, sizeof(set), &set) != 0) return 0;
  return CPU_COUNT(&set);
}

// How the walk's frames are rendered: hpose simulate, and the sensor's height and pitch.
struct WalkRender {
  std::string hpose;
  double sensor_height_m = 0.34;
  double pitch_deg = 0.0;
};

// Renders `frames` 640x480 frames of a humanoid 1.5 m away turning and walking among 4 clutter
// objects into `dir`; false (said on stderr) if hpose simulate fails.
bool RenderWalk(const WalkRender& render, const std::string& dir, int frames) {
  const std::string sim =
      render.hpose + " simulate --out " + dir + " --frames " + std::to_string(frames) +
      " --turn-deg 12 --step-m 0.02 --x 1.5 --width 640 --height 480 --no-cloud --clutter 4" +
      " --sensor-height " + std::to_string(render.sensor_height_m) + " --pitch-deg " +
      std::to_string(render.pitch_deg) + " > /dev/null";
  if (std::system(sim.c_str()) == 0) return true;
  std::fprintf(stderr, "cannot render frames with: %s\n", sim.c_str());
  return false;
}

// The pipeline section: 640x480 frames of a humanoid turning and walking among clutter.
int PipelineSection(const DaemonConfig& base, const WalkRender& render, const std::string& dir,
                    const std::vector<int>& threads, int frames, double seconds) {
  if (!RenderWalk(render, dir, frames)) return 1;
  std::printf(
      "## Pose pipeline, 640x480 frames (%d simulated, humanoid turning and walking, 4 "
      "clutter objects), 2 templates\n",
      frames);
  std::printf("CPUs this process may use: %d (of %u)\n\n", AllowedCpus(),
              std::thread::hardware_concurrency());
  std::printf(
      "| estimate_threads | rate: fast, published/s | rate: recorded 30 fps: published/s "
      "| dropped/s | latency median ms | latency p99 ms | samples |\n");
  std::printf("|---|---|---|---|---|---|---|\n");
  for (const int t : threads) {
    PipelineRun fast, paced;
    if (!RunPipeline(base, dir, /*fast=*/true, t, seconds, 2.0, &fast)) return 1;
    if (!RunPipeline(base, dir, /*fast=*/false, t, seconds, 2.0, &paced)) return 1;
    std::printf("| %d | %.1f | %.1f (input %.1f) | %.1f | %.1f | %.1f | %u |\n", t,
                fast.publish_rate_hz, paced.publish_rate_hz, paced.input_rate_hz,
                paced.dropped / seconds, paced.latency_median_ms, paced.latency_p99_ms,
                paced.latency_samples);
    std::fflush(stdout);
  }
  std::printf(
      "\nlatency: frame arrival (read from the source) to published, over the last 256 "
      "published frames of the paced run\n\n");
  return 0;
}

// One daemon start on the frames of `dir` played once at 30 fps: how long Daemon::Start took,
// the first frame's arrival -> published latency, and the median and largest over every frame;
// then, on a second start without a source, the estimator's own time (timings.total) of the
// daemon's first Estimate calls, of the first frame, one after the other.
struct StartRun {
  double start_ms = 0.0, first_ms = -1.0, median_ms = 0.0, max_ms = 0.0;
  unsigned samples = 0;
  long later_faults = -1;  // the process's page faults from the first publication to the end.
  std::vector<double> call_ms;
};

constexpr int kStartCalls = 6;

long MinorFaults() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_minflt;
}

bool RunFromStart(DaemonConfig config, const std::string& dir, bool warm_up, StartRun* run) {
  config.source.path = dir;
  config.source.loop = false;
  config.source.realtime = true;
  config.source.fps = 30.0;
  config.source.estimate_threads = 1;
  config.source.queue_capacity = 1;
  config.source.warm_up = warm_up;
  config.grpc.warm_up = warm_up;
  const Clock::time_point t0 = Clock::now();
  auto daemon = Daemon::Start(config);
  if (!daemon.ok()) {
    std::fprintf(stderr, "%s\n", daemon.error().ToString().c_str());
    return false;
  }
  run->start_ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
  const int port = (*daemon)->port();
  auto done = [](const v1::GetStatusResponse& s) {
    return s.source().frames_estimated() + s.source().frames_failed();
  };
  // The first publication, caught before the next (a frame period later).
  const Clock::time_point give_up = Clock::now() + std::chrono::seconds(60);
  v1::GetStatusResponse st;
  while (Clock::now() < give_up) {
    st = GetStatus(port);
    if (done(st) > 0) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  const long faults_at_first = MinorFaults();
  if (done(st) == 1) run->first_ms = st.latency().last() * 1e3;
  while (Clock::now() < give_up) {
    st = GetStatus(port);
    if (st.source().state() == v1::SOURCE_STATE_FINISHED &&
        done(st) + st.source().frames_dropped() >= st.source().frames_in()) {
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  if (run->first_ms >= 0.0) run->later_faults = MinorFaults() - faults_at_first;
  (*daemon)->Shutdown();
  run->samples = st.latency().samples();
  run->median_ms = st.latency().median() * 1e3;
  run->max_ms = st.latency().p99() * 1e3;  // of at most 100 samples: the largest.

  // The calls, on a daemon of their own without a source (nothing estimated before them),
  // once its warm-up has had time to end.
  config.source.path.clear();
  daemon = Daemon::Start(config);
  if (!daemon.ok()) {
    std::fprintf(stderr, "%s\n", daemon.error().ToString().c_str());
    return false;
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  v1::EstimateRequest request;
  const auto depth = hpose::ReadDepthPng(dir + "/depth_000.png");
  const auto k = hpose::ReadIntrinsicsJson(dir + "/intrinsics.json");
  if (!depth.ok() || !k.ok()) return false;
  hpose::server::DepthToProto(*depth, *k, request.mutable_depth());
  auto stub = v1::PoseService::NewStub(grpc::CreateChannel(
      "127.0.0.1:" + std::to_string((*daemon)->port()), grpc::InsecureChannelCredentials()));
  for (const double ms : TimeEstimate(stub.get(), request, kStartCalls, true).server_ms) {
    run->call_ms.push_back(ms);
  }
  (*daemon)->Shutdown();
  return true;
}

// The start-up section: `rounds` daemon starts with the warm-ups (source.warm_up, grpc.warm_up)
// off and on, alternating, each playing `frames` rendered frames once at 30 fps with one
// estimation thread, then answering kStartCalls Estimate calls.
int StartSection(const DaemonConfig& base, const WalkRender& render, const std::string& dir,
                 int frames, int rounds) {
  if (!RenderWalk(render, dir, frames)) return 1;
  std::printf(
      "## The first frames after a start, 640x480 (%d simulated frames played once at 30 fps, "
      "1 estimation thread), %d starts each, alternating\n\n",
      frames, rounds);
  std::printf(
      "| warm_up | Daemon::Start ms | first frame's latency ms | largest latency ms "
      "| median latency ms | page faults after the first frame | Estimate call 1, 2, 3-%d: "
      "estimator ms |\n|---|---|---|---|---|---|---|\n",
      kStartCalls);
  std::vector<StartRun> runs[2];
  for (int r = 0; r < rounds; ++r) {
    for (const bool warm : {false, true}) {
      StartRun run;
      if (!RunFromStart(base, dir, warm, &run)) return 1;
      if (run.samples == 0) {
        std::fprintf(stderr, "latency_bench: nothing was published from %s\n", dir.c_str());
        return 1;
      }
      runs[warm ? 1 : 0].push_back(run);
    }
  }
  for (const bool warm : {false, true}) {
    std::vector<double> start, first, largest, median, faults, call1, call2, later;
    for (const StartRun& run : runs[warm ? 1 : 0]) {
      start.push_back(run.start_ms);
      if (run.first_ms >= 0.0) first.push_back(run.first_ms);
      if (run.later_faults >= 0) faults.push_back(static_cast<double>(run.later_faults));
      largest.push_back(run.max_ms);
      median.push_back(run.median_ms);
      call1.push_back(run.call_ms.at(0));
      call2.push_back(run.call_ms.at(1));
      later.insert(later.end(), run.call_ms.begin() + 2, run.call_ms.end());
    }
    std::printf("| %s | %.1f | %.1f (%zu caught) | %.1f | %.1f | %.0f | %.1f, %.1f, %.1f |\n",
                warm ? "true" : "false", Quantile(start, 0.5), Quantile(first, 0.5), first.size(),
                Quantile(largest, 0.5), Quantile(median, 0.5), Quantile(faults, 0.5),
                Quantile(call1, 0.5), Quantile(call2, 0.5), Quantile(later, 0.5));
  }
  std::printf(
      "\nmedians over the starts; latency: frame arrival (read from the source) to published\n\n");
  return 0;
}

// Thread counts, comma-separated, each in [least, 64].
std::vector<int> ParseIntList(const std::string& text, int least) {
  std::vector<int> out;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    char* end = nullptr;
    const long v = std::strtol(item.c_str(), &end, 10);
    if (item.empty() || *end != '\0' || v < least || v > 64) {
      std::fprintf(stderr, "latency_bench: thread counts are integers in [%d, 64], got '%s'\n",
                   least, item.c_str());
      std::exit(2);
    }
    out.push_back(static_cast<int>(v));
  }
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  int calls = 100;
  double seconds = 10.0;
  double pipeline_seconds = 10.0;
  int pipeline_frames = 30;
  bool pipeline_only = false;
  int start_rounds = 0;
  bool no_search = false;
  std::vector<int> threads = {1, 2};
  int search_threads = DaemonConfig().estimator.threads;  // hposed's default.
  std::string hpose = HPOSE_PROGRAM;
  WalkRender render;
  for (int i = 1; i < argc; ++i) {
    const std::string flag = argv[i];
    const bool has_value = i + 1 < argc;
    if (flag == "--pipeline-only") {
      pipeline_only = true;
    } else if (flag == "--calls" && has_value) {
      calls = std::atoi(argv[++i]);
    } else if (flag == "--seconds" && has_value) {
      seconds = std::atof(argv[++i]);
    } else if (flag == "--pipeline-seconds" && has_value) {
      pipeline_seconds = std::atof(argv[++i]);
    } else if (flag == "--pipeline-frames" && has_value) {
      pipeline_frames = std::atoi(argv[++i]);
    } else if (flag == "--threads" && has_value) {
      threads = ParseIntList(argv[++i], 1);
    } else if (flag == "--search-threads" && has_value) {
      // 0: one per core the process may use, as hposed resolves it.
      const std::vector<int> one = ParseIntList(argv[++i], 0);
      if (one.size() != 1) {
        std::fprintf(stderr, "latency_bench: --search-threads wants one integer, got '%s'\n",
                     argv[i]);
        return 2;
      }
      search_threads = one.front();
    } else if (flag == "--hpose" && has_value) {
      hpose = argv[++i];
    } else if (flag == "--sensor-height" && has_value) {
      render.sensor_height_m = std::atof(argv[++i]);
    } else if (flag == "--pitch-deg" && has_value) {
      render.pitch_deg = std::atof(argv[++i]);
    } else if (flag == "--start-rounds" && has_value) {
      start_rounds = std::atoi(argv[++i]);
    } else if (flag == "--no-search") {
      no_search = true;
    } else {
      std::printf(
          "usage: latency_bench [--calls N] [--seconds S] [--hpose PATH] [--pipeline-only]\n"
          "                     [--pipeline-seconds S] [--pipeline-frames N] [--threads 1,2]\n"
          "                     [--search-threads N] [--start-rounds N]\n"
          "                     [--sensor-height M] [--pitch-deg D]\n"
          "  --calls N             Estimate round trips to time (100)\n"
          "  --seconds S           StreamPoses throughput window (10)\n"
          "  --pipeline-only       only the pose pipeline section\n"
          "  --pipeline-seconds S  measurement window of each pipeline run (10)\n"
          "  --pipeline-frames N   640x480 frames rendered for the pipeline runs (30)\n"
          "  --threads LIST        source.estimate_threads values to compare (1,2)\n"
          "  --search-threads N    search.threads of every run: threads inside one estimate\n"
          "                        (its clusters x templates searched at once; default:\n"
          "                        hposed's, 0 = one per core the process may use)\n"
          "  --hpose PATH          the hpose program that renders the frames\n"
          "  --start-rounds N      only the start-up section: N daemon starts with the\n"
          "                        warm-ups off and on each: the first frames' latency and\n"
          "                        the first Estimate calls' time\n"
          "  --sensor-height M     the 640x480 frames' sensor height above the floor (0.34)\n"
          "  --pitch-deg D         and its pitch, degrees down (0)\n"
          "  --no-search           pipeline runs without the pose search (no cluster is\n"
          "                        large enough): the cost of everything else\n"
          "Run under taskset -c 0 / taskset -c 0,1 to compare one and two cores.\n");
      return flag == "--help" ? 0 : 2;
    }
  }
  if (calls < 1 || !(seconds > 0.0) || !(pipeline_seconds > 0.0) || pipeline_frames < 1 ||
      start_rounds < 0) {
    std::fprintf(stderr, "latency_bench: counts and durations must be positive\n");
    return 2;
  }
  const std::string dir =
      (std::filesystem::temp_directory_path() / ("hpose_latency_" + std::to_string(getpid())))
          .string();
  DaemonConfig config;
  config.grpc.listen = "127.0.0.1:0";
  config.templates = {std::string(HPOSE_TEMPLATE_DIR) + "/standing.bt",
                      std::string(HPOSE_TEMPLATE_DIR) + "/right_arm_raised.bt"};
  config.grpc.max_concurrent_estimates = 1;
  config.estimator.threads = search_threads;
  if (no_search) {
    // No cluster reaches this size: every frame is decoded, turned into a cloud, its floor
    // fitted and clustered, and an estimate without detections is published.
    config.estimator.clusters.min_points = 100000000;
    config.estimator.clusters.max_points = 100000000;
  }
  std::printf("# hposed latency benchmark%s\n", no_search ? " (--no-search: no pose search)" : "");
  std::printf("machine: %u cores, %s; search.threads %d\n", std::thread::hardware_concurrency(),
              CpuModel().c_str(), search_threads);
  render.hpose = hpose;
  std::printf("640x480 frames: sensor %.2f m above the floor, %.1f degrees down\n\n",
              render.sensor_height_m, render.pitch_deg);
  if (start_rounds > 0) {
    const int rc = StartSection(config, render, dir + "_start", pipeline_frames, start_rounds);
    std::filesystem::remove_all(dir + "_start");
    return rc;
  }
  if (pipeline_only) {
    const int rc =
        PipelineSection(config, render, dir + "_640", threads, pipeline_frames, pipeline_seconds);
    std::filesystem::remove_all(dir + "_640");
    return rc;
  }
  const std::string sim = hpose + " simulate --out " + dir +
                          " --frames 8 --turn-deg 45 --width 320 --height 240 --no-cloud "
                          "--clutter 2 > /dev/null";
  if (std::system(sim.c_str()) != 0) {
    std::fprintf(stderr, "cannot render frames with: %s\n", sim.c_str());
    return 1;
  }
  config.source.path = dir;
  config.source.loop = true;
  config.source.realtime = false;  // as fast as the estimator goes: measures throughput.
  config.source.queue_capacity = 4;
  auto daemon = Daemon::Start(config);
  if (!daemon.ok()) {
    std::fprintf(stderr, "%s\n", daemon.error().ToString().c_str());
    return 1;
  }
  const int port = (*daemon)->port();
  auto stub = v1::PoseService::NewStub(
      grpc::CreateChannel("127.0.0.1:" + std::to_string(port), grpc::InsecureChannelCredentials()));

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
  std::printf("\n");
  const int rc =
      PipelineSection(config, render, dir + "_640", threads, pipeline_frames, pipeline_seconds);
  std::filesystem::remove_all(dir + "_640");
  return rc;
}
