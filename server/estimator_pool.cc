#include "server/estimator_pool.h"

#include <algorithm>
#include <functional>
#include <optional>
#include <set>
#include <thread>
#include <utility>
#include <vector>

#include "core/common/closest_name.h"
#include "server/estimate_worker.h"

namespace hpose::server {

struct EstimatorPool::Slot {
  std::unique_ptr<Estimator> estimator;  // with every template; made on the slot's first use.
  EstimateWorker worker;
};

EstimatorPool::EstimatorPool(EstimatorOptions options, std::vector<VoxelTemplate> templates,
                             int max_instances)
    : options_(std::move(options)),
      templates_(std::move(templates)),
      max_instances_(max_instances < 1 ? 1 : max_instances) {
  for (int i = 0; i < max_instances_; ++i) slots_.push_back(std::make_unique<Slot>());
  // The first slot at the back: lent first.
  for (int i = max_instances_ - 1; i >= 0; --i) free_.push_back(slots_[i].get());
}

EstimatorPool::~EstimatorPool() = default;

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
  pool->slots_.front()->estimator = std::move(*first);
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
      std::vector<std::string> loaded;
      for (const VoxelTemplate& t : templates_) {
        have += (have.empty() ? "" : ", ") + t.name;
        loaded.push_back(t.name);
      }
      const std::string meant = ClosestName(*wanted.begin(), loaded);
      return MakeError(ErrorCode::kNotFound,
                       "unknown template '" + *wanted.begin() + "' (loaded: " + have +
                           (meant.empty() ? "" : "; did you mean '" + meant + "'?") + ")");
    }
  }
  Slot* slot = nullptr;
  {
    std::unique_lock<std::mutex> lock(mu_);
    if (!cv_.wait_until(lock, deadline, [this] { return !free_.empty(); })) {
      return MakeError(ErrorCode::kUnavailable, "all estimators busy until the deadline");
    }
    slot = free_.back();
    free_.pop_back();
  }
  // The slot goes back to the pool however this call ends.
  struct Release {
    EstimatorPool* pool;
    Slot* slot;
    ~Release() {
      {
        std::lock_guard<std::mutex> lock(pool->mu_);
        pool->free_.push_back(slot);
      }
      pool->cv_.notify_one();
    }
  } release{this, slot};
  std::unique_ptr<Estimator> fresh;  // for a template subset.
  const Estimator* estimator = nullptr;
  if (subset.empty()) {
    Result<const Estimator*> own = SlotEstimator(slot);
    if (!own.ok()) return own.error();
    estimator = *own;
  } else {
    Result<std::unique_ptr<Estimator>> made = Estimator::Create(options_, subset, models_);
    if (!made.ok()) return made.error();
    fresh = std::move(*made);
    estimator = fresh.get();
  }
  std::optional<Result<Estimate>> result;
  slot->worker.Run([&] { result.emplace(fn(*estimator)); });
  return std::move(*result);
}

Result<const Estimator*> EstimatorPool::SlotEstimator(Slot* slot) {
  if (slot->estimator == nullptr) {
    Result<std::unique_ptr<Estimator>> made = Estimator::Create(options_, templates_, models_);
    if (!made.ok()) return made.error();
    slot->estimator = std::move(*made);
  }
  return slot->estimator.get();
}

int EstimatorPool::WarmUp(const DepthImage& depth, const Intrinsics& intrinsics,
                          std::chrono::steady_clock::time_point deadline, int max_slots) {
  std::vector<Slot*> taken;  // the slots lent first, the first at the back.
  {
    std::unique_lock<std::mutex> lock(mu_);
    // All at once: slots taken one by one would hand the same one back each time.
    if (!cv_.wait_until(lock, deadline,
                        [this] { return static_cast<int>(free_.size()) == max_instances_; })) {
      return 0;
    }
    const int count = std::clamp(max_slots, 0, max_instances_);
    taken.assign(free_.end() - count, free_.end());
    free_.resize(free_.size() - count);
  }
  std::vector<std::thread> threads;
  for (Slot* slot : taken) {
    threads.emplace_back([&, slot] {
      // (Create of the same templates and options succeeded before.)
      const Result<const Estimator*> estimator = SlotEstimator(slot);
      if (!estimator.ok()) return;
      slot->worker.Run([&] { (void)(*estimator)->EstimateDepth(depth, intrinsics); });
    });
  }
  for (std::thread& t : threads) t.join();
  {
    std::lock_guard<std::mutex> lock(mu_);
    // Lent first again, in the order they had (after any slot calls gave back meanwhile).
    free_.insert(free_.end(), taken.begin(), taken.end());
  }
  cv_.notify_all();
  return static_cast<int>(taken.size());
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
