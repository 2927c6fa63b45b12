// A serialized EstimateStereoRequest, as a client could send it, through the daemon's
// conversion, the stereo-marker estimator and the answer's conversion: every input gives an
// answer or an Error, never a crash. The calibration is the simulated paper rig at 160x75, the
// size of the seeds run_fuzzers.sh renders, so that seeded pairs reach the landmark matching.
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>

#include "core/stereo/stereo_estimator.h"
#include "core/stereo/stereo_scene_simulator.h"
#include "hpose/v1/pose_service.pb.h"
#include "server/stereo_proto_convert.h"

namespace {

const hpose::StereoEstimator& TheEstimator() {
  static const std::unique_ptr<hpose::StereoEstimator> estimator = [] {
    hpose::StereoSimCameraOptions camera;
    camera.width = 160;
    camera.height = 75;
    const hpose::StereoSceneSimulator simulator(camera);
    return std::move(hpose::StereoEstimator::Create(simulator.calibration()).value());
  }();
  return *estimator;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace hpose;
  v1::EstimateStereoRequest request;
  if (!request.ParseFromArray(data, static_cast<int>(size))) return 0;
  Result<RgbImage> left = server::ColorImageFromProto(request.left(), "left");
  Result<RgbImage> right = server::ColorImageFromProto(request.right(), "right");
  if (!left.ok() || !right.ok()) return 0;
  const Result<StereoFrameResult> result =
      TheEstimator().Process(*left, *right, request.source_time());
  v1::PoseEstimate answer;
  server::FillStereoPoseEstimate(1, request.source_time(), std::chrono::system_clock::now(),
                                 "request", result.ok() ? &*result : nullptr, nullptr,
                                 result.ok() ? nullptr : &result.error(), 0.0, &answer);
  std::string bytes;
  answer.SerializeToString(&bytes);
  return 0;
}
