// A serialized EstimateRequest, as a client could send it, through the daemon's conversion and
// the estimator: every input gives an estimate or an Error, never a crash.
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "core/search/estimator.h"
#include "core/sim/humanoid_model.h"
#include "hpose/v1/pose_service.pb.h"
#include "server/proto_convert.h"

namespace {

const hpose::Estimator& TheEstimator() {
  static const std::unique_ptr<hpose::Estimator> estimator = [] {
    const hpose::HumanoidModel model = *hpose::HumanoidModel::FromPreset("standing");
    std::vector<hpose::VoxelTemplate> templates;
    templates.push_back(*hpose::MakeTemplateFromPoints(*model.SampleSurface(0.004), "standing",
                                                       0.016, "standing", "fuzz"));
    return std::move(
        hpose::Estimator::Create(hpose::DefaultEstimatorOptions(), std::move(templates)).value());
  }();
  return *estimator;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace hpose;
  v1::EstimateRequest request;
  if (!request.ParseFromArray(data, static_cast<int>(size))) return 0;
  if (request.has_depth()) {
    Intrinsics k;
    Result<DepthImage> depth = server::DepthFromProto(request.depth(), &k);
    if (depth.ok()) (void)TheEstimator().EstimateDepth(*depth, k);
  } else if (request.has_cloud()) {
    Result<PointCloud> cloud = server::CloudFromProto(request.cloud());
    if (cloud.ok()) (void)TheEstimator().EstimateCloud(*cloud);
  }
  return 0;
}
