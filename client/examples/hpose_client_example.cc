// An example of the hpose C++ client: asks a running hposed for poses.
//   hpose_client_example [--server ADDR] [--tls-ca FILE] [--token-file FILE] COMMAND
//   COMMAND: latest | stream N | estimate CLOUD.pcd | status
// Built with the project, and by any CMake project with find_package(hpose) (see
// client/README.md).
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "hpose/client.h"

namespace {

constexpr double kPi = 3.14159265358979323846;

void Print(const hpose::client::PoseEstimate& e) {
  std::printf("seq %llu  t %.3f s  ", static_cast<unsigned long long>(e.sequence), e.source_time_s);
  if (!e.error_code.empty()) {
    std::printf("no estimate: %s\n", e.error_message.c_str());
  } else if (e.has_match) {
    std::printf("%s%s  x %.3f m  y %.3f m  theta %.1f deg  score %.1f\n", e.template_name.c_str(),
                e.humanoid_found ? "" : " (below threshold)", e.pose.x_m, e.pose.y_m,
                e.pose.theta_rad * 180.0 / kPi, e.score);
  } else if (e.has_world_pose) {
    std::printf("world x %.3f m  y %.3f m  theta %.1f deg\n", e.world_pose.x_m, e.world_pose.y_m,
                e.world_pose.theta_rad * 180.0 / kPi);
  } else {
    std::printf("no humanoid\n");
  }
}

int Usage() {
  std::fprintf(stderr,
               "usage: hpose_client_example [--server ADDR] [--tls-ca FILE] [--token-file FILE] "
               "(latest | stream N | estimate CLOUD.pcd | status)\n"
               "Asks hposed (default 127.0.0.1:50051) for the newest pose, N streamed poses, the "
               "pose in a PCD cloud, or its status.\n");
  return 2;
}

int Fail(const char* what, const hpose::client::Status& s) {
  std::fprintf(stderr, "hpose_client_example %s: %s (status %d)\n", what, s.message.c_str(),
               s.code);
  return 1;
}

}  // namespace

int main(int argc, char** argv) {
  hpose::client::ConnectOptions options;
  std::vector<std::string> args;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    std::string* value = a == "--server"       ? &options.address
                         : a == "--tls-ca"     ? &options.tls_ca_file
                         : a == "--token-file" ? &options.token_file
                                               : nullptr;
    if (a == "--help" || a == "-h") return Usage() - 2;
    if (value == nullptr) {
      args.push_back(a);
    } else if (i + 1 < argc) {
      *value = argv[++i];
    } else {
      return Usage();
    }
  }
  if (args.empty()) return Usage();
  const std::string& cmd = args[0];
  if (!(args.size() == 1 && (cmd == "latest" || cmd == "status")) &&
      !(args.size() == 2 && (cmd == "stream" || cmd == "estimate"))) {
    return Usage();
  }

  std::unique_ptr<hpose::client::Client> client;
  if (hpose::client::Status s = hpose::client::Client::Connect(options, &client); !s.ok()) {
    return Fail("connect", s);
  }
  if (cmd == "latest") {
    hpose::client::PoseEstimate e;
    if (hpose::client::Status s = client->Latest(&e); !s.ok()) return Fail("latest", s);
    Print(e);
  } else if (cmd == "stream") {
    hpose::client::StreamOptions stream;
    stream.max_estimates = static_cast<std::uint32_t>(std::strtoul(args[1].c_str(), nullptr, 10));
    hpose::client::Status s = client->Stream(
        [](const hpose::client::PoseEstimate& e) {
          Print(e);
          return true;  // false would end the stream here.
        },
        stream);
    if (!s.ok()) return Fail("stream", s);
  } else if (cmd == "estimate") {
    hpose::client::PointCloud cloud;
    if (hpose::client::Status s = hpose::client::ReadPcd(args[1], &cloud); !s.ok()) {
      return Fail("estimate", s);
    }
    hpose::client::PoseEstimate e;
    if (hpose::client::Status s = client->Estimate(cloud, &e); !s.ok()) {
      return Fail("estimate", s);
    }
    Print(e);
  } else {
    hpose::client::DaemonStatus st;
    if (hpose::client::Status s = client->GetStatus(&st); !s.ok()) return Fail("status", s);
    std::printf(
        "hposed %s  up %.1f s  source %s (%s)  frames in %llu estimated %llu  "
        "templates %u\n",
        st.version.c_str(), st.uptime_s, st.source.empty() ? "none" : st.source.c_str(),
        st.source_state.c_str(), static_cast<unsigned long long>(st.frames_in),
        static_cast<unsigned long long>(st.frames_estimated), st.templates);
  }
  return 0;
}
