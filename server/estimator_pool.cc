#include "server/estimator_pool.h"

#include <set>
#include <utility>

namespace hpose::server {

EstimatorPool::EstimatorPool(EstimatorOptions options, std::vector<VoxelTemplate> templates,
                             int max_instances)
    : options_(std::move(options)),
      templates_(std::move(templates)),
      max_instances_(max_instances < 1 ? 1 : max_instances) {}

Result<std::unique_ptr<EstimatorPool>> EstimatorPool::Create(EstimatorOptions options,
                                                             std::vector<VoxelTemplate> templates,
                                                             int max_instances) {
  // Validate once by building the first instance.
  Result<std::unique_ptr<Estimator>> first = Estimator::Create(options, templates);
  if (!first.ok()) return first.error();
  // Estimators for a subset of the templates search at the whole set's voxel edge (a subset
  // without the tallest template would otherwise choose a finer one): the same results for a
  // template whichever others are asked for, and the same shared models.
  options.lattice.resolution_m = (*first)->options().lattice.resolution_m;
  options.resolution_from_templates = false;
  std::unique_ptr<EstimatorPool> pool(
      new EstimatorPool(std::move(options), std::move(templates), max_instances));
  pool->models_ = (*first)->models();
  pool->idle_.push_back(std::move(*first));
  pool->created_ = 1;
  return pool;
}

template <typename Fn>
Result<Estimate> EstimatorPool::Run(const std::vector<std::string>& names,
                                    std::chrono::steady_clock::time_point deadline, Fn fn) {
  // Resolve a template subset first: unknown names are the caller's error.
  std::vector<VoxelTemplate> subset;
  if (!names.empty()) {
    std::set<std::string> wanted(names.begin(), names.end());
    for (const VoxelTemplate& t : templates_) {
      if (wanted.erase(t.name) > 0) subset.push_back(t);
    }
    if (!wanted.empty()) {
      std::string have;
      for (const VoxelTemplate& t : templates_) have += (have.empty() ? "" : ", ") + t.name;
      return MakeError(ErrorCode::kNotFound,
                       "unknown template '" + *wanted.begin() + "' (loaded: " + have + ")");
    }
  }
  std::unique_ptr<Estimator> estimator;
  {
    std::unique_lock<std::mutex> lock(mu_);
    if (!cv_.wait_until(lock, deadline, [this] { return in_use_ < max_instances_; })) {
      return MakeError(ErrorCode::kUnavailable, "all estimators busy until the deadline");
    }
    ++in_use_;
    if (subset.empty() && !idle_.empty()) {
      estimator = std::move(idle_.back());
      idle_.pop_back();
    }
  }
  const bool pooled = subset.empty();
  if (!estimator) {
    Result<std::unique_ptr<Estimator>> made =
        Estimator::Create(options_, pooled ? templates_ : subset, models_);
    if (!made.ok()) {
      std::lock_guard<std::mutex> lock(mu_);
      --in_use_;
      cv_.notify_one();
      return made.error();
    }
    estimator = std::move(*made);
  }
  Result<Estimate> result = fn(*estimator);
  {
    std::lock_guard<std::mutex> lock(mu_);
    --in_use_;
    if (pooled) idle_.push_back(std::move(estimator));
  }
  cv_.notify_one();
  return result;
}

Result<Estimate> EstimatorPool::EstimateDepth(const DepthImage& depth, const Intrinsics& intrinsics,
                                              const std::vector<std::string>& template_names,
                                              std::chrono::steady_clock::time_point deadline) {
  return Run(template_names, deadline,
             [&](const Estimator& e) { return e.EstimateDepth(depth, intrinsics); });
}

Result<Estimate> EstimatorPool::EstimateCloud(const PointCloud& cloud,
                                              const std::vector<std::string>& template_names,
                                              std::chrono::steady_clock::time_point deadline) {
  return Run(template_names, deadline, [&](const Estimator& e) { return e.EstimateCloud(cloud); });
}

}  // namespace hpose::server
