#ifndef HPOSE_CORE_SEARCH_RUNNER_UP_SEARCH_H_
#define HPOSE_CORE_SEARCH_RUNNER_UP_SEARCH_H_

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

}  // namespace hpose

#endif  // HPOSE_CORE_SEARCH_RUNNER_UP_SEARCH_H_
