// Uses every call of the installed hpose::client against a running hposed whose source is a
// looped simulated recording (the humanoid 1 m ahead) and checks the answers; exits non-zero
// with a message on the first failure.
//   hpose_external_client ADDR CLOUD.pcd
#include <hpose/client.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>
#include <thread>
#include <vector>

namespace {

int failures = 0;

void Check(bool ok, const std::string& what) {
  std::printf("%s: %s\n", ok ? "ok" : "FAILED", what.c_str());
  if (!ok) ++failures;
}

bool Ok(const hpose::client::Status& s, const std::string& what) {
  Check(s.ok(), what + (s.ok() ? "" : " (" + s.message + ")"));
  return s.ok();
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: hpose_external_client ADDR CLOUD.pcd\n");
    return 2;
  }
  hpose::client::ConnectOptions options;
  options.address = argv[1];
  std::unique_ptr<hpose::client::Client> client;
  if (!Ok(hpose::client::Client::Connect(options, &client), "connect to " + options.address)) {
    return 1;
  }

  std::vector<std::string> names;
  if (Ok(client->ListTemplates(&names), "list templates")) {
    Check(names.size() == 2, "two templates loaded");
  }

  // The first estimate may take a moment: UNAVAILABLE (14) until then.
  hpose::client::PoseEstimate latest;
  hpose::client::Status s;
  for (int i = 0; i < 200; ++i) {
    s = client->Latest(&latest);
    if (s.code != 14) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  if (Ok(s, "latest")) {
    Check(latest.estimator == hpose::client::Estimator::kDepthTemplate, "latest: depth estimate");
    Check(latest.has_match && std::abs(latest.pose.x_m - 1.0) < 0.1,
          "latest: humanoid about 1 m ahead (x " + std::to_string(latest.pose.x_m) + " m)");
  }

  std::vector<std::uint64_t> sequences;
  hpose::client::StreamOptions stream;
  stream.estimator = hpose::client::Estimator::kDepthTemplate;
  s = client->Stream(
      [&](const hpose::client::PoseEstimate& e) {
        sequences.push_back(e.sequence);
        return sequences.size() < 3;  // stop the stream after three.
      },
      stream);
  if (Ok(s, "stream")) {
    Check(sequences.size() == 3, "stream: three estimates, then stopped by the callback");
    Check(sequences.size() == 3 && sequences[0] < sequences[1] && sequences[1] < sequences[2],
          "stream: increasing sequence numbers");
  }

  hpose::client::PointCloud cloud;
  hpose::client::PoseEstimate estimate;
  if (Ok(hpose::client::ReadPcd(argv[2], &cloud), std::string("read ") + argv[2]) &&
      Ok(client->Estimate(cloud, &estimate), "estimate a cloud")) {
    Check(estimate.source == "request", "estimate: made from the request");
    Check(estimate.humanoid_found && std::abs(estimate.pose.x_m - 1.0) < 0.1 &&
              std::abs(estimate.pose.y_m) < 0.1,
          "estimate: humanoid at (" + std::to_string(estimate.pose.x_m) + ", " +
              std::to_string(estimate.pose.y_m) + ") m, expected (1, 0)");
  }

  hpose::client::DaemonStatus status;
  if (Ok(client->GetStatus(&status), "status")) {
    Check(status.source_state == "running", "status: source running (" + status.source_state + ")");
    Check(status.frames_estimated >= 3, "status: frames estimated");
  }
  std::printf("%d failure(s)\n", failures);
  return failures == 0 ? 0 : 1;
}
