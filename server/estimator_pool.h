#ifndef HPOSE_SERVER_ESTIMATOR_POOL_H_
#define HPOSE_SERVER_ESTIMATOR_POOL_H_

#include <chrono>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "core/common/status.h"
#include "core/search/estimator.h"

namespace hpose::server {

// Estimators for concurrent Estimate calls: an Estimator handles one frame at a time, so the
// pool keeps `max_instances` slots, each an estimator (made on first use) and a worker thread
// (EstimateWorker), and lends one slot per call, the one used last first; the call's estimate
// runs on the slot's thread, so a slot's buffers, per estimator and per thread, stay grown from
// call to call. All its estimators, and those made for a subset of the templates, share one copy
// of the templates' models. Thread-safe.
class EstimatorPool {
 public:
  // Fails like Estimator::Create (no templates, duplicate names, bad options).
  static Result<std::unique_ptr<EstimatorPool>> Create(EstimatorOptions options,
                                                       std::vector<VoxelTemplate> templates,
                                                       int max_instances);
  ~EstimatorPool();

  // Estimates one depth frame (millimetres) or cloud (sensor frame, metres) with all templates,
  // or only those named in `template_names`. Fails with kNotFound for an unknown template name,
  // kUnavailable when no estimator became free before `deadline`, or as the estimator does.
  Result<Estimate> EstimateDepth(const DepthImage& depth, const Intrinsics& intrinsics,
                                 const std::vector<std::string>& template_names,
                                 std::chrono::steady_clock::time_point deadline);
  Result<Estimate> EstimateCloud(const PointCloud& cloud,
                                 const std::vector<std::string>& template_names,
                                 std::chrono::steady_clock::time_point deadline);

  const std::vector<VoxelTemplate>& templates() const { return templates_; }
  // The options every estimator of the pool is made with: the search's voxel edge is fixed to
  // the one the whole set of templates gave (EstimatorOptions::resolution_from_templates off).
  const EstimatorOptions& options() const { return options_; }
  // The templates' models (rotations, search tables, surfaces) every estimator of the pool
  // shares, made with its first: for other estimators of the process (Estimator::Create).
  const std::vector<TemplateModels>& models() const { return models_; }

  // Estimates `depth` once with the estimators of the `max_slots` slots lent first (all slots
  // when there are no more), each on its slot's thread, and drops the results: the first calls
  // then cost what later ones do. Waits until no slot is lent; calls meanwhile wait for the
  // slots being warmed and may take the others. Returns how many slots it warmed: 0, doing
  // nothing, if some were still lent at `deadline`.
  int WarmUp(const DepthImage& depth, const Intrinsics& intrinsics,
             std::chrono::steady_clock::time_point deadline, int max_slots);

 private:
  EstimatorPool(EstimatorOptions options, std::vector<VoxelTemplate> templates, int max_instances);

  struct Slot;
  // The slot's estimator with every template, made on the slot's first use. The caller holds
  // the slot (lent, or taken by WarmUp).
  Result<const Estimator*> SlotEstimator(Slot* slot);
  // Runs `fn` with an estimator (the slot's, or a fresh one for a template subset) on the
  // thread of a free slot.
  template <typename Fn>
  Result<Estimate> Run(const std::vector<std::string>& names,
                       std::chrono::steady_clock::time_point deadline, Fn fn);

  EstimatorOptions options_;
  std::vector<VoxelTemplate> templates_;
  std::vector<TemplateModels> models_;  // set once, at Create.
  const int max_instances_;

  std::mutex mu_;
  std::condition_variable cv_;
  std::vector<std::unique_ptr<Slot>> slots_;  // max_instances_ of them, made at Create.
  std::vector<Slot*> free_;                   // the one freed last at the back.
};

}  // namespace hpose::server

#endif  // HPOSE_SERVER_ESTIMATOR_POOL_H_
