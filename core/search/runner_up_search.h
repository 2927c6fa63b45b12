#ifndef HPOSE_CORE_SEARCH_RUNNER_UP_SEARCH_H_
#define HPOSE_CORE_SEARCH_RUNNER_UP_SEARCH_H_

#include <memory>

#include "core/search/search_result.h"

namespace hpose {

// The rest of a search whose optimum is known (PoseSearch::SearchBest): the runner-up, the
// best pose whose heading lies more than 30 degrees from the optimum's, found only if asked
// for. It holds what the search had bounded and reads the problem's cluster, grids and
// template, which must outlive it.
class RunnerUpSearch {
 public:
  virtual ~RunnerUpSearch() = default;
  // Sets the result's runner-up fields and adds the poses and bounds it evaluated to its
  // counters. Once only.
  virtual void Find(SearchResult* result) = 0;
};

// A search that stopped once it had proved that no pose reaches SearchProblem::min_value
// (PoseSearch::SearchBest's `stopped`): what it had bounded, kept so that it can go on down to a
// lower value without bounding it again. Reads the problem's cluster, grids and template, which
// must outlive it.
class StoppedSearch {
 public:
  virtual ~StoppedSearch() = default;
  // Continues down to `min_value` (below the one it stopped at): `result` becomes what SearchBest
  // of the problem with that min_value gives (the poses and bounds of both parts counted), and
  // the runner-up's search is returned as SearchBest returns it. Once only.
  virtual std::unique_ptr<RunnerUpSearch> Lower(int min_value, SearchResult* result) = 0;
};

}  // namespace hpose

#endif  // HPOSE_CORE_SEARCH_RUNNER_UP_SEARCH_H_
